// TaskManager and Dockcore in closed loop with a scripted fake controller, a kinematic robot and the lidar simulator.
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/dockcore.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "dockcore/perception/tag_measurement.hpp"
#include "dockcore/task/task_manager.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/rng.hpp"

#include "real_tolerance.hpp"
#include "tag_observe.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using dockcore_test::observe_tag;

namespace {

constexpr double kHalfLength = 0.37;  // square footprint default: front edge 0.37 m ahead of the centre

/// Drives straight at the dock origin and reports kArrived on contact; scriptable failure.
class FakeController : public DockingController {
 public:
  const char* name() const override { return "fake"; }
  const char* phase_name(std::uint8_t p) const override { return p == 1 ? "drive" : "idle"; }
  void reset() override { ++resets; }
  ControlOutput step(const ControlInput& in) override {
    ++steps;
    last_aim_m = in.aim_lateral_m;
    ControlOutput o;
    if (in.contact) {
      o.status = ControlStatus::kArrived;
      return o;
    }
    const double x = in.dock_in_robot.x_m, y = in.dock_in_robot.y_m;
    const double gap = std::sqrt(x * x + y * y) - kHalfLength;
    if (in.dock_valid && gap <= arrive_at_gap_m) {  // a success test of its own, contacts or not
      o.status = ControlStatus::kArrived;
      return o;
    }
    if (fail) {
      o.status = ControlStatus::kFailed;
      return o;
    }
    if (!in.dock_valid) {
      o.status = ControlStatus::kLost;
      return o;
    }
    const double bearing = std::atan2(y, x);
    o.phase = 1;
    o.cmd.vx_mps = std::fmax(0.06, std::fmin(0.2, 0.5 * gap));
    o.cmd.wz_radps = 1.5 * bearing;
    return o;
  }
  bool fail = false;
  double last_aim_m = 0;        // ControlInput::aim_lateral_m of the last step
  double arrive_at_gap_m = -1;  // >= 0: also kArrived when the estimate puts the front edge this close to the dock
  int resets = 0;
  int steps = 0;
};

bool moving_state(TaskState s) {
  return s == TaskState::kReachTaskingPoint || s == TaskState::kAlign || s == TaskState::kRetry ||
         s == TaskState::kUndocking;
}

/// World: dock at the origin facing +x, wall flush with its back, robot at 50 Hz, scans and detections at 10 Hz.
struct Sim {
  static constexpr std::uint64_t kTickUs = 20000;
  FakeController ctrl;
  TaskManager tm{ctrl};
  TaskParams params;
  DockProfile profile;
  Pose2 dock{0, 0, 0};
  Pose2 world{1.2, 0.1, kPi};  // truth
  Pose2 odom{1.2, 0.1, kPi};   // odometry (equal until a push)
  Pose2 dock_in_odom{0, 0, 0}; // what the (gating) filter believes
  std::uint64_t now_us = 1000000;
  std::uint64_t dock_stamp_us = 0;
  bool dock_valid = false;
  bool occluded = false;
  bool visible_only_when_turned = false;  // detection only with |yaw - start| > 10°
  bool dock_confirmed = true;             // DockInput::confirmed
  std::vector<Pose2> outliers;            // next detections report these dock poses (world frame), in order
  SceneVerdict outlier_scene = SceneVerdict::kUnknown;  // what the room says on an outlier's scan (SceneCheck)
  bool outlier_at_overruled_place = false;              // outliers lie where the filter was before an overruled restart
  SceneVerdict scene = SceneVerdict::kUnknown;          // what the room says on the other scans
  bool expectation_from_filter = false;  // detections carry the filter's expectation, as Dockcore records it
  double start_yaw = kPi;
  bool charger_works = true;
  int charger_fails_first = 0;  // contacts that get no current (attempts)
  int contacts_made = 0;
  bool contact = false;
  bool prev_contact = false;
  std::uint64_t contact_since_us = 0;
  bool charge_enable = false;
  bool current_stays_on = false;  // undock-failure script; with TaskParams::charger_switched false, a live charger
  bool current_reads_on = false;  // the current sensor reads a current with the contacts open (a stuck sensor)
  bool chassis_ok = true, lidar_ok = true;
  double stop_short_m = 0;       // > 0: something the lidar does not see holds the front edge this far before the dock
  bool wheels_spin = false;      // held there, the wheels keep turning: odometry goes on as commanded
  // The lidar's true mount and the one the task manager is told (plus its calibration's shift): detections are the
  // dock seen by the true lidar, placed through the told mount, as Dockcore places them.
  Pose2 lidar_true{0, 0, 0};
  Pose2 lidar_configured{0, 0, 0};
  std::vector<Vec2> obstacles;   // box centres, 0.1 m boxes
  TaskOutput out;
  std::vector<TaskState> states;  // state changes in order
  int ticks = 0;
  int zero_violations = 0;
  int wait_entries = 0;
  docksim::LidarModel model;
  docksim::Rng rng{1};
  LaserScan scan;
  bool have_scan = false;

  Sim() {
    builtin_profile("breakpoint", profile);
    docksim::lidar_model("ld06", &model);
    model.sigma_const_m = 0;
    model.dropout_prob = 0;
    model.mixed_pixels = false;
    params.detect_wait_s = 0.3;
    tm.configure(params, square_footprint(), profile);
    states.push_back(TaskState::kNotTasking);
  }
  void reconfigure() { tm.configure(params, square_footprint(), profile); }

  docksim::World world_model() const {
    docksim::World w;
    w.add_dock(profile, dock);
    w.add_polyline({Vec2(-0.10, -3.0), Vec2(-0.10, 3.0)});
    for (const Vec2& c : obstacles) w.add_box(c, 0.1, 0.1, 0);
    return w;
  }

  bool detectable() const {
    if (occluded) return false;
    if (visible_only_when_turned && std::fabs(wrap_angle(world.yaw_rad - start_yaw)) < deg_to_rad(10)) return false;
    return true;
  }

  TaskOutput step(HostCommand cmd = HostCommand{}) {
    TaskInput in;
    in.now_us = now_us;
    in.command = cmd;
    in.lidar_mount = lidar_configured;
    in.lidar_mount.x_m += tm.mount_shift_m().x();
    in.lidar_mount.y_m += tm.mount_shift_m().y();
    const Pose2 placed = in.lidar_mount.compose(lidar_true.inverse());  // identity with both mounts at the origin
    const bool scan_tick = ticks % 5 == 0;
    if (scan_tick) {
      simulate_scan(world_model(), world, model, rng, &scan, now_us);
      have_scan = true;
      if (detectable()) {
        dock_valid = true;
        dock_stamp_us = now_us;
        DetectionInput& det = in.detections[0];
        in.detection_count = 1;
        det.fresh = true;
        det.dock_in_robot = placed.compose(world.inverse().compose(dock));
        det.scene = scene;
        if (expectation_from_filter) {
          det.expectation_set = true;
          det.expectation_confirmed = dock_confirmed;
          det.expected_in_odom = dock_in_odom;
        }
        if (!outliers.empty()) {
          det.dock_in_robot = placed.compose(world.inverse().compose(outliers.front()));
          det.scene = outlier_scene;
          det.at_overruled_place = outlier_at_overruled_place;
          outliers.erase(outliers.begin());
        }
        det.odom_at_scan = odom;
        det.stamp_us = now_us;
      }
    }
    const ScanView view = scan.view();
    in.scan = have_scan ? &view : nullptr;
    in.dock.valid = dock_valid;
    in.dock.pose = odom.inverse().compose(dock_in_odom);
    in.dock.stamp_us = dock_stamp_us;
    in.dock.confirmed = dock_confirmed;
    in.odom_pose = odom;
    in.contact = contact;
    const bool current = contact && charge_enable && charger_works && contacts_made > charger_fails_first &&
                         now_us - contact_since_us >= 500000;
    in.charge_current_a = (current || (current_stays_on && contact) || current_reads_on) ? 2.0 : 0.0;
    in.chassis_ok = chassis_ok;
    in.lidar_ok = lidar_ok;
    out = tm.tick(in);
    charge_enable = out.status.charge_enable;
    if (out.status.state != states.back()) {
      states.push_back(out.status.state);
      if (out.status.state == TaskState::kWaitForCharge) ++wait_entries;
    }
    const bool zero = out.cmd.vx_mps == 0 && out.cmd.vy_mps == 0 && out.cmd.wz_radps == 0;
    // Blocked, the robot may only turn on the spot, and only where turning is free.
    const bool blocked_moves =
        out.blocked && (out.cmd.vx_mps != 0 || out.cmd.vy_mps != 0 || !out.obstacles.valid || out.obstacles.rotation);
    if (!zero && (!moving_state(out.status.state) || blocked_moves || out.target_lost)) ++zero_violations;
    // Integrate the commanded body twist exactly (arc) for truth and odometry alike.
    const double dt = kTickUs * 1e-6;
    const Pose2 delta = arc(out.cmd, dt);
    world = world.compose(delta);
    odom = odom.compose(delta);
    // The dock is a hard stop: the front edge may not pass the dock plane (x = 0 in the dock frame), or the plane
    // stop_short_m before it.
    const Vec2 front = dock.inverse_transform(world.transform(Vec2(kHalfLength, 0)));
    if (front.x() < stop_short_m && std::fabs(front.y()) < 0.3) {
      const double back = stop_short_m - front.x();
      world.x_m += back;  // the dock faces +x
      if (!wheels_spin) odom = odom.compose(dockcore_test::pose(-back / std::fabs(std::cos(world.yaw_rad)), 0, 0));
    }
    const Vec2 f2 = dock.inverse_transform(world.transform(Vec2(kHalfLength, 0)));
    contact = f2.x() <= 0.002 && std::fabs(f2.y()) < 0.05;
    if (contact && !prev_contact) {
      contact_since_us = now_us;
      ++contacts_made;
    }
    prev_contact = contact;
    now_us += kTickUs;
    ++ticks;
    return out;
  }
  static Pose2 arc(const Twist2& t, double dt) {
    const double th = t.wz_radps * dt;
    if (std::fabs(th) < 1e-12) return dockcore_test::pose(t.vx_mps * dt, t.vy_mps * dt, 0);
    const double r = t.vx_mps / t.wz_radps;
    return dockcore_test::pose(r * std::sin(th) - t.vy_mps * dt * 0, r * (1 - std::cos(th)) + t.vy_mps * dt, th);
  }
  /// Runs until `state` is reached or `max_s` passes; returns whether it was reached.
  bool run_until(TaskState state, double max_s) {
    const int n = static_cast<int>(max_s / (kTickUs * 1e-6));
    for (int i = 0; i < n; ++i) {
      if (step().status.state == state) return true;
    }
    return false;
  }
  void run_for(double s) {
    const int n = static_cast<int>(s / (kTickUs * 1e-6));
    for (int i = 0; i < n; ++i) step();
  }
  TaskOutput command(HostCommandType t, std::uint16_t id = 0) { return step(HostCommand{t, id}); }
  double centre_to_dock() const { return std::hypot(world.x_m - dock.x_m, world.y_m - dock.y_m); }
  bool saw(TaskState s) const {
    for (TaskState x : states) if (x == s) return true;
    return false;
  }
};

std::unique_ptr<Sim> docked_sim() {
  auto s = std::make_unique<Sim>();
  s->command(HostCommandType::kDock);
  s->run_until(TaskState::kFinishTasking, 30);
  return s;
}

// A final fault raised after backing off: at the staging distance, the contacts open, no charge request, and the
// robot stays where it stopped for watch_s with every tick's command zero.
void check_backed_off_and_standing(Sim& s, double watch_s) {
  REAL_EQUAL(s.params.staging_distance_m, s.centre_to_dock(), 0.004);
  CHECK(!s.contact);
  CHECK(!s.out.status.charge_enable);
  const Pose2 p = s.world;
  s.run_for(watch_s);
  REAL_EQUAL(p.x_m, s.world.x_m, 0);
  LONGS_EQUAL(0, s.zero_violations);
}

}  // namespace

TEST_GROUP(TaskManager){};

TEST(TaskManager, IdleCommandsZeroAndRejections) {
  auto s = std::make_unique<Sim>();
  s->run_for(1.0);
  CHECK(s->out.status.state == TaskState::kNotTasking);
  HostCommand bad;
  bad.type = static_cast<HostCommandType>(99);
  TaskOutput o = s->step(bad);
  CHECK(o.command_result == CommandResult::kRejectedUnknown);
  CHECK(o.status.state == TaskState::kNotTasking);
  CHECK(o.status.last_command == CommandResult::kRejectedUnknown);
  o = s->command(HostCommandType::kUndock);
  CHECK(o.command_result == CommandResult::kRejectedNotDocked);
  CHECK(o.status.state == TaskState::kNotTasking);
  o = s->command(HostCommandType::kDock, 40);
  CHECK(o.command_result == CommandResult::kRejectedDockId);
  CHECK(o.status.state == TaskState::kNotTasking);
  s->run_for(0.5);
  REAL_EQUAL(1.2, s->world.x_m, 1e-12);  // nothing moved
  REAL_EQUAL(0.1, s->world.y_m, 1e-12);
  LONGS_EQUAL(0, s->zero_violations);
}

TEST(TaskManager, HappyPathStateSequenceAndChargeRequest) {
  auto s = std::make_unique<Sim>();
  TaskOutput o = s->command(HostCommandType::kDock, 3);
  CHECK(o.command_result == CommandResult::kAccepted);
  CHECK(o.status.state == TaskState::kGetTaskingCmd);
  CHECK(s->run_until(TaskState::kFinishTasking, 30));
  const std::vector<TaskState> expect = {TaskState::kNotTasking, TaskState::kGetTaskingCmd,
                                         TaskState::kReachTaskingPoint, TaskState::kAlign,
                                         TaskState::kWaitForCharge, TaskState::kFinishTasking};
  CHECK(s->states == expect);
  CHECK(s->out.status.last_result == TaskResult::kDocked);
  CHECK(s->out.status.charge_enable);
  LONGS_EQUAL(3, s->out.status.dock_id);
  LONGS_EQUAL(0, s->out.status.retries);
  // Front edge at the dock plane, near the axis.
  REAL_EQUAL(kHalfLength, s->world.x_m, 0.003);
  // The fake controller aims its centre line at the contacts: the front edge's middle lands on them.
  const Vec2 front = s->world.transform(Vec2(kHalfLength, 0));
  REAL_EQUAL(0.0, front.x(), 0.003);
  CHECK(std::fabs(front.y()) < 0.05);
  s->run_for(5.0);  // stays docked, zero velocity throughout
  CHECK(s->out.status.state == TaskState::kFinishTasking);
  LONGS_EQUAL(0, s->zero_violations);
}

