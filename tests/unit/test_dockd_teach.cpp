// dockd's teach on its own: a Teacher behind scripted daemon hooks (no core, no state file). A teach that collects its
// scans and stores the averaged target, one cancelled by a stop, and the ways one fails: refused at the start, too
// few scans saw the dock before the timeout, detections spread too far, the state file not written.
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/perception/profile_geometry.hpp"
#include "teach.hpp"

#include "CppUTest/TestHarness.h"

namespace {

using dockd::HostRequest;
using dockd::HostRequestKind;

/// The daemon's side: every call recorded, the core and the state file scripted.
struct FakeHooks final : dockd::TeachHooks {
  struct Configured {
    std::uint16_t dock_id;
    bool raw;
  };
  std::vector<Configured> configured;
  bool configure_ok = true;
  std::uint16_t active_dock = 3;
  std::vector<dockd::TaughtTarget> stored;
  std::string store_error;  ///< Not empty: store_target fails with it.
  std::vector<std::string> replies;
  std::vector<std::string> errors;  ///< "code:message" of every error reply.
  std::vector<std::string> events;

  bool configure_core(std::uint16_t dock_id, bool raw_profile) override {
    configured.push_back({dock_id, raw_profile});
    return configure_ok;
  }
  std::uint16_t active_dock_id() const override { return active_dock; }
  bool store_target(const dockd::TaughtTarget& t, std::string& error) override {
    if (!store_error.empty()) {
      error = store_error;
      return false;
    }
    stored.push_back(t);
    return true;
  }
  void reply(const HostRequest&, const char* json, std::size_t len) override { replies.emplace_back(json, len); }
  void reply_error(const HostRequest&, dockd::HostErrorCode code, const char* message) override {
    errors.push_back(std::to_string(static_cast<unsigned>(code)) + ":" + message);
  }
  void log_event(dockd::EventLine& e, dockd::LogLevel) override {
    const std::size_t n = e.w.finish();
    events.emplace_back(e.buf, n);
  }
};

HostRequest teach_request(std::uint32_t seq, std::uint16_t scans, int dock_id = -1) {
  HostRequest r;
  r.kind = HostRequestKind::kTeach;
  r.has_seq = true;
  r.seq = seq;
  r.scans = scans;
  if (dock_id >= 0) {
    r.has_dock_id = true;
    r.dock_id = static_cast<std::uint16_t>(dock_id);
  }
  return r;
}

dockd::TeachConditions ready() {
  dockd::TeachConditions c;
  c.state = dockcore::TaskState::kNotTasking;
  c.on_charger = true;
  c.lidar_fresh = true;
  return c;
}

dockcore::DockEstimate seen(double x_m, double y_m, double yaw_rad) {
  dockcore::DockEstimate e;
  e.found = true;
  e.pose = dockcore::Pose2{static_cast<dockcore::Real>(x_m), static_cast<dockcore::Real>(y_m),
                           static_cast<dockcore::Real>(yaw_rad)};
  return e;
}

constexpr double kPi = 3.14159265358979323846;

/// A detection from a scan without usable intensity (the geometry alone).
void sample(dockd::Teacher& t, const dockcore::DockEstimate& e) {
  t.sample(e, dockcore::ScanView{}, false);
}

}  // namespace

TEST_GROUP(DockdTeach) {
  dockd::DockdConfig cfg;
  FakeHooks hooks;

  void setup() override {
    dockd::DockEntry d;
    d.id = 1;
    cfg.docks.push_back(d);
    d.id = 3;
    cfg.docks.push_back(d);
    cfg.default_dock_id = 1;
    cfg.teach_scans = 4;
    cfg.teach_timeout_s = 10;
  }
};

