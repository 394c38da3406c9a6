// dockd's two camera sources (the UDP datagram and its own camera, docs/camera.md) feeding one camera target, the
// own camera's status fields (appended when they fit, left out — never the status lost — when they do not), and the
// camera stall watchdog.
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "dockd_sim_rig.hpp"

#include "CppUTest/TestHarness.h"

namespace {

struct FakeTargets final : dockcore::hal::CameraTargetSource {
  bool has = false;
  dockcore::CameraTarget next{};
  void put(double u, std::uint64_t stamp_us) {
    next.valid = true;
    next.u_px = static_cast<dockcore::Real>(u);
    next.v_px = 240;
    next.confidence = 1;
    next.stamp_us = stamp_us;
    has = true;
  }
  bool poll_target(dockcore::CameraTarget& out) override {
    if (!has) return false;
    out = next;
    has = false;
    return true;
  }
  int fd() const override { return -1; }
};

struct FakeTags final : dockcore::hal::TagPoseSource {
  std::vector<dockcore::TagObservation> queue;
  /// A tag 1 m straight ahead of the camera, facing it.
  void put(int id, std::uint64_t stamp_us) {
    dockcore::TagObservation o;
    o.id = id;
    o.decision_margin = 80;
    o.stamp_us = stamp_us;
    o.translation_m = dockcore::Vec3(0, 0, 1);
    queue.push_back(o);
  }
  bool poll_tag(dockcore::TagObservation& out) override {
    if (queue.empty()) return false;
    out = queue.front();
    queue.erase(queue.begin());
    return true;
  }
};

/// Frame arrivals of the own camera, as the detection thread would record them.
struct FakeFrames final : dockcore::hal::CameraFrameMonitor {
  std::uint64_t last = 0;
  std::uint64_t last_frame_us() const override { return last; }
};

/// The own camera's state as its pipeline would report it.
struct FakeCameraStatus final : dockcore::hal::CameraStatusSource {
  dockcore::hal::CameraStatus status{};
  dockcore::hal::CameraStatus camera_status() const override { return status; }
};

struct CameraRig {
  docksim::Scenario sc = docksim::load_scenario_file(dockd_test::default_scenario_path());
  dockd::DockdConfig cfg = dockd_test::scenario_config(sc);
  dockd_test::SimClock clock;
  std::unique_ptr<docksim::Chassis> chassis;
  dockd_test::SimChassis link;
  dockd_test::SimLidar lidar;
  FakeTargets udp, own;
  FakeTags tags;
  FakeFrames frames;
  FakeCameraStatus camera_status;
  std::unique_ptr<dockd::Daemon> daemon;
  std::string state_file = "/tmp/dockd_test_camera_" + std::to_string(::getpid());

  /// `status`: the own camera's state in the status (null: no such fields). `fuse_tags`: the tag poses reach the
  /// daemon (their counters are in the status).
  explicit CameraRig(const dockcore::hal::CameraStatus* status, int dock_tag_id = -1, bool watch_frames = false,
                     bool fuse_tags = true) {
    cfg.state_file = state_file;
    cfg.docks[0].tag.id = dock_tag_id;
    chassis = dockd_test::scenario_chassis(sc, link, clock);
    dockd::DaemonIo io;
    io.lidar = &lidar;
    io.chassis = &link;
    io.clock = &clock;
    io.camera = &udp;
    io.camera_own = &own;
    if (fuse_tags) io.tags = &tags;
    if (watch_frames) io.camera_frames = &frames;
    io.stderr_level = dockd::LogLevel::kError;
    if (status != nullptr) {
      camera_status.status = *status;
      io.camera_status = &camera_status;
    }
    daemon = std::make_unique<dockd::Daemon>(cfg, io);
    std::string err;
    CHECK_TRUE_TEXT(daemon->start(err), err.c_str());
  }
  ~CameraRig() {
    daemon.reset();
    std::remove(state_file.c_str());
    std::remove((state_file + ".bak").c_str());
  }
};

}  // namespace

// The scenario parser's static name table is built on first use; build it before CppUTest's per-test leak check
// (as test_dockd_daemon.cpp does).
static const bool kNamesWarm = !docksim::controller_names().empty();

TEST_GROUP(DockdCamera){};