TEST(TaskManager, DetectionSearchSwingsWithinAmplitudeThenFault177) {
  auto s = std::make_unique<Sim>();
  s->occluded = true;
  s->command(HostCommandType::kDock);
  double lo = 0, hi = 0;
  for (int i = 0; i < 3000 && s->out.status.state != TaskState::kFault; ++i) {
    s->step();
    const double d = wrap_angle(s->world.yaw_rad - kPi);
    lo = std::fmin(lo, d);
    hi = std::fmax(hi, d);
  }
  CHECK(s->out.status.state == TaskState::kFault);
  LONGS_EQUAL(177, static_cast<int>(s->out.status.fault));
  const double a = s->params.swing_amplitude_rad;
  // Reached both ends (within the 1° tolerance) and never overshot more than one tick of rotation past them.
  CHECK(hi > a - deg_to_rad(1.01) && hi < a + 0.3 * 0.02 + 1e-9);
  CHECK(lo < -a + deg_to_rad(1.01) && lo > -a - 0.3 * 0.02 - 1e-9);
  const double yaw = s->world.yaw_rad;
  s->run_for(2.0);
  REAL_EQUAL(yaw, s->world.yaw_rad, 0);
  LONGS_EQUAL(0, s->zero_violations);
}

TEST(TaskManager, DetectionDuringSwingStartsAlignment) {
  auto s = std::make_unique<Sim>();
  s->visible_only_when_turned = true;
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 10));
  CHECK(std::fabs(wrap_angle(s->world.yaw_rad - kPi)) >= deg_to_rad(10));
  s->visible_only_when_turned = false;
  CHECK(s->run_until(TaskState::kFinishTasking, 30));
}

TEST(TaskManager, PushSidewaysGives178OnTheSecondDetection) {
  auto s = std::make_unique<Sim>();
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  s->run_for(0.5);
  s->world.y_m += 0.4;  // pushed: odometry does not see it
  // The first detection after the push is suspect only; the second, agreeing with it, confirms the push (one scan
  // cycle, 0.1 s, later) and the fault must appear exactly then.
  while (s->ticks % 5 != 0) {
    s->step();
    CHECK(s->out.status.state == TaskState::kAlign);
  }
  s->step();
  CHECK(s->out.status.state == TaskState::kAlign);
  while (s->ticks % 5 != 0) {
    s->step();
    CHECK(s->out.status.state == TaskState::kAlign);
  }
  s->step();
  CHECK(s->out.status.state == TaskState::kFault);
  LONGS_EQUAL(178, static_cast<int>(s->out.status.fault));
  CHECK(s->out.cmd.vx_mps == 0 && s->out.cmd.wz_radps == 0);
}

TEST(TaskManager, PushGives178OnTheFirstDetectionWhenConfirmIsOne) {
  auto s = std::make_unique<Sim>();
  s->params.deviation.confirm_detections = 1;
  s->tm.configure(s->params, square_footprint(), s->profile);
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  s->run_for(0.5);
  s->world.y_m += 0.4;
  while (s->ticks % 5 != 0) s->step();
  s->step();
  CHECK(s->out.status.state == TaskState::kFault);
  LONGS_EQUAL(178, static_cast<int>(s->out.status.fault));
}

TEST(TaskManager, SingleOutlierDetectionIsNotAFault) {
  auto s = std::make_unique<Sim>();
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  s->run_for(0.5);
  // Clutter taken for the dock once: 0.6 m beside the dock and turned 40° (past both push tolerances).
  s->outliers.push_back(Pose2{0.1, 0.6, deg_to_rad(40)});
  for (int i = 0; i < 50; ++i) {
    s->step();
    CHECK(s->out.status.state == TaskState::kAlign);
  }
  CHECK(s->outliers.empty());
  CHECK(s->run_until(TaskState::kFinishTasking, 30));
}

// Five detections of one place 0.9 m beside the dock, agreeing with each other and failing the push test, with what
// the room says of them (`scene`) and whether they lie where the filter had the dock before an overruled restart:
// `not_a_push` they are counted as overruled and the docking goes on, otherwise they fault 178.
namespace {
void repeated_outliers(SceneVerdict scene, bool at_overruled_place, bool not_a_push) {
  auto s = std::make_unique<Sim>();
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  s->run_for(0.5);
  s->outlier_scene = scene;
  s->outlier_at_overruled_place = at_overruled_place;
  for (int i = 0; i < 5; ++i) s->outliers.push_back(Pose2{0.1, 0.9, 0});
  for (int i = 0; i < 30 && s->out.status.state == TaskState::kAlign; ++i) s->step();
  if (not_a_push) {
    CHECK(s->out.status.state == TaskState::kAlign);
    LONGS_EQUAL(5, static_cast<long>(s->tm.pushes_overruled()));
    CHECK(s->run_until(TaskState::kFinishTasking, 30));
  } else {
    CHECK(s->out.status.state == TaskState::kFault);
    LONGS_EQUAL(178, static_cast<int>(s->out.status.fault));
    LONGS_EQUAL(0, static_cast<long>(s->tm.pushes_overruled()));
  }
}
}  // namespace

// Furniture taken for the dock scan after scan while the dock is hidden: the detections agree with each other and
// fail the push test, but the room stands where odometry puts it, so it is no push. The same detections without
// the room's word are one.
TEST(TaskManager, ARepeatedOutlierWhileTheRoomStandsStillIsNotAPush) {
  repeated_outliers(SceneVerdict::kStill, false, true);
  repeated_outliers(SceneVerdict::kUnknown, false, false);
}

// The filter followed furniture taken for the hidden dock (a restart the room overruled); the dock, seen again where
// the filter had it before, fails the push test against the furniture, and the room is too bare to say anything. It
// is the dock back, not a push. The same detections anywhere else are one (above).
TEST(TaskManager, TheDockSeenAgainWhereItStoodBeforeFurnitureTookOverIsNotAPush) {
  repeated_outliers(SceneVerdict::kUnknown, true, true);
}

// A first look from afar put the dock 0.5 m too near, and the task started on it. Later detections see it where it
// is, beyond the start's distance + distance_growth_margin_m: against a filter resting on that one look only the
// distance is tested, and only the room can tell a push away from a wrong first look. When it stands still, the
// farther distance becomes the start's, and the approach goes on; when it cannot say, the distance test stands.
TEST(TaskManager, AWrongFirstLookIsNotAPushAwayWhenTheRoomStandsStill) {
  for (const bool still : {true, false}) {
    auto s = std::make_unique<Sim>();
    s->world = s->odom = Pose2{1.9, 0.05, kPi};
    s->dock_confirmed = false;
    s->command(HostCommandType::kDock);
    CHECK(s->run_until(TaskState::kAlign, 5));
    s->dock = Pose2{-0.5, 0, 0};  // where the dock really is: 2.4 m out, beyond the start's 1.9 m + 0.3 m
    s->outlier_scene = still ? SceneVerdict::kStill : SceneVerdict::kUnknown;
    for (int i = 0; i < 2; ++i) s->outliers.push_back(s->dock);
    for (int i = 0; i < 40 && s->out.status.state == TaskState::kAlign; ++i) s->step();
    if (still) {
      CHECK(s->out.status.state == TaskState::kAlign);
      // Only the first needed the room: from it on 2.4 m is the start's distance, and the detections there pass.
      LONGS_EQUAL(1, static_cast<long>(s->tm.pushes_overruled()));
    } else {
      CHECK(s->out.status.state == TaskState::kFault);
      LONGS_EQUAL(178, static_cast<int>(s->out.status.fault));
    }
    LONGS_EQUAL(0, s->zero_violations);
  }
}

// The same wrong first look, confirmed: a second look agreed with it, so the filter followed clutter 1.9 m out. The
// dock's detections at 2.4 m are overruled by the room (it stands still) until the filter restarts on the dock; then
// they agree with the filter, and only the distance test is left to judge them. The start's distance must be the
// dock's by then, or the filter's own dock fails it (178) with nothing off the expectation for the room to judge.
TEST(TaskManager, AConfirmedWrongFirstLookIsNotAPushAwayWhenTheRoomStandsStill) {
  auto s = std::make_unique<Sim>();
  s->world = s->odom = Pose2{1.9, 0.05, kPi};
  s->expectation_from_filter = true;  // the clutter's, confirmed
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  s->dock = Pose2{-0.5, 0, 0};  // where the dock really is: 2.4 m out, beyond the start's 1.9 m + 0.3 m
  s->outlier_scene = SceneVerdict::kStill;
  for (int i = 0; i < 3; ++i) s->outliers.push_back(s->dock);
  for (int i = 0; i < 20 && !s->outliers.empty(); ++i) s->step();
  CHECK(s->outliers.empty());
  LONGS_EQUAL(3, static_cast<long>(s->tm.pushes_overruled()));
  s->dock_in_odom = s->dock;  // the filter restarted on the dock: its detections agree with it
  for (int i = 0; i < 40 && s->out.status.state == TaskState::kAlign; ++i) s->step();
  CHECK(s->out.status.state == TaskState::kAlign);
  LONGS_EQUAL(0, s->zero_violations);
}

// One detection off the expectation is a push when the room moved as it implies (SceneCheck says moved): a robot
// shoved so that it then sees the dock only from the side may never get the second, agreeing look. When the room
// cannot tell, the second look is needed.
TEST(TaskManager, OneDetectionIsAPushWhenTheRoomMovedWithIt) {
  for (const bool moved : {true, false}) {
    auto s = std::make_unique<Sim>();
    s->command(HostCommandType::kDock);
    CHECK(s->run_until(TaskState::kAlign, 5));
    s->run_for(0.5);
    s->outlier_scene = moved ? SceneVerdict::kMoved : SceneVerdict::kUnknown;
    s->outliers.push_back(Pose2{0.1, 0.9, 0});
    for (int i = 0; i < 30 && s->out.status.state == TaskState::kAlign; ++i) s->step();
    if (moved) {
      CHECK(s->out.status.state == TaskState::kFault);
      LONGS_EQUAL(178, static_cast<int>(s->out.status.fault));
    } else {
      CHECK(s->out.status.state == TaskState::kAlign);
    }
  }
}

TEST(TaskManager, TwoDisagreeingOutliersInARowAreNotAFault) {
  auto s = std::make_unique<Sim>();
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  s->run_for(0.5);
  // Two wrong detections in a row, 1.2 m apart: they do not agree with each other, so they are not a push.
  s->outliers.push_back(Pose2{0.1, 0.6, 0});
  s->outliers.push_back(Pose2{0.1, -0.6, 0});
  for (int i = 0; i < 50; ++i) {
    s->step();
    CHECK(s->out.status.state == TaskState::kAlign);
  }
  CHECK(s->outliers.empty());
}

// A pushed robot far from its dock finds it in few scans, and one of them may be clutter: the outlier between two
// detections of the pushed dock must not hide the push.
TEST(TaskManager, AnOutlierBetweenTwoDetectionsOfAPushDoesNotHideIt) {
  auto s = std::make_unique<Sim>();
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  s->run_for(0.5);
  s->world.y_m += 0.4;                    // shoved sideways: odometry did not see it
  for (int i = 0; i < 5; ++i) s->step();  // one scan: the dock where the push put it
  CHECK(s->tm.push_suspected());
  s->outliers.push_back(Pose2{0.1, -0.6, 0});  // the next scan: clutter, elsewhere
  for (int i = 0; i < 5; ++i) s->step();
  CHECK(s->outliers.empty());
  CHECK(s->out.status.state == TaskState::kAlign);
  for (int i = 0; i < 5 && s->out.status.state == TaskState::kAlign; ++i) s->step();  // the dock again
  CHECK(s->out.status.state == TaskState::kFault);
  LONGS_EQUAL(178, static_cast<int>(s->out.status.fault));
  LONGS_EQUAL(0, s->zero_violations);
}

TEST(TaskManager, UnconfirmedFilterSkipsThePushTest) {
  auto s = std::make_unique<Sim>();
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  s->run_for(0.5);
  s->world.y_m += 0.4;          // disagrees with the filter by 0.4 m ...
  s->dock_confirmed = false;    // ... but the filter rests on one detection: no evidence of a push
  for (int i = 0; i < 25; ++i) {
    s->step();
    CHECK(s->out.status.state == TaskState::kAlign);
  }
  s->dock_confirmed = true;     // the same disagreement against a confirmed filter: fault within two scans
  for (int i = 0; i < 10 && s->out.status.state == TaskState::kAlign; ++i) s->step();
  CHECK(s->out.status.state == TaskState::kFault);
  LONGS_EQUAL(178, static_cast<int>(s->out.status.fault));
}

// Pushed before a second look confirmed the dock: the filter rests on one detection, which alone is no evidence.
// When the room moved as the detections say, that one detection was right, and the push is reported.
TEST(TaskManager, APushBeforeTheSecondLookIsSeenWhenTheRoomMovedWithIt) {
  for (const SceneVerdict room : {SceneVerdict::kMoved, SceneVerdict::kUnknown}) {
    auto s = std::make_unique<Sim>();
    s->expectation_from_filter = true;
    s->command(HostCommandType::kDock);
    CHECK(s->run_until(TaskState::kAlign, 5));
    s->run_for(0.5);
    s->dock_confirmed = false;
    s->world.y_m += 0.4;
    s->scene = room;
    for (int i = 0; i < 25 && s->out.status.state == TaskState::kAlign; ++i) s->step();
    if (room == SceneVerdict::kMoved) {
      CHECK(s->out.status.state == TaskState::kFault);
      LONGS_EQUAL(178, static_cast<int>(s->out.status.fault));
    } else {
      CHECK(s->out.status.state == TaskState::kAlign);
    }
    LONGS_EQUAL(0, s->zero_violations);
  }
}

TEST(TaskManager, TurnedByHandGives179OnTheSecondDetection) {
  auto s = std::make_unique<Sim>();
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  s->run_for(0.3);
  // Turn about the dock origin by 35°: position relative to the dock keeps its distance, so only the yaw test fires.
  const Pose2 turn{0, 0, deg_to_rad(35)};
  s->world = turn.compose(s->world);
  while (s->ticks % 5 != 0) s->step();
  s->step();
  CHECK(s->out.status.state == TaskState::kAlign);
  while (s->ticks % 5 != 0) s->step();
  s->step();
  CHECK(s->out.status.state == TaskState::kFault);
  LONGS_EQUAL(179, static_cast<int>(s->out.status.fault));
}

TEST(TaskManager, SmallRotationBelowToleranceIsNotAFault) {
  auto s = std::make_unique<Sim>();
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  const Pose2 turn{0, 0, deg_to_rad(25)};  // under 30°, and the position stays on a circle about the dock
  s->world = turn.compose(s->world);
  s->run_for(0.2);
  CHECK(s->out.status.state == TaskState::kAlign);
}

