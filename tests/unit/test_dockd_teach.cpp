// dockd's teach on its own: a Teacher behind scripted daemon hooks (no core, no state file). A teach that collects its
// scans and stores the averaged target, one cancelled by a stop, and the ways one fails: refused at the start, too
// few scans saw the dock before the timeout, detections spread too far, the state file not written.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

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