TEST(DockdTeach, AveragesItsScansStoresTheTargetAndReplies) {
  dockd::Teacher t(cfg, hooks);
  t.start(teach_request(5, 0), ready(), 1000000);
  CHECK_TRUE(t.active());
  CHECK_EQUAL(1u, hooks.configured.size());  // the default dock's raw profile: what a teach measures
  CHECK_EQUAL(1u, hooks.configured[0].dock_id);
  CHECK_TRUE(hooks.configured[0].raw);
  CHECK_EQUAL(1u, hooks.events.size());
  STRCMP_CONTAINS("\"event\":\"teach_start\",\"dock_id\":1,\"scans\":4", hooks.events[0].c_str());

  // Four detections around (0.230, 0.002) facing the robot, the nominal target being (0.225, 0, 180°).
  sample(t, seen(0.229, 0.001, kPi - 0.01));
  sample(t, seen(0.231, 0.003, kPi + 0.01));
  t.progress(1100000);
  CHECK_TRUE(t.active());  // two of four
  sample(t, seen(0.230, 0.002, kPi));
  sample(t, seen(0.230, 0.002, kPi));
  sample(t, seen(0.5, 0.5, 0));  // beyond its scans: not averaged
  t.progress(1200000);
  CHECK_FALSE(t.active());

  CHECK_EQUAL(1u, hooks.stored.size());
  const dockd::TaughtTarget& s = hooks.stored[0];
  CHECK_EQUAL(1u, s.dock_id);
  CHECK_EQUAL(4u, s.scans);
  DOUBLES_EQUAL(0.230, static_cast<double>(s.target.x_m), 1e-6);
  DOUBLES_EQUAL(0.002, static_cast<double>(s.target.y_m), 1e-6);
  DOUBLES_EQUAL(0.0, std::remainder(static_cast<double>(s.target.yaw_rad) - kPi, 2 * kPi), 1e-6);
  DOUBLES_EQUAL(std::hypot(0.001, 0.001), s.spread_m, 1e-6);
  CHECK_EQUAL(2u, hooks.configured.size());  // then corrected by the new target
  CHECK_EQUAL(1u, hooks.configured[1].dock_id);
  CHECK_FALSE(hooks.configured[1].raw);
  CHECK_TRUE(hooks.errors.empty());
  CHECK_EQUAL(1u, hooks.replies.size());
  STRCMP_CONTAINS(
      "{\"ok\":true,\"cmd\":\"teach\",\"seq\":5,\"dock_id\":1,\"scans\":4,\"target_x_m\":0.2300,"
      "\"target_y_m\":0.0020,",
      hooks.replies[0].c_str());
  STRCMP_CONTAINS("\"spread_mm\":1.41,\"offset_x_mm\":5.0,\"offset_y_mm\":2.0,", hooks.replies[0].c_str());
  // Scans without usable intensity: no code, and the reply says why.
  STRCMP_CONTAINS("\"code\":\"intensity_unusable\",\"spread_mm\"", hooks.replies[0].c_str());
  CHECK_EQUAL(0, s.stripe_count);
  CHECK_EQUAL(2u, hooks.events.size());
  STRCMP_CONTAINS("\"event\":\"teach_done\",\"dock_id\":1,\"scans\":4,\"target_x_m\":0.2300", hooks.events[1].c_str());
}

TEST(DockdTeach, AStopCancelsTheRunningTeach) {
  dockd::Teacher t(cfg, hooks);
  t.cancel(500000);  // none runs: nothing
  CHECK_TRUE(hooks.errors.empty());
  t.start(teach_request(6, 10, 3), ready(), 1000000);
  CHECK_TRUE(t.active());
  sample(t, seen(0.23, 0, kPi));
  t.cancel(1100000);
  CHECK_FALSE(t.active());
  CHECK_EQUAL(1u, hooks.errors.size());
  STRCMP_EQUAL("7:cancelled by stop", hooks.errors[0].c_str());
  CHECK_TRUE(hooks.stored.empty());
  CHECK_TRUE(hooks.replies.empty());
  // The core goes back to the dock it ran for before the teach.
  CHECK_EQUAL(2u, hooks.configured.size());
  CHECK_EQUAL(3u, hooks.configured[1].dock_id);
  CHECK_FALSE(hooks.configured[1].raw);
  // Nothing left to finish.
  t.progress(60000000);
  CHECK_EQUAL(1u, hooks.errors.size());
}

TEST(DockdTeach, FailsWhenTooFewScansSawTheDockBeforeTheTimeout) {
  dockd::Teacher t(cfg, hooks);
  t.start(teach_request(7, 5), ready(), 1000000);
  sample(t, seen(0.23, 0, kPi));
  sample(t, seen(0.23, 0, kPi));
  t.progress(10999999);
  CHECK_TRUE(t.active());
  t.progress(11000000);  // teach_timeout_s after the start
  CHECK_FALSE(t.active());
  CHECK_EQUAL(1u, hooks.errors.size());
  STRCMP_EQUAL("7:only 2 of 5 scans saw the dock within 10 s", hooks.errors[0].c_str());
  CHECK_TRUE(hooks.stored.empty());
  CHECK_EQUAL(3u, hooks.configured.back().dock_id);
  sample(t, seen(0.23, 0, kPi));  // after the end: ignored
  CHECK_FALSE(t.active());
}