TEST(TaskManager, FarAwayDistanceTolerance178) {
  auto s = std::make_unique<Sim>();
  s->world = s->odom = Pose2{1.5, 0, kPi};
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  // Moved away along the line of sight, odometry seeing it (no push): beyond 2.0 m from the dock.
  const double dx = 2.05 - s->world.x_m;
  s->world.x_m += dx;
  s->odom = s->odom.compose(dockcore_test::pose(-dx, 0, 0));
  // Two detections: one far detection alone could be clutter (DeviationParams::confirm_detections).
  while (s->ticks % 5 != 0) s->step();
  s->step();
  CHECK(s->out.status.state == TaskState::kAlign);
  while (s->ticks % 5 != 0) s->step();
  s->step();
  CHECK(s->out.status.state == TaskState::kFault);
  LONGS_EQUAL(178, static_cast<int>(s->out.status.fault));
}

TEST(TaskManager, StartingFartherThanTheToleranceIsAllowedButNotDrivingAway) {
  auto s = std::make_unique<Sim>();
  s->world = s->odom = Pose2{2.4, 0, kPi};  // the default scenario starts up to 2.5 m away
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  s->run_for(1.0);
  CHECK(s->out.status.state == TaskState::kAlign);
  const double dx = 2.75 - s->world.x_m;  // 0.35 m farther than at the start: beyond the 0.3 m growth margin
  s->world.x_m += dx;
  s->odom = s->odom.compose(dockcore_test::pose(-dx, 0, 0));
  // Two detections: one far detection alone could be clutter (DeviationParams::confirm_detections).
  while (s->ticks % 5 != 0) s->step();
  s->step();
  CHECK(s->out.status.state == TaskState::kAlign);
  while (s->ticks % 5 != 0) s->step();
  s->step();
  LONGS_EQUAL(178, static_cast<int>(s->out.status.fault));
}

TEST(TaskManager, OneSecondOcclusionStopsAndRecovers) {
  auto s = std::make_unique<Sim>();
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  s->run_for(0.5);
  s->occluded = true;
  int lost_ticks = 0;
  for (int i = 0; i < 50; ++i) {
    s->step();
    if (s->out.target_lost) {
      ++lost_ticks;
      CHECK(s->out.cmd.vx_mps == 0 && s->out.cmd.wz_radps == 0);
    }
    CHECK(s->out.status.state == TaskState::kAlign);
  }
  // Lost after 0.5 s without a detection (the last one may be up to 0.1 s before the occlusion).
  CHECK(lost_ticks >= 20 && lost_ticks <= 30);
  s->occluded = false;
  CHECK(s->run_until(TaskState::kFinishTasking, 30));
  LONGS_EQUAL(0, s->zero_violations);
}

TEST(TaskManager, TargetLostTimeout181) {
  auto s = std::make_unique<Sim>();
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  s->occluded = true;
  const std::uint64_t t0 = s->now_us;
  CHECK(s->run_until(TaskState::kFault, 10));
  LONGS_EQUAL(181, static_cast<int>(s->out.status.fault));
  const double waited = (s->now_us - t0) * 1e-6;
  CHECK(waited > 5.0 && waited < 5.8);
  s->run_for(1.0);
  LONGS_EQUAL(0, s->zero_violations);
}

// The last stretch: the lidar loses the dock with the robot's edge a few centimetres from the face (a lidar near the
// robot's front sees only the flat face there). The confirmed estimate, carried by odometry, finishes the approach;
// with blind_finish_m 0 the same loss holds the robot and faults 181.
TEST(TaskManager, TheLastCentimetresRunOnTheOdometryCarriedEstimate) {
  for (const bool blind : {true, false}) {
    auto s = std::make_unique<Sim>();
    if (!blind) {
      s->params.blind_finish_m = 0;
      s->reconfigure();
    }
    s->command(HostCommandType::kDock);
    CHECK(s->run_until(TaskState::kAlign, 5));
    for (int i = 0; i < 3000 && s->centre_to_dock() - kHalfLength > 0.06; ++i) s->step();
    CHECK(s->centre_to_dock() - kHalfLength <= 0.06);
    s->occluded = true;
    int lost_ticks = 0;
    for (int i = 0; i < 1500 && s->out.status.state == TaskState::kAlign; ++i) {
      s->step();
      if (s->out.target_lost) ++lost_ticks;
    }
    if (blind) {
      LONGS_EQUAL(0, lost_ticks);
      CHECK(s->run_until(TaskState::kFinishTasking, 10));
    } else {
      // Lost in the final push for the loss timeout: the robot is at the face without the contacts, an attempt that
      // missed them (retried), not a dock that is gone (181).
      CHECK(lost_ticks > 0);
      CHECK(s->out.status.state == TaskState::kRetry);
      LONGS_EQUAL(0, static_cast<int>(s->out.status.fault));
      CHECK(s->saw(TaskState::kRetry));
    }
    LONGS_EQUAL(0, s->zero_violations);
  }
}

// Far from the dock a loss does not stop the robot: the estimate, carried by odometry, keeps the approach going for
// blind_approach_max_s (a standing robot would keep the view that lost the dock); then it holds and faults 181 after
// the loss timeout. With blind_approach_max_s 0 it holds at once.
TEST(TaskManager, FarFromTheDockALossKeepsTheApproachGoingForAWhile) {
  for (const bool carry : {true, false}) {
    auto s = std::make_unique<Sim>();
    s->world = s->odom = Pose2{2.4, 0.1, kPi};
    // 3 s: short enough that the carry ends while the dock is still far (the default runs on to blind_approach_m).
    s->params.blind_approach_max_s = carry ? 3 : 0;
    s->reconfigure();
    s->command(HostCommandType::kDock);
    CHECK(s->run_until(TaskState::kAlign, 5));
    s->occluded = true;
    const double x0 = s->world.x_m;
    const std::uint64_t lost_from_us = s->dock_stamp_us;
    std::uint64_t held_at_us = 0;
    for (int i = 0; i < 1000 && s->out.status.state == TaskState::kAlign; ++i) {
      s->step();
      if (s->out.target_lost && held_at_us == 0) held_at_us = s->now_us;
    }
    const double held_after_s = static_cast<double>(held_at_us - lost_from_us) * 1e-6;
    const double travelled_m = x0 - s->world.x_m;
    if (carry) {
      CHECK(held_after_s > 2.95 && held_after_s < 3.1);  // blind_approach_max_s
      CHECK(travelled_m > 0.4);
      CHECK(s->centre_to_dock() - kHalfLength > s->params.blind_approach_m);
    } else {
      CHECK(held_after_s > 0.45 && held_after_s < 0.6);  // target_lost_after_s
      CHECK(travelled_m < 0.12);
    }
    LONGS_EQUAL(181, static_cast<int>(s->out.status.fault));
    LONGS_EQUAL(0, s->zero_violations);
  }
}

// The carry ends where the approach stops being far: a loss with the dock within blind_approach_m holds the robot.
TEST(TaskManager, ALossNearTheDockHoldsTheRobot) {
  auto s = std::make_unique<Sim>();
  s->world = s->odom = Pose2{2.4, 0.1, kPi};
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  for (int i = 0; i < 3000 && s->centre_to_dock() - kHalfLength > 1.05; ++i) s->step();
  s->occluded = true;
  std::uint64_t held_at_us = 0;
  const std::uint64_t lost_from_us = s->dock_stamp_us;
  for (int i = 0; i < 500 && held_at_us == 0; ++i) {
    s->step();
    if (s->out.target_lost) held_at_us = s->now_us;
  }
  CHECK(held_at_us != 0);
  CHECK(static_cast<double>(held_at_us - lost_from_us) * 1e-6 < 1.0);
  CHECK(s->centre_to_dock() - kHalfLength < s->params.blind_approach_m);
  LONGS_EQUAL(0, s->zero_violations);
}

// Near the dock but 35° off its axis, a loss keeps the approach going on odometry as far away does: from the side
// the dock shows one flank, and the way towards its axis is what brings it back. Off: the robot stands at once.
TEST(TaskManager, FromTheSideALossKeepsTheApproachGoing) {
  for (const bool carry : {true, false}) {
    auto s = std::make_unique<Sim>();
    s->world = s->odom = Pose2{0.75, 0.52, std::atan2(-0.52, -0.75)};  // 0.91 m out, 34.7° off the axis
    s->params.blind_off_axis_rad = carry ? deg_to_rad(static_cast<Real>(20)) : kPi;
    s->reconfigure();
    s->command(HostCommandType::kDock);
    CHECK(s->run_until(TaskState::kAlign, 5));
    CHECK(s->centre_to_dock() - kHalfLength < s->params.blind_approach_m);  // not "far"
    s->occluded = true;
    const Pose2 from = s->world;
    const std::uint64_t lost_from_us = s->dock_stamp_us;
    std::uint64_t held_at_us = 0;
    for (int i = 0; i < 75; ++i) {  // 1.5 s
      s->step();
      if (s->out.target_lost && held_at_us == 0) held_at_us = s->now_us;
    }
    CHECK(s->out.status.state == TaskState::kAlign);
    const double moved_m = std::hypot(s->world.x_m - from.x_m, s->world.y_m - from.y_m);
    if (carry) {
      LONGS_EQUAL(0, static_cast<long>(held_at_us));
      CHECK(moved_m > 0.1);
    } else {
      const double held_after_s = static_cast<double>(held_at_us - lost_from_us) * 1e-6;
      CHECK(held_after_s > 0.45 && held_after_s < 0.6);  // target_lost_after_s
      CHECK(moved_m < 0.1);
    }
    LONGS_EQUAL(0, s->zero_violations);
  }
}

TEST(TaskManager, ObstacleStopsAndResumes) {
  auto s = std::make_unique<Sim>();
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  // A box 0.15 m ahead of the front edge, on the way to the dock.
  const Vec2 box = s->world.transform(Vec2(kHalfLength + 0.2, 0));
  s->obstacles.push_back(box);
  int blocked = 0;
  for (int i = 0; i < 100; ++i) {
    s->step();
    if (s->out.blocked) ++blocked;
  }
  CHECK(blocked >= 90);
  CHECK(s->out.status.state == TaskState::kAlign);
  CHECK(s->out.obstacles.forward);
  const double x = s->world.x_m;
  s->run_for(0.5);
  REAL_EQUAL(x, s->world.x_m, 0);
  s->obstacles.clear();
  CHECK(s->run_until(TaskState::kFinishTasking, 30));
  LONGS_EQUAL(0, s->zero_violations);
}

// A disc appearing 1.5 cm beyond the front edge (inside the 2 cm self margin; HIL row motion_obstacle,
// docs/reliability.md) must not vanish as "the robot itself": it holds the robot as long as it is there, without a
// fault, and the approach continues once it is gone.
TEST(TaskManager, ObstacleAtTheBumperHoldsTheRobotUntilItLeaves) {
  auto s = std::make_unique<Sim>();
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  s->run_for(0.3);
  const Pose2 at = s->world;
  s->obstacles.push_back(at.transform(Vec2(kHalfLength + 0.015 + 0.05, 0)));  // 0.1 m box, near face 1.5 cm out
  int moving_ticks = 0;
  for (int i = 0; i < 100; ++i) {  // 2 s
    s->step();
    CHECK(s->out.status.state == TaskState::kAlign);
    if (i >= 10 && (s->out.cmd.vx_mps != 0 || s->out.cmd.wz_radps != 0)) ++moving_ticks;
  }
  LONGS_EQUAL(0, moving_ticks);
  CHECK(s->out.blocked);
  // The robot stopped before reaching the box (it saw it at most one scan period late at <= 0.2 m/s).
  const double travelled = at.inverse().compose(s->world).x_m;
  CHECK(travelled < 0.015 + 0.02);
  s->obstacles.clear();
  CHECK(s->run_until(TaskState::kFinishTasking, 30));
  LONGS_EQUAL(0, s->zero_violations);
}

TEST(TaskManager, ObstacleTimeout180) {
  auto s = std::make_unique<Sim>();
  s->params.obstacle_timeout_s = 2.0;
  s->reconfigure();
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  s->obstacles.push_back(s->world.transform(Vec2(kHalfLength + 0.2, 0)));
  CHECK(s->run_until(TaskState::kFault, 3.0));
  LONGS_EQUAL(180, static_cast<int>(s->out.status.fault));
}

TEST(TaskManager, TheDockAndItsWallAreNotObstacles) {
  auto s = docked_sim();
  CHECK(s->out.status.state == TaskState::kFinishTasking);
  // At the contacts the wall is 0.1 m ahead of the front edge: it must not have stopped the approach.
  CHECK(s->saw(TaskState::kWaitForCharge));
  CHECK(!s->saw(TaskState::kFault));
}

TEST(TaskManager, ChargingRetryThenSuccess) {
  auto s = std::make_unique<Sim>();
  s->charger_fails_first = 1;
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kRetry, 30));
  CHECK(!s->out.status.charge_enable);
  LONGS_EQUAL(182, static_cast<int>(s->out.status.retry_reason));  // the attempt ended: no charging current
  LONGS_EQUAL(0, static_cast<int>(s->out.status.fault));
  CHECK(s->run_until(TaskState::kReachTaskingPoint, 20));
  LONGS_EQUAL(0, static_cast<int>(s->out.status.retry_reason));
  // Backed off on odometry until the centre is at the staging distance.
  REAL_EQUAL(s->params.staging_distance_m, s->centre_to_dock(), 0.1 * 0.02 + 0.002);
  LONGS_EQUAL(1, s->out.status.retries);
  CHECK(s->run_until(TaskState::kFinishTasking, 30));
  LONGS_EQUAL(2, s->wait_entries);
  LONGS_EQUAL(0, s->zero_violations);
}

TEST(TaskManager, ChargingExhaustionBacksOffThenFault182) {
  auto s = std::make_unique<Sim>();
  s->charger_works = false;
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kFault, 120));
  LONGS_EQUAL(182, static_cast<int>(s->out.status.fault));
  LONGS_EQUAL(s->params.max_retries + 1, s->wait_entries);
  LONGS_EQUAL(s->params.max_retries, s->out.status.retries);
  check_backed_off_and_standing(*s, 3.0);
}

TEST(TaskManager, ControllerFailureRetriesThenFault188) {
  auto s = std::make_unique<Sim>();
  s->ctrl.fail = true;
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kRetry, 30));
  LONGS_EQUAL(188, static_cast<int>(s->out.status.retry_reason));
  CHECK(s->run_until(TaskState::kFault, 60));
  LONGS_EQUAL(0, static_cast<int>(s->out.status.retry_reason));
  LONGS_EQUAL(188, static_cast<int>(s->out.status.fault));
  LONGS_EQUAL(s->params.max_retries, s->out.status.retries);
}

// Steps until the state changes to `to` (true) or `max_s` passes; `exit_cmd` gets the twist of the tick it changed on.
bool step_until_state(Sim& s, TaskState to, double max_s, Twist2* exit_cmd) {
  const int n = static_cast<int>(max_s / (Sim::kTickUs * 1e-6));
  for (int i = 0; i < n; ++i) {
    const TaskOutput o = s.step();
    if (o.status.state == to) {
      *exit_cmd = o.cmd;
      return true;
    }
  }
  return false;
}

