// dockd's control tick under a 30 frames/s camera load, in real time: the Daemon docking in the simulated world
// (dockd_sim_rig.hpp) at 50 Hz on CLOCK_MONOTONIC, first without a camera, then with the real detection thread
// (CameraPipeline + libapriltag, decimate 2) on drawn 640×480 frames holding the dock's tag, 30 per second, whose
// tag poses the tick fuses. Prints each run's worst and 99th-percentile tick duration (the Daemon's own
// tick_work_worst_us: the time inside on_tick) and the camera thread's figures. Figures, not timed assertions: the
// checks are that the camera really ran (frames, tag poses reaching the tick) and the docking went on.
// DOCKD_LOAD_SECONDS sets each run's length (default 5).
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/drivers/apriltag_detector.hpp"
#include "dockcore/drivers/camera_pipeline.hpp"
#include "dockd_sim_rig.hpp"
#include "docksim/rng.hpp"

#include "CppUTest/TestHarness.h"

namespace {

std::uint64_t mono_us() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000u + static_cast<std::uint64_t>(ts.tv_nsec) / 1000u;
}

void sleep_until_us(std::uint64_t t_us) {
  timespec ts{static_cast<time_t>(t_us / 1000000u), static_cast<long>((t_us % 1000000u) * 1000u)};
  while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
  }
}

struct RealClock final : dockcore::hal::Clock {
  std::uint64_t now_us() const override { return mono_us(); }
};

constexpr int kTagId = 3;
constexpr std::uint32_t kW = 640, kH = 480;

/// A camera delivering one drawn frame (the dock's tag, 8 px cells) every `period_us`, stamped at delivery.
struct DrawnCamera final : dockcore::hal::CameraFrameSource {
  std::vector<std::uint8_t> grey = std::vector<std::uint8_t>(static_cast<std::size_t>(kW) * kH, 128);
  std::uint64_t period_us = 33333;
  std::uint64_t next_us = 0;
  dockcore::hal::CameraFrameCounters c{};
  DrawnCamera() {
    CHECK_TRUE(dockcore::drivers::draw_tag_upright("tag36h11", kTagId, 8, 280, 200, grey.data(), kW, kH, kW));
  }
  dockcore::hal::CameraFrameStatus next_frame(dockcore::hal::CameraFrame& out, int timeout_ms) override {
    const std::uint64_t now = mono_us();
    if (next_us == 0) next_us = now;
    if (next_us > now + static_cast<std::uint64_t>(timeout_ms) * 1000u) {
      sleep_until_us(now + static_cast<std::uint64_t>(timeout_ms) * 1000u);
      return dockcore::hal::CameraFrameStatus::kTimeout;
    }
    sleep_until_us(next_us);
    next_us += period_us;
    out.grey = grey.data();
    out.width_px = kW;
    out.height_px = kH;
    out.stride_bytes = kW;
    out.stamp_us = mono_us();
    out.sequence = static_cast<std::uint32_t>(c.frames);
    ++c.frames;
    return dockcore::hal::CameraFrameStatus::kFrame;
  }
  bool connected() const override { return true; }
  const dockcore::hal::CameraFrameCounters& counters() const override { return c; }
  const char* last_error() const override { return ""; }
};

struct Run {
  std::uint64_t ticks = 0, worst_work_us = 0, p99_work_us = 0, worst_period_us = 0;
  std::uint64_t frames = 0, tag_poses = 0, tag_fused = 0;
  double detect_worst_ms = 0;
  bool docking = false;
};