TEST(DockdTeach, FailsWhenTheDetectionsSpreadOrTheStateFileCannotBeWritten) {
  dockd::Teacher t(cfg, hooks);
  t.start(teach_request(8, 2), ready(), 1000000);
  sample(t, seen(0.20, 0, kPi));
  sample(t, seen(0.25, 0, kPi));  // 25 mm from the mean each: a moving robot
  t.progress(1100000);
  CHECK_FALSE(t.active());
  CHECK_EQUAL(1u, hooks.errors.size());
  STRCMP_EQUAL("7:detections spread 25.0 mm (> 20 mm): robot moving or dock ambiguous", hooks.errors[0].c_str());
  CHECK_TRUE(hooks.stored.empty());
  CHECK_EQUAL(1u, hooks.configured.back().dock_id);

  hooks.store_error = "rename: read-only file system";
  t.start(teach_request(9, 2), ready(), 2000000);
  sample(t, seen(0.23, 0, kPi));
  sample(t, seen(0.23, 0, kPi));
  t.progress(2100000);
  CHECK_FALSE(t.active());
  CHECK_EQUAL(2u, hooks.errors.size());
  STRCMP_EQUAL("7:state file: rename: read-only file system", hooks.errors[1].c_str());
  CHECK_TRUE(hooks.replies.empty());
}

TEST(DockdTeach, RefusedAtTheStartWhenTheRobotIsNotReady) {
  dockd::Teacher t(cfg, hooks);
  t.start(teach_request(1, 0, 9), ready(), 0);
  dockd::TeachConditions busy = ready();
  busy.state = dockcore::TaskState::kAlign;
  t.start(teach_request(2, 0), busy, 0);
  dockd::TeachConditions off = ready();
  off.on_charger = false;
  t.start(teach_request(3, 0), off, 0);
  dockd::TeachConditions blind = ready();
  blind.lidar_fresh = false;
  t.start(teach_request(4, 0), blind, 0);
  hooks.configure_ok = false;
  t.start(teach_request(5, 0), ready(), 0);
  CHECK_FALSE(t.active());
  CHECK_EQUAL(5u, hooks.errors.size());
  STRCMP_EQUAL("5:dock id 9 is not in the dock database", hooks.errors[0].c_str());
  STRCMP_EQUAL("7:teach needs an idle robot (stop the running task first)", hooks.errors[1].c_str());
  STRCMP_EQUAL("7:teach needs the robot on the charger: contacts are not closed", hooks.errors[2].c_str());
  STRCMP_EQUAL("7:teach needs the lidar: no fresh scans", hooks.errors[3].c_str());
  STRCMP_EQUAL("7:dock profile refused", hooks.errors[4].c_str());

  hooks.configure_ok = true;
  t.start(teach_request(6, 0), ready(), 0);
  CHECK_TRUE(t.active());
  t.start(teach_request(7, 0), ready(), 0);  // one at a time
  STRCMP_EQUAL("9:a teach is already running", hooks.errors[5].c_str());
  CHECK_TRUE(t.active());
  CHECK_TRUE(hooks.events.size() == 1u);  // only the one that started
}

namespace {

/// A 0.2° scan of a plate-v at `dock` (robot frame, lidar at the robot's origin) whose face (segment 1) is bright from
/// `from_m` to `to_m` along it (none when from_m >= to_m), everything else at 150-156.
std::unique_ptr<dockcore::LaserScan> taped_scan(const dockcore::DockProfile& plate, const dockcore::Pose2& dock,
                                                double from_m, double to_m) {
  auto scan = std::make_unique<dockcore::LaserScan>();
  scan->reset(1800, static_cast<dockcore::Real>(-kPi), static_cast<dockcore::Real>(2 * kPi / 1800), 0);
  dockcore::PlacedProfile placed;
  placed.place(plate, dock);
  for (std::size_t i = 0; i < scan->count; ++i) {
    const dockcore::Real a = scan->view().angle_rad(i);
    const dockcore::Vec2 dir(std::cos(a), std::sin(a));
    dockcore::Real r = 0;
    std::size_t seg = 0;
    scan->intensities[i] = static_cast<dockcore::Real>(150 + i % 7);  // a diffuse face's intensities vary
    if (!placed.raycast(dir, &r, &seg)) continue;
    scan->ranges_m[i] = r;
    const double along = static_cast<double>(placed.along_m(seg, r * dir));
    if (seg == 1 && along > from_m && along < to_m) scan->intensities[i] = 250;
  }
  return scan;
}

}  // namespace