bool is_zero_twist(const Twist2& t) {
  return t.vx_mps == 0 && t.vy_mps == 0 && t.wz_radps == 0;
}

// Contacts closed, no current (a dead charger, an unpowered dock): each attempt ends in RETRY with reason 182, the
// last in fault 182 — retried like any failed attempt — and every exit commands zero on its own tick.
TEST(TaskManager, ContactsClosedWithoutCurrentRetryThenFault182WithZeroOnEveryExit) {
  auto s = std::make_unique<Sim>();
  s->charger_works = false;
  s->params.max_retries = 1;
  s->reconfigure();
  s->command(HostCommandType::kDock);
  Twist2 cmd{1, 1, 1};
  CHECK(step_until_state(*s, TaskState::kWaitForCharge, 30, &cmd));
  CHECK(is_zero_twist(cmd));
  CHECK(s->contact);
  CHECK(step_until_state(*s, TaskState::kRetry, 10, &cmd));
  CHECK(is_zero_twist(cmd));
  LONGS_EQUAL(182, static_cast<int>(s->out.status.retry_reason));
  CHECK(step_until_state(*s, TaskState::kReachTaskingPoint, 20, &cmd));
  CHECK(is_zero_twist(cmd));
  CHECK(step_until_state(*s, TaskState::kRetry, 40, &cmd));
  CHECK(is_zero_twist(cmd));
  LONGS_EQUAL(182, static_cast<int>(s->out.status.retry_reason));
  CHECK(step_until_state(*s, TaskState::kFault, 20, &cmd));
  CHECK(is_zero_twist(cmd));
  LONGS_EQUAL(182, static_cast<int>(s->out.status.fault));
  LONGS_EQUAL(2, s->wait_entries);
  LONGS_EQUAL(0, s->zero_violations);
}

// Something the lidar does not see holds the robot 2 cm before the dock: the estimate says it is not there yet, the
// controller keeps creeping, the wheels stall. The final push ends after max_push_s (its odometry travel well within
// max_push_m), each attempt retries with reason 190 and the last ends in fault 190, backed off and standing.
TEST(TaskManager, HeldShortOfTheContactsThePushEndsOnTimeThenFault190) {
  auto s = std::make_unique<Sim>();
  s->stop_short_m = 0.02;
  s->params.max_retries = 1;
  s->params.max_push_s = 4.0;
  s->reconfigure();
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 10));
  Twist2 cmd{1, 1, 1};
  std::uint64_t push_start_us = 0;
  for (int i = 0; i < 2000 && s->out.status.state == TaskState::kAlign; ++i) {
    const TaskOutput o = s->step();
    if (push_start_us == 0 && s->tm.in_final_push()) push_start_us = s->now_us - Sim::kTickUs;
    if (o.status.state != TaskState::kAlign) cmd = o.cmd;
  }
  CHECK(s->out.status.state == TaskState::kRetry);
  CHECK(is_zero_twist(cmd));
  LONGS_EQUAL(190, static_cast<int>(s->out.status.retry_reason));
  CHECK(!s->saw(TaskState::kWaitForCharge));
  // The bound in time: ended on the first tick past max_push_s, measured from the push's first tick.
  CHECK(s->tm.push_elapsed_s() > 4.0);
  CHECK(s->tm.push_elapsed_s() <= 4.0 + 0.021);
  REAL_EQUAL(s->tm.push_elapsed_s(), (s->now_us - Sim::kTickUs - push_start_us) * 1e-6, 1e-9);
  // It began in the zone: the front edge within push_zone_m of the face by the estimate.
  CHECK(s->tm.push_travel_m() < s->params.max_push_m);
  CHECK(s->tm.push_travel_m() > s->params.push_zone_m - 0.02 - 0.01);
  CHECK(step_until_state(*s, TaskState::kFault, 60, &cmd));
  CHECK(is_zero_twist(cmd));
  LONGS_EQUAL(190, static_cast<int>(s->out.status.fault));
  LONGS_EQUAL(1, s->out.status.retries);
  check_backed_off_and_standing(*s, 2.0);
}

// A Sim whose attempts miss the contacts (held 2 cm short) until lifted, with a short final push.
std::unique_ptr<Sim> missing_sim(bool remember_aim) {
  auto s = std::make_unique<Sim>();
  s->stop_short_m = 0.02;
  s->params.max_push_s = 2.0;
  s->params.remember_aim = remember_aim;
  s->reconfigure();
  return s;
}

// Docks at `id`: the first two attempts miss, the third (aimed one search step to the side) reaches the contacts;
// then undocks.
void dock_on_the_third_attempt(Sim& s, std::uint16_t id) {
  s.command(HostCommandType::kDock, id);
  for (int miss = 0; miss < 2; ++miss) {
    CHECK(s.run_until(TaskState::kRetry, 40));
    CHECK(s.run_until(TaskState::kAlign, 30));
  }
  s.stop_short_m = 0;
  CHECK(s.run_until(TaskState::kFinishTasking, 30));
}

void undock(Sim& s) {
  s.command(HostCommandType::kUndock);
  CHECK(s.run_until(TaskState::kNotTasking, 20));
}

// Starts a docking at `id` and returns the aim its first attempt gives the controller.
double first_aim(Sim& s, std::uint16_t id) {
  s.command(HostCommandType::kDock, id);
  CHECK(s.run_until(TaskState::kAlign, 10));
  s.step();
  return s.ctrl.last_aim_m;
}

// The aim that closed the contacts is the next docking's first aim (remember_aim); a docking that misses the contacts
// to its last attempt forgets it.
TEST(TaskManager, TheAimThatClosedTheContactsIsTheNextDockingsFirstAim) {
  auto s = missing_sim(true);
  const double step_m = static_cast<double>(s->params.retry_lateral_step_m);
  dock_on_the_third_attempt(*s, 3);
  REAL_EQUAL(step_m, s->ctrl.last_aim_m, 1e-9);
  REAL_EQUAL(step_m, static_cast<double>(s->out.status.aim_lateral_m), 1e-9);
  undock(*s);

  REAL_EQUAL(step_m, first_aim(*s, 3), 1e-9);  // the first attempt starts where the last one closed them
  CHECK(s->run_until(TaskState::kFinishTasking, 30));
  LONGS_EQUAL(0, s->out.status.retries);
  undock(*s);

  REAL_EQUAL(0.0, first_aim(*s, 4), 0);  // another dock has no remembered aim
  CHECK(s->run_until(TaskState::kFinishTasking, 30));
  undock(*s);

  s->stop_short_m = 0.02;  // dock 3 now misses to the end: fault 190, and its aim is forgotten
  s->command(HostCommandType::kDock, 3);
  CHECK(s->run_until(TaskState::kFault, 200));
  LONGS_EQUAL(190, static_cast<int>(s->out.status.fault));
  s->stop_short_m = 0;
  REAL_EQUAL(0.0, first_aim(*s, 3), 0);
}

// Contacts that close and open again before the charge is confirmed (the pads at the edge of the contacts' window):
// retried as 182, and counted as a miss by the sideways search, so after one more miss the third attempt aims beside
// the axis instead of on it again.
TEST(TaskManager, ContactsThatDidNotStayClosedAreAMissForTheSidewaysSearch) {
  auto s = missing_sim(true);
  s->stop_short_m = 0;
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kWaitForCharge, 30));
  s->world.x_m += 0.05;  // off the contacts before any current came
  s->step();
  CHECK_FALSE(s->contact);
  CHECK(s->run_until(TaskState::kRetry, 10));
  LONGS_EQUAL(182, static_cast<int>(s->out.status.retry_reason));
  s->stop_short_m = 0.02;  // the second attempt misses
  CHECK(s->run_until(TaskState::kAlign, 30));
  REAL_EQUAL(0.0, s->ctrl.last_aim_m, 0);
  CHECK(s->run_until(TaskState::kRetry, 40));
  CHECK(s->run_until(TaskState::kAlign, 30));
  s->step();
  REAL_EQUAL(static_cast<double>(s->params.retry_lateral_step_m), s->ctrl.last_aim_m, 1e-9);
}

// After the first miss of the contacts the robot backs off, swings on the spot to ±calibration_swing and back (RETRY,
// phase 1), measures from the dock's detections where its lidar sits, and moves the mount: reported once
// (TaskOutput::mount_changed) and kept as mount_shift_m(). The next attempt follows; a second miss in the same task
// does not swing again, and neither does a task with the swing switched off.
TEST(TaskManager, AMissOfTheContactsIsFollowedByACalibrationSwingThatMovesTheMount) {
  auto s = missing_sim(true);
  s->lidar_true = dockcore_test::pose(0.05, 0.012, 0);  // 12 mm left of where it is told
  s->lidar_configured = dockcore_test::pose(0.05, 0, 0);
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kRetry, 40));
  double min_turn = 0, max_turn = 0;
  int swing_ticks = 0, changed = 0;
  double yaw0 = 0;
  bool swinging = false;
  while (s->out.status.state == TaskState::kRetry && s->ticks < 100000) {
    s->step();
    changed += s->out.mount_changed ? 1 : 0;
    if (s->out.status.state != TaskState::kRetry || s->out.status.phase != 1) continue;
    if (!swinging) yaw0 = static_cast<double>(s->world.yaw_rad);
    swinging = true;
    ++swing_ticks;
    CHECK(s->out.cmd.vx_mps == 0);  // on the spot
    const double turn = static_cast<double>(wrap_angle(s->world.yaw_rad - static_cast<Real>(yaw0)));
    min_turn = turn < min_turn ? turn : min_turn;
    max_turn = turn > max_turn ? turn : max_turn;
  }
  CHECK(swing_ticks > 50);
  const double a = static_cast<double>(s->params.calibration_swing_rad);
  REAL_EQUAL(a, max_turn, 0.03);
  REAL_EQUAL(-a, min_turn, 0.03);
  LONGS_EQUAL(1, changed);
  LONGS_EQUAL(1, static_cast<long>(s->tm.calibrations()));
  CHECK(s->tm.last_calibration().status == MountCalibrationStatus::kOk);
  REAL_EQUAL(0.012, s->tm.mount_shift_m().y(), 0.001);
  REAL_EQUAL(0.0, s->tm.mount_shift_m().x(), 0.001);
  CHECK(s->out.status.state == TaskState::kReachTaskingPoint);
  LONGS_EQUAL(1, s->out.status.retries);
  LONGS_EQUAL(0, s->zero_violations);
  // The second miss: backed off and straight on to the next attempt.
  CHECK(s->run_until(TaskState::kRetry, 40));
  CHECK(s->run_until(TaskState::kReachTaskingPoint, 30));
  LONGS_EQUAL(1, static_cast<long>(s->tm.calibrations()));
  // configure() forgets the measure; a host configuring for another dock hands it back (TaskLearned).
  const TaskLearned learned = s->tm.learned();
  s->reconfigure();
  REAL_EQUAL(0.0, s->tm.mount_shift_m().y(), 0);
  CHECK(s->tm.last_calibration().status == MountCalibrationStatus::kNone);
  s->tm.restore_learned(learned);
  REAL_EQUAL(0.012, s->tm.mount_shift_m().y(), 0.001);
  CHECK(s->tm.last_calibration().status == MountCalibrationStatus::kOk);
  LONGS_EQUAL(1, static_cast<long>(s->tm.calibrations()));

  auto off = missing_sim(true);
  off->params.calibrate_mount = false;
  off->reconfigure();
  off->command(HostCommandType::kDock);
  CHECK(off->run_until(TaskState::kRetry, 40));
  CHECK(off->run_until(TaskState::kReachTaskingPoint, 30));
  LONGS_EQUAL(0, static_cast<long>(off->tm.calibrations()));
}

// A swing that something stops (an obstacle where the robot's corners turn) measures nothing: the mount stays and
// the retry goes on, with the motion stopped rather than waiting for the obstacle timeout.
TEST(TaskManager, ASwingAnObstacleStopsChangesNothing) {
  auto s = missing_sim(true);
  s->lidar_true = dockcore_test::pose(0.05, 0.012, 0);
  s->lidar_configured = dockcore_test::pose(0.05, 0, 0);
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kRetry, 40));
  while (s->out.status.phase != 1 && s->ticks < 100000) s->step();
  // A box at the robot's side: turning on the spot sweeps its corners into it.
  s->obstacles.push_back(Vec2(static_cast<double>(s->world.x_m), static_cast<double>(s->world.y_m) + 0.30));
  CHECK(s->run_until(TaskState::kReachTaskingPoint, 10));
  LONGS_EQUAL(1, static_cast<long>(s->tm.calibrations()));
  CHECK(s->tm.last_calibration().status == MountCalibrationStatus::kInterrupted);
  REAL_EQUAL(0.0, s->tm.mount_shift_m().y(), 0);
  CHECK(s->out.status.fault == FaultCode::kNone);
}

// The remembered aims go on into another configuration with the learned state (not with remember_aim off).
TEST(TaskManager, RememberedAimsSurviveAReconfigurationWhenHandedBack) {
  auto s = missing_sim(true);
  s->params.calibrate_mount = false;
  s->reconfigure();
  const double step_m = static_cast<double>(s->params.retry_lateral_step_m);
  dock_on_the_third_attempt(*s, 3);
  undock(*s);
  const TaskLearned learned = s->tm.learned();
  REAL_EQUAL(step_m, learned.remembered_aim_m[3], 1e-9);
  s->reconfigure();
  s->tm.restore_learned(learned);
  REAL_EQUAL(step_m, first_aim(*s, 3), 1e-9);
  CHECK(s->run_until(TaskState::kFinishTasking, 30));
  undock(*s);
  s->params.remember_aim = false;
  s->reconfigure();
  s->tm.restore_learned(learned);
  REAL_EQUAL(0.0, first_aim(*s, 3), 0);
}

TEST(TaskManager, WithoutRememberAimEveryDockingStartsOnTheAxis) {
  auto s = missing_sim(false);
  dock_on_the_third_attempt(*s, 0);
  REAL_EQUAL(static_cast<double>(s->params.retry_lateral_step_m), s->ctrl.last_aim_m, 1e-9);
  undock(*s);
  REAL_EQUAL(0.0, first_aim(*s, 0), 0);
}

// Held short while the wheels spin (slip): odometry runs on, the robot does not. The push ends on its distance,
// well before its time.
TEST(TaskManager, HeldShortWithSpinningWheelsThePushEndsOnDistance) {
  auto s = std::make_unique<Sim>();
  s->stop_short_m = 0.02;
  s->wheels_spin = true;
  s->params.max_push_m = 0.15;
  s->reconfigure();
  s->command(HostCommandType::kDock);
  Twist2 cmd{1, 1, 1};
  CHECK(step_until_state(*s, TaskState::kRetry, 40, &cmd));
  CHECK(is_zero_twist(cmd));
  LONGS_EQUAL(190, static_cast<int>(s->out.status.retry_reason));
  // Ended on the first tick past max_push_m: one tick adds at most the creep's 0.06 m/s × 20 ms.
  CHECK(s->tm.push_travel_m() > 0.15);
  CHECK(s->tm.push_travel_m() <= 0.15 + 0.06 * 0.02 + 1e-9);
  CHECK(s->tm.push_elapsed_s() < s->params.max_push_s);
  CHECK(!s->saw(TaskState::kWaitForCharge));
  LONGS_EQUAL(0, s->zero_violations);
}