TEST(DockdCamera, EitherSourceFeedsTheTargetAndTheNewerImageWins) {
  CameraRig r(nullptr);
  CHECK_FALSE(r.daemon->camera_target().valid);
  r.own.put(300, 1000);
  r.daemon->on_camera_readable(2000);
  CHECK(r.daemon->camera_target().valid);
  DOUBLES_EQUAL(300, static_cast<double>(r.daemon->camera_target().u_px), 0);
  r.udp.put(310, 1500);
  r.daemon->on_camera_readable(2100);
  DOUBLES_EQUAL(310, static_cast<double>(r.daemon->camera_target().u_px), 0);
  // Both new at once: the newer image, whichever source.
  r.udp.put(320, 3000);
  r.own.put(330, 3500);
  r.daemon->on_camera_readable(4000);
  DOUBLES_EQUAL(330, static_cast<double>(r.daemon->camera_target().u_px), 0);
  r.udp.put(340, 5500);
  r.own.put(350, 5000);
  r.daemon->on_camera_readable(6000);
  DOUBLES_EQUAL(340, static_cast<double>(r.daemon->camera_target().u_px), 0);
}

// The camera part of the status: every camera group, whole, however full the main status is.
std::string camera_part(const dockd::Daemon& d) {
  char buf[dockcore::drivers::kMaxHostReply];
  dockd::JsonWriter w(buf, sizeof buf);
  d.camera_fields(w);
  const std::size_t n = w.finish();
  return std::string(buf, n);
}

TEST(DockdCamera, TheCameraPartCarriesTheCameraFields) {
  dockcore::hal::CameraStatus cs;
  cs.connected = true;
  cs.capture.frames = 42;
  cs.capture.dropped = 3;
  cs.capture.reconnects = 2;
  cs.tag_id = 5;
  CameraRig r(&cs, -1, false, false);
  STRCMP_EQUAL(
      "{\"camera_connected\":true,\"camera_frames\":42,\"camera_dropped\":3,\"camera_late\":0,"
      "\"camera_corrupt\":0,\"camera_reconnects\":2,\"camera_tag_id\":5}",
      camera_part(*r.daemon).c_str());
}

TEST(DockdCamera, StatusWithoutTheCameraFieldsWhenTheyDoNotFit) {
  // Every counter at its largest, beside the tag fusion's fields: more than the status's 1472 bytes.
  dockcore::hal::CameraStatus cs;
  cs.capture.frames = cs.capture.dropped = cs.capture.late = cs.capture.corrupt = 18446744073709551615ull;
  cs.capture.reconnects = 4294967295u;
  cs.tag_id = -1;
  CameraRig r(&cs, 3);
  char st[dockcore::drivers::kMaxHostReply];
  const std::size_t len = r.daemon->status_json(st, sizeof st, 0);
  CHECK(len > 0);
  CHECK_EQUAL(std::strlen(st), len);
  CHECK_EQUAL('}', st[len - 1]);
  CHECK(std::strstr(st, "camera_") == nullptr);
  STRCMP_CONTAINS("\"dock_confirmed\":", st);
  STRCMP_CONTAINS(",\"tag_fused\":", st);
  // The camera part has them.
  const std::string part = camera_part(*r.daemon);
  STRCMP_CONTAINS("\"tag_fused\":0,", part.c_str());
  STRCMP_CONTAINS(",\"camera_frames\":18446744073709551615,", part.c_str());
  STRCMP_CONTAINS(",\"camera_tag_id\":-1}", part.c_str());
}

TEST(DockdCamera, TagPosesReachTheCoreAndAreCountedInTheStatus) {
  CameraRig r(nullptr, 3);
  char st[dockcore::drivers::kMaxHostReply];
  r.daemon->status_json(st, sizeof st, 0);
  // The tag counters, then the lidar mount calibration (the status's last group).
  STRCMP_CONTAINS(",\"tag_fused\":0,\"tag_refused\":[0,0,0,0,0,0,0,0],\"mount_swings\":0,", st);
  // The active dock's tag, another dock's tag, the same frame again.
  r.tags.put(3, r.clock.t - 30000);
  r.tags.put(5, r.clock.t - 20000);
  r.tags.put(3, r.clock.t - 30000);
  r.daemon->on_camera_readable(r.clock.t);
  r.daemon->status_json(st, sizeof st, 0);
  STRCMP_CONTAINS(",\"tag_fused\":1,\"tag_refused\":[1,0,0,0,0,0,1,0],", st);
  // A dock without a tag refuses every tag as another dock's.
  CameraRig none(nullptr, -1);
  none.tags.put(3, none.clock.t);
  none.daemon->on_camera_readable(none.clock.t);
  none.daemon->status_json(st, sizeof st, 0);
  STRCMP_CONTAINS(",\"tag_fused\":0,\"tag_refused\":[1,", st);
}