// With usable intensity each detection's scan is read at its pose: the pattern most scans read is the code (edges
// averaged), a pattern only half the scans read is none, and a profile with its own stripes keeps them.
TEST(DockdTeach, TheCodeIsThePatternMostScansRead) {
  dockcore::DockProfile plate;
  CHECK(dockcore::builtin_profile("plate-v", plate) == dockcore::ProfileError::kOk);
  cfg.docks[0].profile = plate;
  const dockcore::DockEstimate e = seen(0.23, 0.0, kPi);
  const auto taped = taped_scan(plate, e.pose, 0.05, 0.15);
  const auto bare = taped_scan(plate, e.pose, 0, 0);
  dockd::Teacher t(cfg, hooks);

  t.start(teach_request(5, 0), ready(), 1000000);
  for (int i = 0; i < 3; ++i) t.sample(e, taped->view(), true);
  t.sample(e, bare->view(), true);
  t.progress(1100000);
  CHECK_EQUAL(1u, hooks.stored.size());
  const dockd::TaughtTarget& s = hooks.stored[0];
  CHECK_EQUAL(1, s.stripe_count);
  CHECK_EQUAL(3, s.code_scans);
  CHECK_EQUAL(1, s.stripes[0].segment);
  // Edges half-way between beams 0.8 mm apart on the face.
  DOUBLES_EQUAL(0.05, static_cast<double>(s.stripes[0].from_m), 0.001);
  DOUBLES_EQUAL(0.15, static_cast<double>(s.stripes[0].to_m), 0.001);
  STRCMP_CONTAINS("\"code\":\"taught\",\"stripes\":[[1,0.05", hooks.replies[0].c_str());
  STRCMP_CONTAINS("\"code_scans\":3,\"code_spread_mm\":0.0", hooks.replies[0].c_str());
  STRCMP_CONTAINS("\"code\":\"taught\"", hooks.events.back().c_str());

  // Two of four scans read the stripe: no majority, no code.
  t.start(teach_request(6, 0), ready(), 2000000);
  for (int i = 0; i < 2; ++i) t.sample(e, taped->view(), true);
  for (int i = 0; i < 2; ++i) t.sample(e, bare->view(), true);
  t.progress(2100000);
  CHECK_EQUAL(2u, hooks.stored.size());
  CHECK_EQUAL(0, hooks.stored[1].stripe_count);
  STRCMP_CONTAINS("\"code\":\"unread\",\"spread_mm\"", hooks.replies[1].c_str());

  // The profile's own stripes stay; the teach says whether its reading agrees.
  dockcore::ReflectorStripe own{1, static_cast<dockcore::Real>(0.05), static_cast<dockcore::Real>(0.15)};
  CHECK(dockcore::add_reflector(cfg.docks[0].profile, own) == dockcore::ProfileError::kOk);
  t.start(teach_request(7, 0), ready(), 3000000);
  for (int i = 0; i < 4; ++i) t.sample(e, taped->view(), true);
  t.progress(3100000);
  CHECK_EQUAL(0, hooks.stored[2].stripe_count);
  STRCMP_CONTAINS("\"code\":\"profile\",\"stripes\":[[1,0.05", hooks.replies[2].c_str());
  STRCMP_CONTAINS("\"code_matches\":true", hooks.replies[2].c_str());
  t.start(teach_request(8, 0), ready(), 4000000);
  for (int i = 0; i < 4; ++i) t.sample(e, bare->view(), true);
  t.progress(4100000);
  STRCMP_CONTAINS("\"code\":\"profile\",\"stripes\":[],\"code_scans\":4", hooks.replies[3].c_str());
  STRCMP_CONTAINS("\"code_matches\":false", hooks.replies[3].c_str());
}