// A docking that reaches the contacts is unchanged by the push bound: same ticks, same pose, same states as with
// bounds that can never bind; its push stayed well inside both.
TEST(TaskManager, APushThatReachesTheContactsIsNotCutShort) {
  auto bounded = std::make_unique<Sim>();
  auto unbounded = std::make_unique<Sim>();
  unbounded->params.max_push_m = 1e6;
  unbounded->params.max_push_s = 1e6;
  unbounded->reconfigure();
  for (Sim* s : {bounded.get(), unbounded.get()}) {
    s->command(HostCommandType::kDock);
    CHECK(s->run_until(TaskState::kFinishTasking, 30));
  }
  LONGS_EQUAL(unbounded->ticks, bounded->ticks);
  REAL_EQUAL(unbounded->world.x_m, bounded->world.x_m, 0);
  REAL_EQUAL(unbounded->world.y_m, bounded->world.y_m, 0);
  CHECK(unbounded->states == bounded->states);
  LONGS_EQUAL(1, bounded->wait_entries);
  CHECK(bounded->tm.in_final_push());
  CHECK(bounded->tm.push_travel_m() > 0.08);
  CHECK(bounded->tm.push_travel_m() < 0.5 * bounded->params.max_push_m);
  CHECK(bounded->tm.push_elapsed_s() < 0.5 * bounded->params.max_push_s);
  LONGS_EQUAL(0, bounded->zero_violations);
}

// The push starts only lined up with the dock: a robot passing along the face (heading parallel to it) with its side
// close to it is not pushing.
TEST(TaskManager, ThePushZoneNeedsTheRobotLinedUpWithTheDock) {
  auto s = std::make_unique<Sim>();
  s->world = s->odom = dockcore_test::pose(0.30, 0.6, -kPi / 2);  // 0.30 m out, heading along the face
  s->start_yaw = -kPi / 2;
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 10));
  int checked = 0;
  for (int i = 0; i < 100 && s->out.status.state == TaskState::kAlign; ++i) {
    s->step();
    // Its edge would be past the face were it lined up (centre 0.30 m out, half-length 0.37 m).
    if (std::fabs(std::cos(s->world.yaw_rad)) < 0.7) {
      CHECK(!s->tm.in_final_push());
      ++checked;
    }
  }
  CHECK(checked > 10);
}

// A controller may arrive by a test of its own: when the contacts then never close in WAIT_FOR_CHARGE the robot is
// not on them, and the attempt is "contacts not reached" (190), not a charger fault.
TEST(TaskManager, WaitingWithTheContactsOpenThroughoutIs190) {
  auto s = std::make_unique<Sim>();
  s->stop_short_m = 0.02;
  s->ctrl.arrive_at_gap_m = 0.03;
  s->params.max_retries = 0;
  s->reconfigure();
  s->command(HostCommandType::kDock);
  Twist2 cmd{1, 1, 1};
  CHECK(step_until_state(*s, TaskState::kWaitForCharge, 30, &cmd));
  CHECK(is_zero_twist(cmd));
  CHECK(!s->contact);
  CHECK(step_until_state(*s, TaskState::kRetry, 10, &cmd));
  CHECK(is_zero_twist(cmd));
  LONGS_EQUAL(190, static_cast<int>(s->out.status.retry_reason));
  CHECK(step_until_state(*s, TaskState::kFault, 20, &cmd));
  LONGS_EQUAL(190, static_cast<int>(s->out.status.fault));
  LONGS_EQUAL(0, s->zero_violations);
}

TEST(TaskManager, ContactsLostWhileCharging183) {
  auto s = docked_sim();
  CHECK(s->out.status.state == TaskState::kFinishTasking);
  s->world.x_m += 0.05;  // pulled off the contacts
  s->odom.x_m += 0.0;
  s->step();
  CHECK(!s->contact);
  CHECK(s->run_until(TaskState::kFault, 1.0));
  LONGS_EQUAL(183, static_cast<int>(s->out.status.fault));
  CHECK(!s->out.status.charge_enable);
}

TEST(TaskManager, UndockBacksOffToStagingAndReportsDone) {
  auto s = docked_sim();
  TaskOutput o = s->command(HostCommandType::kUndock);
  CHECK(o.command_result == CommandResult::kAccepted);
  CHECK(o.status.state == TaskState::kUndocking);
  CHECK(!o.status.charge_enable);
  CHECK(s->run_until(TaskState::kNotTasking, 20));
  CHECK(s->out.status.last_result == TaskResult::kUndocked);
  REAL_EQUAL(s->params.staging_distance_m, s->centre_to_dock(), 0.004);
  s->run_for(1.0);
  LONGS_EQUAL(0, s->zero_violations);
}

TEST(TaskManager, UndockAfterAFaultMidBackOffFinishesTheBackOff) {
  // A lidar hold mid back-off faults the undocking with the robot off the contacts, short of the staging point
  // (dockd resumes it with another undock): it must finish backing off, not be refused as "not docked".
  auto s = docked_sim();
  s->command(HostCommandType::kUndock);
  s->run_for(1.0);
  CHECK(s->out.status.state == TaskState::kUndocking);
  CHECK_FALSE(s->contact);
  const double part = s->centre_to_dock();
  CHECK(part < s->params.staging_distance_m - 0.05);
  s->lidar_ok = false;
  s->step();
  LONGS_EQUAL(185, static_cast<int>(s->out.status.fault));
  s->lidar_ok = true;
  s->run_for(0.5);
  REAL_EQUAL(part, s->centre_to_dock(), 0.01);  // stopped while faulted
  TaskOutput o = s->command(HostCommandType::kUndock);
  CHECK(o.command_result == CommandResult::kAccepted);
  CHECK(o.status.state == TaskState::kUndocking);
  LONGS_EQUAL(0, static_cast<int>(o.status.fault));
  CHECK(s->run_until(TaskState::kNotTasking, 20));
  CHECK(s->out.status.last_result == TaskResult::kUndocked);
  REAL_EQUAL(s->params.staging_distance_m, s->centre_to_dock(), 0.01);
  LONGS_EQUAL(0, s->zero_violations);
}

TEST(TaskManager, UndockWaitsForAnObstacleBehind) {
  auto s = docked_sim();
  s->obstacles.push_back(s->world.transform(Vec2(-kHalfLength - 0.15, 0)));
  s->command(HostCommandType::kUndock);
  const double x = s->world.x_m;
  s->run_for(2.0);
  REAL_EQUAL(x, s->world.x_m, 0);
  CHECK(s->out.blocked);
  CHECK(s->out.status.state == TaskState::kUndocking);
  s->obstacles.clear();
  CHECK(s->run_until(TaskState::kNotTasking, 20));
}

// A dock whose charger is live whenever the contacts touch (no relay the host switches): undocking cannot wait for the
// current to stop; the robot backs off at once and the contacts opening end it.
std::unique_ptr<Sim> docked_on_live_charger() {
  auto s = std::make_unique<Sim>();
  s->params.charger_switched = false;
  s->reconfigure();
  s->current_stays_on = true;
  s->command(HostCommandType::kDock);
  s->run_until(TaskState::kFinishTasking, 30);
  return s;
}

TEST(TaskManager, UndockFromALiveChargerBacksOffWithCurrentFlowing) {
  auto s = docked_on_live_charger();
  CHECK(s->out.status.state == TaskState::kFinishTasking);
  s->command(HostCommandType::kUndock);
  s->run_for(0.5);
  CHECK(s->out.status.state == TaskState::kUndocking);
  CHECK_FALSE(s->contact);  // moving off well within charge_off_timeout_s
  CHECK(s->run_until(TaskState::kNotTasking, 20));
  CHECK(s->out.status.last_result == TaskResult::kUndocked);
  CHECK_FALSE(s->saw(TaskState::kFault));
  REAL_EQUAL(s->params.staging_distance_m, s->centre_to_dock(), 0.004);
  LONGS_EQUAL(0, s->zero_violations);
}

TEST(TaskManager, UndockFromALiveChargerFails186WhenCurrentStillFlowsBackedOff) {
  auto s = docked_on_live_charger();
  s->current_reads_on = true;
  s->command(HostCommandType::kUndock);
  CHECK(s->run_until(TaskState::kFault, 20));
  LONGS_EQUAL(186, static_cast<int>(s->out.status.fault));
  check_backed_off_and_standing(*s, 1.0);
}

TEST(TaskManager, UndockFailsWhenCurrentDoesNotStop186) {
  auto s = docked_sim();
  s->current_stays_on = true;
  s->command(HostCommandType::kUndock);
  CHECK(s->run_until(TaskState::kFault, 5));
  LONGS_EQUAL(186, static_cast<int>(s->out.status.fault));
  REAL_EQUAL(kHalfLength, s->world.x_m, 0.003);  // never drove with current flowing
}

TEST(TaskManager, DockWhileDockedIsReportedAndDoesNotMove) {
  auto s = docked_sim();
  TaskOutput o = s->command(HostCommandType::kDock);
  CHECK(o.command_result == CommandResult::kAlreadyDocked);
  CHECK(o.status.state == TaskState::kFinishTasking);
  // After a cancel (charging off) the robot still sits on the contacts: dock confirms charging without moving.
  s->command(HostCommandType::kCancel);
  CHECK(s->out.status.state == TaskState::kNotTasking);
  CHECK(s->out.status.last_result == TaskResult::kCancelled);
  const double x = s->world.x_m;
  o = s->command(HostCommandType::kDock);
  CHECK(o.command_result == CommandResult::kAlreadyDocked);
  CHECK(o.status.state == TaskState::kWaitForCharge);
  CHECK(s->run_until(TaskState::kFinishTasking, 6));
  REAL_EQUAL(x, s->world.x_m, 0);
}

TEST(TaskManager, BusyAndCancelFromEveryActiveState) {
  const TaskState targets[] = {TaskState::kGetTaskingCmd, TaskState::kReachTaskingPoint, TaskState::kAlign,
                               TaskState::kWaitForCharge, TaskState::kRetry};
  for (TaskState target : targets) {
    auto s = std::make_unique<Sim>();
    s->charger_works = false;
    s->command(HostCommandType::kDock);
    if (target != TaskState::kGetTaskingCmd) CHECK(s->run_until(target, 40));
    CHECK(s->out.status.state == target);
    TaskOutput o = s->command(HostCommandType::kTestMode);
    if (s->out.status.state == target) CHECK(o.command_result == CommandResult::kRejectedBusy);
    o = s->command(HostCommandType::kCancel);
    CHECK(o.command_result == CommandResult::kAccepted);
    CHECK(o.status.state == TaskState::kNotTasking);
    CHECK(o.cmd.vx_mps == 0 && o.cmd.wz_radps == 0);
    CHECK(!o.status.charge_enable);
    s->run_for(0.5);
    LONGS_EQUAL(0, s->zero_violations);
  }
}

TEST(TaskManager, StaleChassisAndLidarFaults) {
  auto s = std::make_unique<Sim>();
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kAlign, 5));
  s->lidar_ok = false;
  s->step();
  LONGS_EQUAL(185, static_cast<int>(s->out.status.fault));
  s->lidar_ok = true;
  s->command(HostCommandType::kCancel);
  auto d = docked_sim();
  d->lidar_ok = false;  // not moving: the lidar does not matter while charging
  d->run_for(0.5);
  CHECK(d->out.status.state == TaskState::kFinishTasking);
  d->chassis_ok = false;
  d->step();
  LONGS_EQUAL(184, static_cast<int>(d->out.status.fault));
  LONGS_EQUAL(0, d->zero_violations);
}

TEST(TaskManager, TaskTimeout189) {
  auto s = std::make_unique<Sim>();
  s->params.task_timeout_s = 3.0;
  s->reconfigure();
  s->occluded = true;
  s->params.max_swings = 100;
  s->reconfigure();
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kFault, 4));
  LONGS_EQUAL(189, static_cast<int>(s->out.status.fault));
}

TEST(TaskManager, FaultClearsWithCancelOrANewDock) {
  auto s = std::make_unique<Sim>();
  s->occluded = true;
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kFault, 30));
  TaskOutput o = s->command(HostCommandType::kUndock);  // not on the contacts
  CHECK(o.command_result == CommandResult::kRejectedNotDocked);
  CHECK(o.status.state == TaskState::kFault);
  o = s->command(HostCommandType::kCancel);
  CHECK(o.status.state == TaskState::kNotTasking);
  LONGS_EQUAL(0, static_cast<int>(o.status.fault));
  // A fault also clears with a new dock command, which starts a fresh task.
  s->command(HostCommandType::kDock);
  CHECK(s->run_until(TaskState::kFault, 30));
  s->occluded = false;
  o = s->command(HostCommandType::kDock);
  CHECK(o.command_result == CommandResult::kAccepted);
  CHECK(o.status.state == TaskState::kGetTaskingCmd);
  LONGS_EQUAL(0, static_cast<int>(o.status.fault));
  CHECK(s->run_until(TaskState::kFinishTasking, 30));
}

TEST(TaskManager, TestModeReportsTheDockAndNeverMoves) {
  auto s = std::make_unique<Sim>();
  TaskOutput o = s->command(HostCommandType::kTestMode);
  CHECK(o.status.state == TaskState::kTestMode);
  s->run_for(1.0);
  CHECK(s->out.status.dock_valid);
  const Pose2 truth = s->world.inverse().compose(s->dock);
  REAL_EQUAL(truth.x_m, s->out.status.dock_pose.x_m, 1e-9);
  o = s->command(HostCommandType::kDock);
  CHECK(o.command_result == CommandResult::kRejectedBusy);
  REAL_EQUAL(1.2, s->world.x_m, 0);
  o = s->command(HostCommandType::kCancel);
  CHECK(o.status.state == TaskState::kNotTasking);
  LONGS_EQUAL(0, s->zero_violations);
}