TEST(DockdCamera, AStalledCameraIsReportedAfterStallMsAndClearedWhenFramesResume) {
  CameraRig r(nullptr, -1, true);
  const std::uint64_t stall_us = std::uint64_t{r.cfg.camera_device.stall_ms} * 1000u;
  CHECK_EQUAL(200000u, stall_us);  // the default
  char st[dockcore::drivers::kMaxHostReply];
  auto tick = [&r] {
    r.clock.t += 20000;  // dockd's 50 Hz tick
    r.daemon->on_tick(r.clock.t);
  };
  // 30 frames/s for a second: never stalled.
  std::uint64_t next_frame = r.clock.t;
  for (int i = 0; i < 50; ++i) {
    while (next_frame <= r.clock.t + 20000) {
      r.frames.last = next_frame;
      next_frame += 33333;
    }
    tick();
    CHECK_FALSE(r.daemon->camera_stalled());
  }
  r.daemon->status_json(st, sizeof st, r.clock.t);
  STRCMP_CONTAINS(",\"camera_stalled\":false}", st);
  // The frames stop: reported on the first tick more than stall_ms after the last one, and not before.
  const std::uint64_t last = r.frames.last;
  while (!r.daemon->camera_stalled()) {
    CHECK(r.clock.t - last <= stall_us);
    tick();
    CHECK(r.clock.t - last <= stall_us + 20000);
  }
  CHECK_EQUAL(1u, r.daemon->counters().camera_stalls);
  r.daemon->status_json(st, sizeof st, r.clock.t);
  STRCMP_CONTAINS(",\"camera_stalled\":true}", st);
  // Still stalled a while later: one stall, counted once.
  for (int i = 0; i < 20; ++i) tick();
  CHECK_TRUE(r.daemon->camera_stalled());
  CHECK_EQUAL(1u, r.daemon->counters().camera_stalls);
  // A frame again: cleared on the next tick; a second stall counts again.
  r.frames.last = r.clock.t + 5000;
  tick();
  CHECK_FALSE(r.daemon->camera_stalled());
  for (int i = 0; i < 12; ++i) tick();
  CHECK_TRUE(r.daemon->camera_stalled());
  CHECK_EQUAL(2u, r.daemon->counters().camera_stalls);
}

TEST(DockdCamera, ACameraThatNeverDeliversStallsFromStartAndNoWatchdogWithoutOne) {
  CameraRig r(nullptr, -1, true);
  const std::uint64_t start = r.clock.t;
  while (!r.daemon->camera_stalled() && r.clock.t - start < 1000000) {
    r.clock.t += 20000;
    r.daemon->on_tick(r.clock.t);
  }
  CHECK_TRUE(r.daemon->camera_stalled());
  CHECK(r.clock.t - start <= 240000);  // the first tick plus stall_ms plus one tick
  // Without a frame monitor (no own camera) there is no watchdog and no field.
  CameraRig none(nullptr);
  for (int i = 0; i < 30; ++i) {
    none.clock.t += 20000;
    none.daemon->on_tick(none.clock.t);
  }
  CHECK_FALSE(none.daemon->camera_stalled());
  char st[dockcore::drivers::kMaxHostReply];
  none.daemon->status_json(st, sizeof st, none.clock.t);
  CHECK(std::strstr(st, "camera_stalled") == nullptr);
}

TEST(DockdCamera, TheStallFlagComesBeforeTheCameraCountersInAFullStatus) {
  // The own camera after a week at 30 frames/s (18 million frames, a million of them dropped, late or corrupt), a
  // week after boot. With the tag fusion's fields and the stall flag the status is about 1.38 kB of its 1472 bytes:
  // the capture counters (about 170 bytes, as the status writes them below) are what is left out, the flag stays.
  dockcore::hal::CameraStatus cs;
  cs.capture.frames = 18144000;
  cs.capture.dropped = cs.capture.late = cs.capture.corrupt = 1000000;
  cs.capture.reconnects = 99999;
  cs.tag_id = 587;
  const std::string camera_fields =
      ",\"camera_connected\":false,\"camera_frames\":18144000,\"camera_dropped\":1000000,\"camera_late\":"
      "1000000,\"camera_corrupt\":1000000,\"camera_reconnects\":99999,\"camera_tag_id\":587";
  CameraRig r(&cs, 3, true);
  for (int i = 0; i < 20; ++i) {
    r.clock.t += 20000;
    r.daemon->on_tick(r.clock.t);
  }
  char st[dockcore::drivers::kMaxHostReply];
  const std::size_t len = r.daemon->status_json(st, sizeof st, 604800000000ull);
  CHECK(len > 0);
  CHECK_EQUAL('}', st[len - 1]);
  STRCMP_CONTAINS(",\"tag_fused\":", st);
  STRCMP_CONTAINS(",\"camera_stalled\":true", st);
  CHECK(std::strstr(st, "\"camera_frames\"") == nullptr);
  const std::string part = camera_part(*r.daemon);
  STRCMP_CONTAINS(",\"camera_stalled\":true", part.c_str());
  STRCMP_CONTAINS(camera_fields.c_str(), part.c_str());
  std::printf("\nstatus: %zu bytes with the stall flag, %zu more for the camera counters, limit %zu\n", len,
              camera_fields.size(), sizeof st - 1);
}