/// Docks for `seconds` in real time, with or without the camera thread.
Run dock_for(bool with_camera, double seconds) {
  docksim::Scenario sc = docksim::load_scenario_file(dockd_test::default_scenario_path());
  dockd::DockdConfig cfg = dockd_test::scenario_config(sc);
  cfg.state_file = "/tmp/dockd_test_camera_load_" + std::to_string(::getpid());
  cfg.docks[0].tag.id = kTagId;
  cfg.camera_device.enabled = with_camera;
  cfg.camera_device.tag.intrinsics = dockcore::drivers::CameraIntrinsics{600, 600, 319.5, 239.5};
  cfg.camera_device.tag.tag_size_m = 0.08;
  dockd_test::SimClock sim_clock;  // the simulated chassis's stamps: set to real time every tick
  sim_clock.t = mono_us();
  RealClock clock;
  dockd_test::SimChassis link;
  dockd_test::SimLidar lidar;
  dockd_test::FakeHost host;
  auto chassis = dockd_test::scenario_chassis(sc, link, sim_clock);
  chassis->set_true_pose(docksim::start_from(sc, 1.5, 0.2, 0.1).robot_world);
  const docksim::World world = docksim::scenario_world(sc, true);
  docksim::Rng rng(3);

  DrawnCamera camera;
  std::string err;
  std::unique_ptr<dockcore::drivers::TagDetector> detector;
  std::unique_ptr<dockcore::drivers::CameraPipeline> pipeline;
  dockd::DaemonIo io;
  io.lidar = &lidar;
  io.chassis = &link;
  io.can_host = &host;
  io.clock = &clock;
  io.stderr_level = dockd::LogLevel::kError;
  if (with_camera) {
    detector = dockcore::drivers::TagDetector::create(cfg.camera_device.tag, err);
    CHECK_TRUE_TEXT(detector != nullptr, err.c_str());
    dockcore::drivers::CameraPipelineOptions po;
    po.target_id = kTagId;
    pipeline = dockcore::drivers::CameraPipeline::start(camera, *detector, po, err);
    CHECK_TRUE_TEXT(pipeline != nullptr, err.c_str());
    io.camera_own = pipeline.get();
    io.tags = pipeline.get();
    io.camera_frames = pipeline.get();
  }
  auto daemon = std::make_unique<dockd::Daemon>(cfg, io);
  CHECK_TRUE_TEXT(daemon->start(err), err.c_str());

  Run r;
  std::vector<std::uint64_t> work;
  const std::uint64_t start = mono_us();
  std::uint64_t next_tick = start, next_scan = start;
  bool commanded = false;
  while (next_tick - start < static_cast<std::uint64_t>(seconds * 1e6)) {
    sleep_until_us(next_tick);
    const std::uint64_t now = mono_us();
    for (int i = 0; i < 4; ++i) chassis->step();
    sim_clock.t = now;
    if (now >= next_scan) {
      next_scan += 100000;
      docksim::simulate_scan(world, chassis->state().true_pose.compose(sc.lidar_mount), sc.lidar, rng, lidar.scan.get(),
                             now);
      lidar.pending = true;
    }
    if (!commanded && !daemon->lidar_stale() && !daemon->chassis_stale()) {
      host.command(1, 0);
      commanded = true;
    }
    const std::uint64_t t0 = mono_us();
    daemon->on_tick(t0);
    work.push_back(mono_us() - t0);
    next_tick += 20000;
  }
  r.ticks = daemon->tick_stats().ticks;
  r.worst_work_us = daemon->tick_stats().worst_work_us;
  r.worst_period_us = daemon->tick_stats().worst_period_us;
  std::sort(work.begin(), work.end());
  r.p99_work_us = work[std::min(work.size() - 1, work.size() * 99 / 100)];
  r.docking = daemon->state() == dockcore::TaskState::kAlign;
  for (std::uint32_t n : daemon->counters().tags) r.tag_poses += n;
  r.tag_fused = daemon->counters().tags[static_cast<std::size_t>(dockcore::TagStatus::kFused)];
  if (pipeline) {
    const dockcore::drivers::CameraPipelineStats s = pipeline->stats();
    r.frames = s.frames_processed;
    r.detect_worst_ms = s.detect_worst_ms;
    pipeline->stop();
  }
  daemon.reset();
  std::remove(cfg.state_file.c_str());
  std::remove((cfg.state_file + ".bak").c_str());
  return r;
}

void print(const char* name, const Run& r, double seconds) {
  double load[3] = {0, 0, 0};
  const int nl = ::getloadavg(load, 3);
  std::printf(
      "{\"type\":\"tick_load\",\"camera\":\"%s\",\"seconds\":%.1f,\"ticks\":%llu,\"tick_work_worst_us\":%llu,"
      "\"tick_work_p99_us\":%llu,\"tick_period_worst_us\":%llu,\"camera_frames\":%llu,\"tag_poses\":%llu,"
      "\"tag_fused\":%llu,\"detect_worst_ms\":%.2f,\"load_avg_1min\":%.2f}\n",
      name, seconds, static_cast<unsigned long long>(r.ticks), static_cast<unsigned long long>(r.worst_work_us),
      static_cast<unsigned long long>(r.p99_work_us), static_cast<unsigned long long>(r.worst_period_us),
      static_cast<unsigned long long>(r.frames), static_cast<unsigned long long>(r.tag_poses),
      static_cast<unsigned long long>(r.tag_fused), r.detect_worst_ms, nl > 0 ? load[0] : -1.0);
  std::fflush(stdout);
}

}  // namespace

// The scenario parser's static name table is built on first use; build it before CppUTest's per-test leak check.
static const bool kNamesWarm = !docksim::controller_names().empty();

TEST_GROUP(DockdCameraLoad){};

TEST(DockdCameraLoad, WorstTickWithAndWithoutA30FpsCamera) {
  const char* env = std::getenv("DOCKD_LOAD_SECONDS");
  const double seconds = env != nullptr ? std::atof(env) : 5.0;
  CHECK_TRUE(seconds >= 1.0);
  const Run quiet = dock_for(false, seconds);
  print("none", quiet, seconds);
  const Run loaded = dock_for(true, seconds);
  print("30fps", loaded, seconds);
  CHECK_TRUE(quiet.docking);
  CHECK_TRUE(loaded.docking);
  // The camera really loaded the process: most frames detected, and their tag poses reached the tick.
  CHECK_TEXT(static_cast<double>(loaded.frames) >= 0.8 * 30 * seconds, std::to_string(loaded.frames).c_str());
  CHECK_TEXT(static_cast<double>(loaded.tag_poses) >= 0.8 * 30 * seconds, std::to_string(loaded.tag_poses).c_str());
}