TEST(TaskManager, TestModeReportsItsDockIdAndRefusesABadOne) {
  auto s = std::make_unique<Sim>();
  TaskOutput o = s->command(HostCommandType::kTestMode, 3);
  CHECK(o.command_result == CommandResult::kAccepted);
  CHECK(o.status.state == TaskState::kTestMode);
  LONGS_EQUAL(3, o.status.dock_id);
  s->run_for(0.5);
  LONGS_EQUAL(3, s->out.status.dock_id);
  o = s->command(HostCommandType::kTestMode, 3);  // again on the same dock: nothing changes
  CHECK(o.command_result == CommandResult::kAccepted);
  LONGS_EQUAL(3, o.status.dock_id);
  o = s->command(HostCommandType::kTestMode, 5);  // another dock while testing: cancel first
  CHECK(o.command_result == CommandResult::kRejectedBusy);
  LONGS_EQUAL(3, o.status.dock_id);
  s->command(HostCommandType::kCancel);
  // An id the task manager does not accept is refused and changes nothing.
  s->params.accepted_dock_ids = 0x0Fu;  // ids 0..3
  s->reconfigure();
  o = s->command(HostCommandType::kTestMode, 4);
  CHECK(o.command_result == CommandResult::kRejectedDockId);
  CHECK(o.status.state == TaskState::kNotTasking);
  o = s->command(HostCommandType::kTestMode, 40);
  CHECK(o.command_result == CommandResult::kRejectedDockId);
  CHECK(o.status.state == TaskState::kNotTasking);
  LONGS_EQUAL(0, s->zero_violations);
}

TEST(TaskManager, Deterministic) {
  auto run = [] {
    auto s = std::make_unique<Sim>();
    s->charger_fails_first = 1;
    s->command(HostCommandType::kDock);
    std::vector<double> trace;
    for (int i = 0; i < 2500; ++i) {
      const TaskOutput o = s->step();
      trace.push_back(o.cmd.vx_mps);
      trace.push_back(o.cmd.wz_radps);
      trace.push_back(static_cast<double>(o.status.state));
    }
    return trace;
  };
  const std::vector<double> a = run(), b = run();
  CHECK(a == b);
}

namespace {

/// The camera and tag of the facade tests: camera 0.2 m ahead of the centre at 0.2 m height, an 80 mm tag 0.2 m
/// above the contacts on a 600 px camera.
TagFusionParams facade_tag_params() {
  TagFusionParams p;
  p.mount.x_m = 0.2;
  p.mount.z_m = 0.2;
  p.fx_px = 600;
  p.tag_size_m = 0.08;
  p.dock_tag.id = 3;
  p.dock_tag.z_m = 0.2;
  return p;
}

/// The Sim's world and robot, driven through Dockcore with the real estimator and filter on simulated scans.
struct FacadeSim {
  Sim w;  // world, robot integration and charging script (its TaskManager is unused)
  FakeController ctrl;
  std::unique_ptr<Dockcore> core = std::make_unique<Dockcore>(ctrl);
  FacadeSim() {
    DockcoreConfig cfg;
    cfg.task.detect_wait_s = 0.3;
    CHECK(core->configure(w.profile, cfg));
  }
  /// Tag detections every other tick (25 frames/s), 40 ms old when they arrive, mapped through the odometry pose
  /// at their stamp.
  void enable_tags(const TagFusionParams& p, bool feed = true) {
    DockcoreConfig cfg;
    cfg.task.detect_wait_s = 0.3;
    cfg.tag = p;
    CHECK(core->configure(w.profile, cfg));
    tags_on = feed;
    tag_truth = p;
  }
  TagFusionParams tag_truth{};  // where the tag really is (observe_tag), whatever the core is told
  bool tags_on = false;
  bool lidar_sees_dock = true;  // false: every scan has no returns (no lidar detection; the scans still arrive)
  double tag_sigma_px = static_cast<double>(TagFusionParams{}.sigma_px);  // tags drawn at the model's σ
  docksim::Rng tag_rng{7};  // its own stream: the lidar's noise is the same with and without tags
  struct Past {
    std::uint64_t stamp_us;
    Pose2 world, odom;
  };
  std::vector<Past> past;
  bool scans_on = true;  // false: a lidar gap (the host drops late scans); ticks and odometry go on
  /// The chassis's odometry at the current time, as a host hands it over (ideal: odometry = w.odom).
  void feed_odom() { core->on_odometry(w.odom, Twist2{}, w.now_us); }
  /// Steps to the next scan tick and hands that scan over matched to an odometry sample that lags the robot by
  /// `lag_m` (read late), so its detection lands that far off; then one tick. Scans stay on as they were.
  void late_odometry_scan(double lag_m) {
    const bool on = scans_on;
    scans_on = false;
    while (w.ticks % 5 != 0) step();
    simulate_scan(w.world_model(), w.world, w.model, w.rng, &w.scan, w.now_us);
    // The lagging odometry sample is the one at the scan's stamp; the true pose follows a microsecond later.
    core->on_odometry(w.odom.compose(Pose2{static_cast<Real>(-lag_m), 0, 0}), Twist2{}, w.now_us);
    core->on_scan(w.scan.view(), w.now_us, w.now_us);
    core->on_odometry(w.odom, Twist2{}, w.now_us + 1);
    step();
    scans_on = on;
  }
  bool odom_on = true;  // false: the chassis is silent (no feedback); the robot still moves by the last command
  TickOutput step(HostCommand cmd = HostCommand{}) {
    if (cmd.type != HostCommandType::kNone) {
      QueuedCommand q;
      q.command = cmd;
      core->submit(q);
    }
    if (odom_on) feed_odom();
    if (scans_on && w.ticks % 5 == 0) {
      simulate_scan(w.world_model(), w.world, w.model, w.rng, &w.scan, w.now_us);
      if (!lidar_sees_dock) {
        for (std::size_t i = 0; i < w.scan.count; ++i) w.scan.ranges_m[i] = 0;
      }
      core->on_scan(w.scan.view(), w.now_us, w.now_us);
    }
    past.push_back(Past{w.now_us, w.world, w.odom});
    if (tags_on && w.ticks % 2 == 0 && past.size() > 2) {
      const Past& then = past[past.size() - 3];  // two ticks ago: 40 ms
      core->on_tag(observe_tag(then.world, w.dock, tag_truth, &tag_rng, tag_sigma_px, then.stamp_us));
    }
    TickInput in;
    in.now_us = w.now_us;
    in.contact = w.contact;
    const bool current = w.contact && w.charge_enable && w.now_us - w.contact_since_us >= 500000;
    in.charge_current_a = current ? 2.0 : 0.0;
    const TickOutput o = core->tick(in);
    w.charge_enable = o.status.charge_enable;
    const bool zero = o.cmd.vx_mps == 0 && o.cmd.vy_mps == 0 && o.cmd.wz_radps == 0;
    if (!zero && !moving_state(o.status.state)) ++w.zero_violations;
    // Same integration and dock stop as Sim::step.
    const Pose2 delta = Sim::arc(o.cmd, Sim::kTickUs * 1e-6);
    w.world = w.world.compose(delta);
    w.odom = w.odom.compose(delta);
    const Vec2 front = w.dock.inverse_transform(w.world.transform(Vec2(kHalfLength, 0)));
    if (front.x() < 0 && std::fabs(front.y()) < 0.3) {
      const double back = -front.x();
      w.world.x_m += back;
      w.odom = w.odom.compose(dockcore_test::pose(-back / std::fabs(std::cos(w.world.yaw_rad)), 0, 0));
    }
    const Vec2 f2 = w.dock.inverse_transform(w.world.transform(Vec2(kHalfLength, 0)));
    w.contact = f2.x() <= 0.002 && std::fabs(f2.y()) < 0.05;
    if (w.contact && !w.prev_contact) w.contact_since_us = w.now_us;
    w.prev_contact = w.contact;
    w.now_us += Sim::kTickUs;
    ++w.ticks;
    return o;
  }
  bool run_until(TaskState s, double max_s) {
    for (int i = 0; i < static_cast<int>(max_s / 0.02); ++i) {
      if (step().status.state == s) return true;
    }
    return false;
  }
};

}  // namespace

TEST_GROUP(Dockcore){};

TEST(Dockcore, DocksWithTheRealEstimatorAndFilter) {
  FacadeSim f;
  TickOutput o = f.step(HostCommand{HostCommandType::kDock, 0});
  CHECK(o.command_result == CommandResult::kAccepted);
  CHECK(f.run_until(TaskState::kFinishTasking, 30));
  CHECK(f.core->filter().initialised());
  CHECK(f.core->estimator().counters().found > 10);
  const Vec2 front = f.w.world.transform(Vec2(kHalfLength, 0));
  REAL_EQUAL(0.0, front.x(), 0.003);
  CHECK(std::fabs(front.y()) < 0.05);
  LONGS_EQUAL(0, f.w.zero_violations);
  printf("\nsizeof(Dockcore) = %zu, TaskManager = %zu, DockPoseEstimator = %zu, LaserScan = %zu\n", sizeof(Dockcore),
         sizeof(TaskManager), sizeof(DockPoseEstimator), sizeof(LaserScan));
}

// The learned state handed back after configure() moves the lidar mount in use by the calibration's shift, and keeps
// the deadband floors.
TEST(Dockcore, LearnedStateHandedBackAfterConfigureMovesTheMount) {
  FacadeSim f;
  DockcoreBase::Learned l = f.core->learned();
  l.task.mount_shift_m = Vec2(static_cast<Real>(0.002), static_cast<Real>(-0.011));
  l.task.last_calibration.status = MountCalibrationStatus::kOk;
  DockcoreConfig cfg = f.core->config();
  cfg.lidar_mount = dockcore_test::pose(0.05, 0.01, 0.1);
  CHECK(f.core->configure(f.w.profile, cfg));
  REAL_EQUAL(0.01, f.core->lidar_mount().y_m, 1e-9);
  f.core->restore_learned(l);
  REAL_EQUAL(0.052, f.core->lidar_mount().x_m, 1e-6);
  REAL_EQUAL(-0.001, f.core->lidar_mount().y_m, 1e-6);
  REAL_EQUAL(0.1, f.core->lidar_mount().yaw_rad, 1e-6);
  CHECK(f.core->task_manager().last_calibration().status == MountCalibrationStatus::kOk);
  CHECK(f.core->configure(f.w.profile, cfg));  // a plain configure forgets it
  REAL_EQUAL(0.01, f.core->lidar_mount().y_m, 1e-9);
}

TEST(Dockcore, ScanIsCopiedOnceAndRescanAfterConfigureCopiesNothing) {
  // on_scan() copies the scan once, for the tick; configure() keeps it, and rescan() (what dockd does after
  // reconfiguring) copies nothing and estimates the same dock.
  FacadeSim f;
  CHECK_EQUAL(0u, f.core->last_scan().count);
  simulate_scan(f.w.world_model(), f.w.world, f.w.model, f.w.rng, &f.w.scan, f.w.now_us);
  f.feed_odom();
  const DockEstimate first = *f.core->on_scan(f.w.scan.view(), f.w.now_us, f.w.now_us);
  CHECK_TRUE(first.found);
  CHECK_EQUAL(2 * f.w.scan.count * sizeof(Real), f.core->scan_copy_bytes());
  const ScanView kept = f.core->last_scan();
  CHECK_EQUAL(f.w.scan.count, kept.count);
  CHECK_TRUE(kept.ranges_m != f.w.scan.ranges_m);
  for (std::size_t i = 0; i < kept.count; ++i) CHECK_TRUE(kept.ranges_m[i] == f.w.scan.ranges_m[i]);
  DockcoreConfig cfg;
  cfg.task.detect_wait_s = 0.3;
  CHECK(f.core->configure(f.w.profile, cfg));  // forgets the detections, keeps the scan
  CHECK_EQUAL(kept.count, f.core->last_scan().count);
  const DockEstimate again = f.core->rescan();
  CHECK_EQUAL(0u, f.core->scan_copy_bytes());
  CHECK_EQUAL(kept.count, f.core->last_scan().count);
  CHECK_TRUE(again.found);
  CHECK_TRUE(again.pose.x_m == first.pose.x_m && again.pose.y_m == first.pose.y_m &&
             again.pose.yaw_rad == first.pose.yaw_rad);
}

TEST(Dockcore, PushIsAFaultOnTheFirstScanAfterItWhenTheRoomMovedWithIt) {
  FacadeSim f;
  f.step(HostCommand{HostCommandType::kDock, 0});
  CHECK(f.run_until(TaskState::kAlign, 5));
  for (int i = 0; i < 25; ++i) f.step();
  f.w.world.y_m += 0.4;
  while (f.w.ticks % 5 != 0) f.step();
  // The first scan after the push: the room (the dock's wall, its ends in view) moved as the detection implies.
  const TickOutput o = f.step();
  CHECK(o.status.state == TaskState::kFault);
  LONGS_EQUAL(178, static_cast<int>(o.status.fault));
}

TEST(Dockcore, NoScansMeansLidarStaleWhenMoving) {
  FacadeSim f;
  TickInput in;
  in.now_us = 1000000;
  f.core->on_odometry(Pose2{}, Twist2{}, in.now_us);  // the chassis answers; the lidar never did
  QueuedCommand dock;
  dock.command = HostCommand{HostCommandType::kDock, 0};
  f.core->submit(dock);
  const TickOutput o = f.core->tick(in);
  CHECK(o.status.state == TaskState::kFault);
  LONGS_EQUAL(185, static_cast<int>(o.status.fault));
}

// Right after a push the host's loop stalls, then drains the lidar backlog — several scans through on_scan before the
// next tick (dockd: up to 4 per loop; docs/reliability.md). The filter gates the first two jumps and restarts at the
// pushed pose on the third (reinit_after 3), so a test of the newest detection against the restarted filter would
// see nothing. Every detection must be tested against the filter as it was before that detection.
TEST(Dockcore, PushFollowedByAScanBacklogIsStillReported) {
  for (int turned = 0; turned <= 1; ++turned) {
    for (int backlog = 2; backlog <= 10; ++backlog) {
      FacadeSim f;
      f.step(HostCommand{HostCommandType::kDock, 0});
      CHECK(f.run_until(TaskState::kAlign, 5));
      for (int i = 0; i < 25; ++i) f.step();
      if (turned != 0) {
        f.w.world = Pose2{0, 0, deg_to_rad(static_cast<Real>(40))}.compose(f.w.world);  // about the dock: 179
      } else {
        f.w.world.y_m += 0.4;  // sideways: 178
      }
      // The stall: no tick, the robot stands (its motors time out), scans queue and are then handed over together.
      for (int k = 0; k < backlog; ++k) {
        f.w.now_us += 100000;
        simulate_scan(f.w.world_model(), f.w.world, f.w.model, f.w.rng, &f.w.scan, f.w.now_us);
        f.feed_odom();
        f.core->on_scan(f.w.scan.view(), f.w.now_us, f.w.now_us);
      }
      CHECK(f.core->filter().reinitialisations() >= (backlog >= 3 ? 1u : 0u));  // the filter did adopt the push
      TickInput in;
      in.now_us = f.w.now_us + 1000;
      const TickOutput o = f.core->tick(in);
      CHECK_TEXT(o.status.state == TaskState::kFault, (std::string("backlog ") + std::to_string(backlog)).c_str());
      LONGS_EQUAL(turned != 0 ? 179 : 178, static_cast<int>(o.status.fault));
      CHECK(o.cmd.vx_mps == 0 && o.cmd.wz_radps == 0);
      LONGS_EQUAL(backlog > 8 ? backlog - 8 : 0, static_cast<long>(f.core->detections_dropped()));
    }
  }
}

// On a loaded machine dockd can match a few scans to odometry read late, so their detections sit 3-5 cm off the
// estimate and the filter gates them (docs/reliability.md, "A push right after a filter restart"). A restart needs
// reinit_after (3) gated detections in a row. When the push comes after one or two of them, the first post-push
// detection restarts the filter; with three the filter restarts just before the push. Either way the push test meets
// a filter resting on one detection, which it may not test against. The last confirmed estimate must stay the
// reference until the filter is confirmed again, so the push is reported (179).
TEST(Dockcore, PushRightAfterGatedDetectionsIsStillReported) {
  for (int gated = 1; gated <= 3; ++gated) {
    const std::string what = std::to_string(gated) + " gated detection(s) before the push";
    FacadeSim f;
    f.step(HostCommand{HostCommandType::kDock, 0});
    CHECK_TEXT(f.run_until(TaskState::kAlign, 5), what.c_str());
    for (int i = 0; i < 25; ++i) f.step();
    const std::uint32_t gated0 = f.core->filter().gated(), reinit0 = f.core->filter().reinitialisations();
    // The odometry matched to these scans lags the robot by 5 cm (read late): the detections land 5 cm off.
    for (int k = 0; k < gated; ++k) f.late_odometry_scan(0.05);
    LONGS_EQUAL_TEXT(gated, static_cast<long>(f.core->filter().gated() - gated0 +
                                              (f.core->filter().reinitialisations() - reinit0)), what.c_str());
    f.scans_on = true;
    f.w.world = Pose2{0, 0, deg_to_rad(static_cast<Real>(40))}.compose(f.w.world);  // about the dock: 179
    TickOutput o;
    for (int i = 0; i < 40 && o.status.state != TaskState::kFault; ++i) o = f.step();  // up to 8 scans
    CHECK_TEXT(o.status.state == TaskState::kFault, what.c_str());
    LONGS_EQUAL_TEXT(179, static_cast<int>(o.status.fault), what.c_str());
  }
}

// Far from its dock a robot sees it seldom, and the filter may restart around a push (two looks gated before it,
// the first after it the third): the last fused look 2.5 s before the push, one look after it, then nothing for
// 1.2 s. The next look agrees with the restarted filter, but the confirmed estimate from before, carried by
// odometry, is still the reference (push_check_max_gap_s): 179.
TEST(Dockcore, APushBetweenSparseLooksIsStillReported) {
  FacadeSim f;
  f.step(HostCommand{HostCommandType::kDock, 0});
  CHECK(f.run_until(TaskState::kAlign, 5));
  for (int i = 0; i < 25; ++i) f.step();
  const std::uint32_t reinit0 = f.core->filter().reinitialisations();
  for (int k = 0; k < 2; ++k) f.late_odometry_scan(0.05);  // two looks 5 cm off: gated
  f.lidar_sees_dock = false;
  for (int i = 0; i < 125; ++i) f.step();                                         // 2.5 s without the dock
  f.w.world = Pose2{0, 0, deg_to_rad(static_cast<Real>(40))}.compose(f.w.world);  // turned about the dock
  f.lidar_sees_dock = true;
  while (f.w.ticks % 5 != 0) f.step();
  f.step();  // one look: the third gated, the filter restarts on it
  LONGS_EQUAL(1, static_cast<long>(f.core->filter().reinitialisations() - reinit0));
  f.lidar_sees_dock = false;
  for (int i = 0; i < 60; ++i) f.step();  // 1.2 s
  f.lidar_sees_dock = true;
  TickOutput o;
  for (int i = 0; i < 40 && o.status.state != TaskState::kFault; ++i) o = f.step();
  CHECK(o.status.state == TaskState::kFault);
  LONGS_EQUAL(179, static_cast<int>(o.status.fault));
}

// dockd stalls ~0.9 s around a 0.5 m push and then drops the late scans, so the core gets no detection for ~1 s and
// then only post-push ones. Wheel odometry runs through a lidar gap, so the pre-gap estimate carried by odometry is
// still the expectation: the push must be reported on the second agreeing post-gap detection (178 sideways, 179
// turned about the dock). When the ticks run through a long gap the input watch holds the robot and then faults 185
// (after lidar_stale_ms + fault_after_ms), and dockd's watchdog resume re-issues the dock command: the resumed task
// must still report the push (the new task resets the filter, so the pre-push estimate is the only reference).
// `ticking`: the host kept ticking through the gap (dropped scans) or stalled (no ticks).
TEST(Dockcore, PushDuringALidarGapIsStillReported) {
  const double gaps_s[] = {0.6, 1.0, 2.0};
  for (int ticking = 0; ticking <= 1; ++ticking) {
    for (const double gap_s : gaps_s) {
      for (int turned = 0; turned <= 1; ++turned) {
        char what[96];
        std::snprintf(what, sizeof what, "gap %.1f s, %s, %s", gap_s, turned != 0 ? "turned" : "sideways",
                      ticking != 0 ? "ticking" : "stalled");
        FacadeSim f;
        f.step(HostCommand{HostCommandType::kDock, 0});
        CHECK_TEXT(f.run_until(TaskState::kAlign, 5), what);
        for (int i = 0; i < 25; ++i) f.step();
        while (f.w.ticks % 5 != 1) f.step();  // just after a scan
        const int gap_ticks = static_cast<int>(gap_s / 0.02 + 0.5);
        FaultCode fault = FaultCode::kNone;
        f.scans_on = false;
        for (int k = 0; k < gap_ticks; ++k) {
          if (k == gap_ticks / 2) {
            if (turned != 0) {
              f.w.world = Pose2{0, 0, deg_to_rad(static_cast<Real>(40))}.compose(f.w.world);
            } else {
              f.w.world = f.w.world.compose(Pose2{0, 0.5, 0});
            }
          }
          if (ticking != 0) {
            const TickOutput o = f.step();
            if (o.status.state == TaskState::kFault && fault == FaultCode::kNone) fault = o.status.fault;
          } else {
            f.w.now_us += Sim::kTickUs;  // the host stalls: no tick; the wheels stop (motor timeout)
            ++f.w.ticks;
          }
        }
        // The gap ends with a fresh scan handed over before the next tick (HIL: late scans dropped, then a fresh one).
        while (f.w.ticks % 5 != 0) {
          f.w.now_us += Sim::kTickUs;
          ++f.w.ticks;
        }
        f.scans_on = true;
        if (fault != FaultCode::kNone) {
          // The input watch faulted 185 in the gap (lidar_stale_ms + fault_after_ms), the robot stands. The resume
          // policy re-issues the dock command once scans have been fresh for resume_after_ms; the resumed task must
          // still report the push, not dock on from the pushed pose.
          LONGS_EQUAL_TEXT(185, static_cast<int>(fault), what);
          CHECK_TEXT(ticking != 0 && gap_s > 1.2, what);
          CHECK_TEXT(f.core->resume_pending(), what);
          const Pose2 at = f.w.world;
          TickOutput resumed;
          for (int i = 0; i < 100 && resumed.resume == ResumeEvent::kNone; ++i) resumed = f.step();
          CHECK_TEXT(resumed.resume == ResumeEvent::kResumed && resumed.command_taken && resumed.command.resume, what);
          CHECK_TEXT(resumed.command_result == CommandResult::kAccepted, what);
          // Resumed on the first tick at which both inputs had been fresh for resume_after_ms.
          const std::uint64_t fresh_for_us = f.w.now_us - Sim::kTickUs - f.core->inputs().fresh_since_us();
          const std::uint64_t resume_after_us = f.core->config().watchdog.resume_after_ms * 1000u;
          CHECK_TEXT(fresh_for_us >= resume_after_us && fresh_for_us < resume_after_us + Sim::kTickUs, what);
          const Pose2 moved = at.inverse().compose(f.w.world);
          CHECK_TEXT(std::fabs(moved.x_m) < 1e-4 && std::fabs(moved.y_m) < 1e-4, what);  // stood still until then
          TickOutput o;
          for (int i = 0; i < 500; ++i) {
            o = f.step();
            if (o.status.state == TaskState::kFault || o.status.state == TaskState::kFinishTasking) break;
          }
          CHECK_TEXT(o.status.state == TaskState::kFault, what);
          LONGS_EQUAL_TEXT(turned != 0 ? 179 : 178, static_cast<int>(o.status.fault), what);
          continue;
        }
        while (f.w.ticks % 5 != 0) f.step();
        // The first post-gap detection faults when the room moved with it, else it is a suspect and the second,
        // agreeing one confirms the push.
        TickOutput o = f.step();
        if (o.status.state == TaskState::kAlign) {
          while (f.w.ticks % 5 != 0) f.step();
          o = f.step();
        }
        CHECK_TEXT(o.status.state == TaskState::kFault, what);
        LONGS_EQUAL_TEXT(turned != 0 ? 179 : 178, static_cast<int>(o.status.fault), what);
      }
    }
  }
}

TEST(Dockcore, DriveCommandIsSaturatedRateLimitedAndZeroedAtOnce) {
  // Tolerances are float ulps at these magnitudes (the float build's Real).
  FacadeSim f;
  DockcoreConfig cfg;
  cfg.task.detect_wait_s = 0.3;
  cfg.limits.max_vx_mps = 0.2;
  cfg.limits.max_linear_accel_mps2 = 0.5;
  cfg.limits.max_angular_accel_radps2 = 2.0;
  cfg.control_period_s = 0.02;
  CHECK(f.core->configure(f.w.profile, cfg));
  f.step(HostCommand{HostCommandType::kDock, 0});
  bool moved = false;
  Twist2 prev{};
  for (int i = 0; i < 400 && f.core->task_manager().state() != TaskState::kFinishTasking; ++i) {
    const TickOutput o = f.step();
    const bool want_zero = o.cmd.vx_mps == 0 && o.cmd.vy_mps == 0 && o.cmd.wz_radps == 0;
    if (want_zero) {
      // A stop is sent at once, however fast the robot was going.
      CHECK(o.drive_cmd.vx_mps == 0 && o.drive_cmd.wz_radps == 0);
    } else {
      moved = true;
      CHECK(std::fabs(o.drive_cmd.vx_mps) <= 0.2 + 1e-5);
      CHECK(std::fabs(o.drive_cmd.vx_mps - prev.vx_mps) <= 0.5 * 0.02 + 1e-5);
      CHECK(std::fabs(o.drive_cmd.wz_radps - prev.wz_radps) <= 2.0 * 0.02 + 1e-5);
    }
    // The wheels realise exactly the shaped twist.
    const WheelSpeeds w = twist_to_wheels(cfg.drive, o.drive_cmd);
    LONGS_EQUAL(2, static_cast<long>(o.wheels.count));
    REAL_EQUAL(w.radps[0], o.wheels.radps[0], 0);
    REAL_EQUAL(w.radps[1], o.wheels.radps[1], 0);
    // drive_cmd() reports the last tick's shaped command.
    CHECK(f.core->drive_cmd().vx_mps == o.drive_cmd.vx_mps && f.core->drive_cmd().vy_mps == o.drive_cmd.vy_mps &&
          f.core->drive_cmd().wz_radps == o.drive_cmd.wz_radps);
    prev = o.drive_cmd;
  }
  CHECK(moved);
}

TEST(Dockcore, StaleChassisHoldsTheDriveThenFaultsAndTheRampRestartsFromRest) {
  FacadeSim f;
  f.step(HostCommand{HostCommandType::kDock, 0});
  TickOutput o;
  for (int i = 0; i < 200; ++i) {
    o = f.step();
    if (o.drive_cmd.vx_mps != 0) break;
  }
  CHECK(o.drive_cmd.vx_mps != 0);
  // The chassis falls silent (scans go on): held once its newest feedback is older than chassis_stale_ms. The task
  // manager still wants to move; the drive gets zero.
  const WatchdogParams wd = f.core->config().watchdog;
  const std::uint64_t silent_from_us = f.w.now_us - Sim::kTickUs;  // the last feedback's stamp
  f.odom_on = false;
  TickOutput held;
  while (f.w.now_us - silent_from_us <= wd.chassis_stale_ms * 1000u) {
    held = f.step();
    CHECK(!f.core->inputs().chassis_stale());
  }
  held = f.step();
  CHECK(f.core->inputs().chassis_stale());
  CHECK(held.status.state == TaskState::kAlign || held.status.state == TaskState::kReachTaskingPoint);
  CHECK(held.cmd.vx_mps != 0 || held.cmd.wz_radps != 0);
  CHECK(held.drive_cmd.vx_mps == 0 && held.drive_cmd.wz_radps == 0);
  CHECK(held.wheels.radps[0] == 0 && held.wheels.radps[1] == 0);
  // Back before fault_after_ms: the same task continues, the acceleration limit ramping up from rest.
  f.odom_on = true;
  const TickOutput next = f.step();
  CHECK(!f.core->inputs().chassis_stale());
  CHECK(next.status.fault == FaultCode::kNone);
  const DriveLimits lim = f.core->config().limits;
  CHECK(std::fabs(next.drive_cmd.vx_mps) <= lim.max_linear_accel_mps2 * f.core->config().control_period_s + 1e-5);
  // Silent for the hold and fault_after_ms: fault 184, the wheels at zero throughout.
  const std::uint64_t again_us = f.w.now_us - Sim::kTickUs;
  f.odom_on = false;
  TickOutput last;
  while (f.w.now_us - again_us <= (wd.chassis_stale_ms + wd.fault_after_ms) * 1000u + 20000u) {
    last = f.step();
    if (f.w.now_us - again_us > wd.chassis_stale_ms * 1000u + 20000u) {
      CHECK(last.wheels.radps[0] == 0 && last.wheels.radps[1] == 0);
    }
  }
  CHECK(last.status.state == TaskState::kFault);
  LONGS_EQUAL(184, static_cast<int>(last.status.fault));
  CHECK_EQUAL(2u, f.core->inputs().chassis_trips());
}

// A scan stamped in a gap of the odometry (no feedback for longer than Odometry::kMaxGapUs) is placed at the pose
// before the gap, however far the robot drove meanwhile: its detection is counted and neither fused nor tested for
// a push. Once feedback returns, detections are fused again and the docking goes on.
TEST(Dockcore, ADetectionInAnOdometryGapIsNeitherFusedNorTestedForAPush) {
  FacadeSim f;
  f.step(HostCommand{HostCommandType::kDock, 0});
  CHECK(f.run_until(TaskState::kAlign, 5));
  for (int i = 0; i < 25; ++i) f.step();
  CHECK(f.core->filter().initialised());
  LONGS_EQUAL(0, static_cast<long>(f.core->detections_unplaced()));
  const std::uint64_t fused_before_us = f.core->filter().last_update_us();
  // The chassis falls silent for 0.3 s (held after chassis_stale_ms, no fault yet); scans go on.
  f.odom_on = false;
  for (int i = 0; i < 15; ++i) f.step();
  CHECK(f.core->detections_unplaced() >= 1);
  const std::uint64_t fused_in_gap_us = f.core->filter().last_update_us();
  // Scans of the first 0.2 s are still placed by the last feedback; none after it.
  CHECK(fused_in_gap_us - fused_before_us <= Odometry::kMaxGapUs + 2 * Sim::kTickUs);
  f.odom_on = true;
  TickOutput o;
  for (int i = 0; i < 20; ++i) o = f.step();
  CHECK(f.core->filter().last_update_us() > fused_in_gap_us);
  CHECK(o.status.fault == FaultCode::kNone);
  CHECK(o.status.state == TaskState::kAlign);
}

TEST(Dockcore, AChassisOutageFaultIsResumedAtMostMaxResumesTimes) {
  FacadeSim f;
  const WatchdogParams wd = f.core->config().watchdog;
  f.step(HostCommand{HostCommandType::kDock, 0});
  CHECK(f.run_until(TaskState::kAlign, 5));
  // Silent chassis: held, then fault 184 after fault_after_ms; the dock command waits for fresh data.
  auto outage = [&f, &wd]() {
    f.odom_on = false;
    TickOutput o;
    for (int i = 0; i < 200 && o.status.state != TaskState::kFault; ++i) o = f.step();
    LONGS_EQUAL(184, static_cast<int>(o.status.fault));
    CHECK(f.core->resume_pending());
    f.odom_on = true;
    // Fresh again: the command is issued again after resume_after_ms, not before.
    int ticks = 0;
    for (; ticks < 200 && o.resume == ResumeEvent::kNone; ++ticks) o = f.step();
    CHECK(ticks * 20 >= static_cast<int>(wd.resume_after_ms));
    return o;
  };
  for (std::uint8_t n = 1; n <= wd.max_resumes; ++n) {
    const TickOutput o = outage();
    CHECK(o.resume == ResumeEvent::kResumed);
    CHECK(o.command_taken && o.command.resume && o.command.command.type == HostCommandType::kDock);
    CHECK(o.command_result == CommandResult::kAccepted);
    LONGS_EQUAL(n, o.resumes);
    CHECK(f.run_until(TaskState::kAlign, 5));
  }
  const TickOutput last = outage();
  CHECK(last.resume == ResumeEvent::kGivenUp);
  CHECK_FALSE(last.command_taken);
  CHECK(last.status.state == TaskState::kFault);
  CHECK_FALSE(f.core->resume_pending());
  // A host's dock is a new task: its resumes count from zero.
  TickOutput o = f.step(HostCommand{HostCommandType::kDock, 0});
  CHECK(o.command_taken && !o.command.resume);
  LONGS_EQUAL(0, o.resumes);
}

TEST(Dockcore, AStopWhileFaultedForgetsTheInterruptedCommand) {
  FacadeSim f;
  f.step(HostCommand{HostCommandType::kDock, 0});
  CHECK(f.run_until(TaskState::kAlign, 5));
  f.odom_on = false;
  TickOutput o;
  for (int i = 0; i < 200 && o.status.state != TaskState::kFault; ++i) o = f.step();
  CHECK(f.core->resume_pending());
  f.step(HostCommand{HostCommandType::kCancel, 0});
  CHECK_FALSE(f.core->resume_pending());
  f.odom_on = true;
  for (int i = 0; i < 100; ++i) CHECK(f.step().resume == ResumeEvent::kNone);
}

TEST(Dockcore, CommandsWaitWhileTheHostHoldsThem) {
  FacadeSim f;
  QueuedCommand dock;
  dock.command = HostCommand{HostCommandType::kDock, 0};
  dock.token = 7;
  CHECK(f.core->submit(dock) == SubmitResult::kQueued);
  CHECK(f.core->next_command() != nullptr && f.core->next_command()->token == 7);
  f.feed_odom();
  TickInput in;
  in.now_us = f.w.now_us;
  in.hold_commands = true;
  TickOutput o = f.core->tick(in);
  CHECK_FALSE(o.command_taken);
  CHECK(o.status.state == TaskState::kNotTasking);
  in.hold_commands = false;
  o = f.core->tick(in);
  CHECK(o.command_taken);
  LONGS_EQUAL(7, static_cast<long>(o.command.token));
  CHECK(f.core->next_command() == nullptr);
}

TEST(Dockcore, LateScansAreNotUsedAndALongLidarGapFaults) {
  FacadeSim f;
  f.step(HostCommand{HostCommandType::kDock, 0});
  CHECK(f.run_until(TaskState::kAlign, 5));
  const std::uint32_t found = f.core->estimator().counters().found;
  // A scan read more than lidar_stale_ms after its turn ended (a backlog): counted, not used.
  const WatchdogParams wd = f.core->config().watchdog;
  simulate_scan(f.w.world_model(), f.w.world, f.w.model, f.w.rng, &f.w.scan, f.w.now_us);
  const std::uint64_t read_us = f.w.now_us + 100000 + wd.lidar_stale_ms * 1000u + 1000u;
  CHECK(f.core->on_scan(f.w.scan.view(), f.w.now_us, read_us) == nullptr);
  CHECK_EQUAL(1u, f.core->inputs().late_scans());
  CHECK_EQUAL(found, f.core->estimator().counters().found);
  // No scans: held after lidar_stale_ms, fault 185 after fault_after_ms more.
  f.scans_on = false;
  bool held = false;
  TickOutput o;
  for (int i = 0; i < 100 && o.status.state != TaskState::kFault; ++i) {
    o = f.step();
    if (f.core->inputs().lidar_stale() && o.status.state != TaskState::kFault) {
      held = true;
      CHECK(o.drive_cmd.vx_mps == 0 && o.drive_cmd.wz_radps == 0);
    }
  }
  CHECK(held);
  CHECK(o.status.state == TaskState::kFault);
  LONGS_EQUAL(185, static_cast<int>(o.status.fault));
}

TEST(TaskManager, StatesAndCommandResultsHaveTheirStableNames) {
  // States by wire code (0-4 are seed 004's AutoContainerState names, docs/task-manager.md).
  const char* const states[] = {"NOT_TASKING",     "GET_TASKING_CMD", "REACH_TASKING_POINT", "ALIGN", "FINISH_TASKING",
                                "WAIT_FOR_CHARGE", "RETRY",           "UNDOCKING",           "FAULT", "TEST_MODE"};
  for (int s = 0; s < 10; ++s) STRCMP_EQUAL(states[s], to_string(static_cast<TaskState>(s)));
  STRCMP_EQUAL("UNKNOWN", to_string(static_cast<TaskState>(10)));
  // Command results by wire code; the rejections are the names docs/faults.md gives for code 187.
  const char* const results[] = {
      "none",         "accepted", "already_docked", "rejected_unknown", "rejected_dock_id", "rejected_not_docked",
      "rejected_busy"};
  for (int r = 0; r < 7; ++r) STRCMP_EQUAL(results[r], to_string(static_cast<CommandResult>(r)));
  STRCMP_EQUAL("unknown", to_string(static_cast<CommandResult>(7)));
}

TEST(Dockcore, TagAloneDocksWhenTheLidarSeesNoDock) {
  // The lidar still scans (the obstacle check needs it) but never detects the dock: the tag alone docks.
  FacadeSim f;
  f.enable_tags(facade_tag_params());
  f.lidar_sees_dock = false;
  f.step(HostCommand{HostCommandType::kDock, 0});
  CHECK(f.run_until(TaskState::kFinishTasking, 30));
  LONGS_EQUAL(0, f.core->estimator().counters().found);
  CHECK(f.core->tag_count(TagStatus::kFused) > 100);
  LONGS_EQUAL(0, f.core->tag_count(TagStatus::kStale) + f.core->tag_count(TagStatus::kOutOfOrder));
  const Vec2 front = f.w.world.transform(Vec2(kHalfLength, 0));
  REAL_EQUAL(0.0, front.x(), 0.003);
  CHECK(std::fabs(front.y()) < 0.05);
  // Tags add no evidence: the sequential test is the lidar's.
  REAL_EQUAL(0.0, f.core->filter().evidence_nats(), 0);
  CHECK_FALSE(f.core->filter().confirmed());
  LONGS_EQUAL(0, f.w.zero_violations);
}

TEST(Dockcore, TagWithoutScansIsStillLidarStale) {
  // The tag replaces the lidar's dock detection, not its obstacle check: no scans at all is still fault 185.
  FacadeSim f;
  f.enable_tags(facade_tag_params());
  f.scans_on = false;
  TickOutput o = f.step(HostCommand{HostCommandType::kDock, 0});
  for (int i = 0; i < 100 && o.status.state != TaskState::kFault; ++i) o = f.step();
  CHECK(o.status.state == TaskState::kFault);
  LONGS_EQUAL(185, static_cast<int>(o.status.fault));
}

TEST(Dockcore, LidarAndTagFusedAreAtLeastAsAccurateAsLidarAlone) {
  // The same lidar noise (σ 10 mm, its own random stream) with and without tags; the robot stands 1.2 m off the
  // dock at several bearings; the filter's dock after 2 s against the truth.
  double se_lidar[3] = {0, 0, 0}, se_fused[3] = {0, 0, 0};
  int n = 0;
  for (int seed = 1; seed <= 12; ++seed) {
    for (int tags = 0; tags <= 1; ++tags) {
      FacadeSim f;
      f.w.model.sigma_const_m = 0.01;
      f.w.rng = docksim::Rng(static_cast<std::uint64_t>(seed));
      f.w.world = f.w.odom = dockcore_test::pose(1.2, -0.15 + 0.025 * seed, kPi + 0.02 * (seed - 6));
      if (tags != 0) f.enable_tags(facade_tag_params());
      for (int i = 0; i < 100; ++i) f.step();
      CHECK(f.core->filter().initialised());
      const Pose2 est = f.core->filter().dock_in_robot(f.w.odom);
      const Pose2 truth = f.w.world.inverse().compose(f.w.dock);
      const double e[3] = {est.x_m - truth.x_m, est.y_m - truth.y_m, wrap_angle(est.yaw_rad - truth.yaw_rad)};
      for (int k = 0; k < 3; ++k) (tags != 0 ? se_fused : se_lidar)[k] += e[k] * e[k];
      if (tags != 0) CHECK(f.core->tag_count(TagStatus::kFused) > 40);
    }
    ++n;
  }
  const char* names[3] = {"x", "y (lateral)", "yaw"};
  for (int k = 0; k < 3; ++k) {
    const double lidar = std::sqrt(se_lidar[k] / n), fused = std::sqrt(se_fused[k] / n);
    printf("\n%s RMS: lidar %.5f, lidar + tag %.5f", names[k], lidar, fused);
    CHECK_TEXT(fused <= lidar, names[k]);
  }
  printf("\n");
}

TEST(Dockcore, WrongIdStaleAndOutOfOrderTagsAreCountedAndChangeNothing) {
  FacadeSim f;
  const TagFusionParams p = facade_tag_params();
  f.enable_tags(p, false);               // configured, fed by hand below
  for (int i = 0; i < 6; ++i) f.step();  // scans at ticks 0 and 5
  const std::uint64_t scan_us = f.core->last_scan().stamp_us;
  CHECK(f.core->filter().initialised());
  auto tag_at = [&](std::uint64_t stamp_us) { return observe_tag(f.w.world, f.w.dock, p, nullptr, 0, stamp_us); };
  auto check_refused = [&](const TagObservation& o, TagStatus want) {
    const Pose2 dock = f.core->filter().dock_in_odom();
    const Mat3 cov = f.core->filter().covariance_odom();
    const std::uint32_t fused = f.core->filter().tag_fused(), before = f.core->tag_count(want);
    CHECK_EQUAL_TEXT(static_cast<int>(want), static_cast<int>(f.core->on_tag(o)), to_string(want));
    const Pose2 d = f.core->filter().dock_in_odom();
    CHECK(d.x_m == dock.x_m && d.y_m == dock.y_m && d.yaw_rad == dock.yaw_rad);
    CHECK(f.core->filter().covariance_odom() == cov);
    LONGS_EQUAL(fused, f.core->filter().tag_fused());
    LONGS_EQUAL(before + 1, f.core->tag_count(want));
  };
  check_refused(tag_at(scan_us - 60000), TagStatus::kStale);  // 60 ms before the newest scan (bound 50 ms)
  CHECK(f.core->on_tag(tag_at(scan_us - 40000)) == TagStatus::kFused);
  LONGS_EQUAL(1, f.core->filter().tag_fused());
  check_refused(tag_at(scan_us - 45000), TagStatus::kOutOfOrder);  // older than the previous frame
  check_refused(tag_at(scan_us - 40000), TagStatus::kOutOfOrder);  // the same frame again
  TagObservation wrong = tag_at(scan_us);
  wrong.id = 4;  // another dock's tag
  check_refused(wrong, TagStatus::kWrongId);
  TagObservation behind = tag_at(scan_us + 1);
  behind.translation_m.z() = -behind.translation_m.z();
  check_refused(behind, TagStatus::kBehind);
  TagObservation nan = tag_at(scan_us + 2);
  nan.rotation(0, 0) = std::nan("");
  check_refused(nan, TagStatus::kInvalid);
  CHECK(f.core->on_tag(tag_at(scan_us + 3)) == TagStatus::kFused);
  // A frame taken in a gap of the odometry (no feedback for 0.3 s) cannot be placed: stale too.
  f.odom_on = false;
  for (int i = 0; i < 15; ++i) f.step();
  check_refused(tag_at(f.core->last_scan().stamp_us), TagStatus::kStale);
  f.odom_on = true;
  f.step();
  // A dock without a tag (id −1) takes none.
  TagFusionParams none = p;
  none.dock_tag.id = -1;
  f.enable_tags(none, false);
  for (int i = 0; i < 5; ++i) f.step();
  check_refused(tag_at(f.core->last_scan().stamp_us), TagStatus::kWrongId);
}

TEST(Dockcore, AMisplacedTagIsGatedAndDoesNotOverruleTheLidar) {
  // The tag's configured place is 0.3 m off: with the lidar fusing, its measurements are gated and never restart
  // the filter; the lidar's dock stands.
  FacadeSim f;
  TagFusionParams told = facade_tag_params();
  told.dock_tag.y_m = 0.3;
  f.enable_tags(told);
  f.tag_truth = facade_tag_params();  // where the tag really is
  for (int i = 0; i < 200; ++i) f.step();
  CHECK(f.core->tag_count(TagStatus::kGated) > 50);
  LONGS_EQUAL(0, f.core->filter().reinitialisations());
  const Pose2 est = f.core->filter().dock_in_robot(f.w.odom);
  const Pose2 want = f.w.world.inverse().compose(f.w.dock);
  REAL_EQUAL(want.y_m, est.y_m, 0.01);
}
