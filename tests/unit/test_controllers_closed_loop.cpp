// The four docking controllers in closed loop: an ideal plant (exact SE(2) integration of the commanded twist, a
// hand-written contact model) and docksim::Chassis (latency, motor lag, deadband, slip, contact physics), from a fixed
// set of starts. Perception is ideal: dock_in_robot from the true poses, the camera target from a pinhole projection
// of the dock origin, the lidar scan raycast analytically against a wall along the dock face.
// Set DOCKCORE_CTL_REPORT=1 to print one line per run (the figures in docs/controllers.md).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "dockcore/control/controllers.hpp"
#include "dockcore/control/kinematics.hpp"
#include "docksim/chassis.hpp"

#include "docking_starts.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using dockcore_test::deg;
using dockcore_test::kCtlDt;
using dockcore_test::kPadReach;
using dockcore_test::kPiD;
using dockcore_test::Start;
using dockcore_test::start_pose;
using dockcore_test::wrapd;

namespace {

constexpr double kFaceHalf = 0.15;
constexpr double kMaxTime = 120.0;

// The fixed start set: distance 0.5–2.5 m, bearing ±45°, heading ±30°.
const Start kStarts[] = {{0.5, 0, 0},    {0.8, 10, -10}, {1.0, 20, -15}, {1.0, -30, 20}, {1.5, 45, 0},
                         {1.5, -45, 30}, {2.0, 10, -30}, {2.5, -20, 10}, {2.5, 45, -30}, {2.5, -45, 30}};
constexpr std::size_t kNumStarts = sizeof(kStarts) / sizeof(kStarts[0]);

// ---- sensors --------------------------------------------------------------------------------------------------------
constexpr std::size_t kBeams = 720;
struct Sensors {
  Real ranges[kBeams];
  ScanView view;
};

// Lidar at the robot centre, 0.5° beams, returns from a 2 m wall along the dock face (dock frame x = 0, |y| <= 1).
void raycast(const Pose2& robot_in_dock, Sensors* s) {
  for (std::size_t i = 0; i < kBeams; ++i) {
    const double a = static_cast<double>(robot_in_dock.yaw_rad) - kPiD + static_cast<double>(i) * (2.0 * kPiD / kBeams);
    const double dx = std::cos(a), dy = std::sin(a);
    double r = 0;
    if (dx < -1e-9) {
      const double t = -static_cast<double>(robot_in_dock.x_m) / dx;
      const double yh = static_cast<double>(robot_in_dock.y_m) + t * dy;
      if (t > 0.05 && t < 12.0 && std::fabs(yh) <= 1.0) r = t;
    }
    s->ranges[i] = static_cast<Real>(r);
  }
  s->view.ranges_m = s->ranges;
  s->view.intensities = nullptr;
  s->view.count = kBeams;
  s->view.angle_min_rad = -kPi;
  s->view.angle_increment_rad = kTwoPi / static_cast<Real>(kBeams);
}

// Camera at the robot centre looking forward, fx 500, cx 320, 640 px wide: the dock origin's column.
CameraTarget camera_of(const Pose2& dock_in_robot, std::uint64_t now_us) {
  CameraTarget c;
  const double x = static_cast<double>(dock_in_robot.x_m), y = static_cast<double>(dock_in_robot.y_m);
  if (x > 0.02) {
    const double u = 320.0 - 500.0 * y / x;
    if (u >= 0 && u <= 640) {
      c.valid = true;
      c.u_px = static_cast<Real>(u);
      c.v_px = 240;
      c.confidence = 1;
      c.stamp_us = now_us;
    }
  }
  return c;
}

// ---- plants ---------------------------------------------------------------------------------------------------------
enum class PlantKind { kIdeal, kChassis };

struct RunSpec {
  PlantKind plant = PlantKind::kIdeal;
  DriveKind drive = DriveKind::kDifferential;
  bool backwards = false;
  bool with_camera = false;
  std::uint64_t seed = 7;
};

struct RunResult {
  bool arrived = false;
  bool failed = false;
  double time_s = 0;
  double lateral_m = 0, yaw_deg = 0;  // true pad errors at the end
  int reversals = 0;
  double max_inplace_deg = 0;  // largest contiguous turn with |vx|,|vy| < 5 mm/s
  bool zero_after_arrival = true;
  std::uint8_t last_phase = 0;
  std::size_t ncmd = 0;
};

// Exact SE(2) motion for a constant body twist (arc with sideways component).
Pose2 exact_step(const Pose2& p, double vx, double vy, double wz, double dt) {
  const double th = wz * dt;
  double a, b;
  if (std::fabs(th) < 1e-9) {
    a = 1 - th * th / 6;
    b = th / 2;
  } else {
    a = std::sin(th) / th;
    b = (1 - std::cos(th)) / th;
  }
  const double bx = (a * vx - b * vy) * dt, by = (b * vx + a * vy) * dt;
  const double c = std::cos(static_cast<double>(p.yaw_rad)), s = std::sin(static_cast<double>(p.yaw_rad));
  return Pose2{static_cast<Real>(static_cast<double>(p.x_m) + c * bx - s * by),
               static_cast<Real>(static_cast<double>(p.y_m) + s * bx + c * by),
               static_cast<Real>(wrapd(static_cast<double>(p.yaw_rad) + th))};
}

struct PadState {
  double x, y, yaw_err;
};
PadState pad_of(const Pose2& robot_in_dock, bool backwards) {
  const double sgn = backwards ? -1.0 : 1.0;
  const double c = std::cos(static_cast<double>(robot_in_dock.yaw_rad)),
               s = std::sin(static_cast<double>(robot_in_dock.yaw_rad));
  PadState p;
  p.x = static_cast<double>(robot_in_dock.x_m) + c * sgn * kPadReach;
  p.y = static_cast<double>(robot_in_dock.y_m) + s * sgn * kPadReach;
  p.yaw_err = wrapd(static_cast<double>(robot_in_dock.yaw_rad) + (backwards ? 0.0 : kPiD));
  return p;
}

docksim::ChassisParams chassis_params(const RunSpec& spec) {
  docksim::ChassisParams cp;
  cp.geometry.kind =
      spec.drive == DriveKind::kMecanum ? docksim::DriveKind::kMecanum : docksim::DriveKind::kDifferential;
  cp.footprint.pad_side = spec.backwards ? docksim::PadSide::kRear : docksim::PadSide::kFront;
  return cp;
}

DriveGeometry core_geometry(const docksim::ChassisParams& cp) {
  DriveGeometry g;
  g.kind = cp.geometry.kind == docksim::DriveKind::kMecanum ? DriveKind::kMecanum : DriveKind::kDifferential;
  g.wheel_radius_m = static_cast<Real>(cp.geometry.wheel_radius_m);
  g.wheel_base_m = static_cast<Real>(cp.geometry.wheel_base_m);
  g.lx_m = static_cast<Real>(cp.geometry.lx_m);
  g.ly_m = static_cast<Real>(cp.geometry.ly_m);
  return g;
}

// Runs one docking; the dock frame is the world frame. `cmds` (optional, capacity cap) records every command.
RunResult run_docking(DockingController& ctl, const RunSpec& spec, const Start& st, Twist2* cmds = nullptr,
                      std::size_t cap = 0) {
  ctl.reset();
  RunResult res;
  const docksim::ChassisParams cp = chassis_params(spec);
  const DriveGeometry geom = core_geometry(cp);
  DriveLimits lim;
  lim.max_vx_mps = static_cast<Real>(0.4);
  lim.max_wz_radps = static_cast<Real>(1.0);
  lim.max_wheel_radps = static_cast<Real>(20);
  lim.max_linear_accel_mps2 = static_cast<Real>(0.5);
  lim.max_angular_accel_radps2 = static_cast<Real>(2.0);

  docksim::Chassis chassis(cp, spec.seed);
  docksim::DockPlacement dp;
  dp.pose_world = Pose2{};
  dp.face_half_width_m = kFaceHalf;
  chassis.set_dock(dp);
  Pose2 pose = start_pose(st, spec.backwards);
  chassis.set_true_pose(pose);
  chassis.reset_odometry(pose);
  Pose2 odom = pose;
  bool ideal_contact = false;
  Twist2 prev_cmd{}, measured{};
  static Sensors sensors;
  double t = 0, inplace_acc = 0;
  int last_sign = 0;
  double arrived_at = -1;
  while (t < kMaxTime) {
    const std::uint64_t now_us = static_cast<std::uint64_t>(std::llround(t * 1e6));
    ControlInput in;
    in.now_us = now_us;
    in.dt_s = static_cast<Real>(kCtlDt);
    in.dock_valid = true;
    in.dock_in_robot = pose.inverse();  // dock frame = world frame
    in.dock_stamp_us = now_us;
    in.odom_pose = odom;
    in.measured_twist = measured;
    if (spec.with_camera) {
      in.camera = camera_of(in.dock_in_robot, now_us);
      raycast(pose, &sensors);
      in.scan = &sensors.view;
    }
    if (spec.plant == PlantKind::kChassis) {
      in.contact = chassis.state().contact;
      in.charging = chassis.state().charging;
    } else {
      in.contact = ideal_contact;
    }
    const ControlOutput out = ctl.step(in);
    res.last_phase = out.phase;
    if (cmds != nullptr && res.ncmd < cap) cmds[res.ncmd] = out.cmd;
    ++res.ncmd;
    if (out.status != ControlStatus::kRunning) {
      if (out.cmd.vx_mps != 0 || out.cmd.vy_mps != 0 || out.cmd.wz_radps != 0) res.zero_after_arrival = false;
    }
    if (out.status == ControlStatus::kArrived && arrived_at < 0) {
      arrived_at = t;
      res.arrived = true;
      res.time_s = t;
    }
    if (out.status == ControlStatus::kFailed) {
      res.failed = true;
      res.time_s = t;
      break;
    }
    if (arrived_at >= 0 && t - arrived_at > 1.0) break;  // keep stepping one second after arrival
    // Motion metrics on the command.
    const double vx = static_cast<double>(out.cmd.vx_mps), vy = static_cast<double>(out.cmd.vy_mps);
    const int sgn = vx > 1e-4 ? 1 : (vx < -1e-4 ? -1 : 0);
    if (sgn != 0) {
      if (last_sign != 0 && sgn != last_sign) ++res.reversals;
      last_sign = sgn;
    }
    if (std::fabs(vx) < 0.005 && std::fabs(vy) < 0.005 && std::fabs(static_cast<double>(out.cmd.wz_radps)) > 1e-4) {
      inplace_acc += std::fabs(static_cast<double>(out.cmd.wz_radps)) * kCtlDt;
      if (inplace_acc * 180.0 / kPiD > res.max_inplace_deg) res.max_inplace_deg = inplace_acc * 180.0 / kPiD;
    } else {
      inplace_acc = 0;
    }
    // Kinematics as the task manager applies it.
    Twist2 cmd = saturate_twist(geom, lim, out.cmd);
    cmd = limit_acceleration(lim, prev_cmd, cmd, static_cast<Real>(kCtlDt));
    prev_cmd = cmd;
    if (spec.plant == PlantKind::kChassis) {
      const WheelSpeeds w = twist_to_wheels(geom, cmd);
      docksim::WheelRadps wr{};
      for (std::size_t i = 0; i < w.count; ++i) wr[i] = static_cast<double>(w.radps[i]);
      chassis.command_wheels(wr);
      for (int k = 0; k < 4; ++k) chassis.step();  // 4 x 5 ms
      const docksim::ChassisState& s = chassis.state();
      pose = s.true_pose;
      odom = s.odom_pose;
      WheelSpeeds m;
      m.count = w.count;
      for (std::size_t i = 0; i < m.count; ++i) m.radps[i] = static_cast<Real>(s.wheel_measured_radps[i]);
      measured = wheels_to_twist(geom, m);
    } else {
      const Twist2 f = drive_feasible(geom, cmd);
      // 1 ms sub-steps: within the face width the pads stop at an 8 mm spring travel.
      for (int k = 0; k < 20; ++k) {
        const Pose2 next = exact_step(pose, static_cast<double>(f.vx_mps), static_cast<double>(f.vy_mps),
                                      static_cast<double>(f.wz_radps), 0.001);
        const PadState pn = pad_of(next, spec.backwards);
        if (pn.x < -0.008 && std::fabs(pn.y) <= kFaceHalf) break;
        pose = next;
      }
      const PadState pe = pad_of(pose, spec.backwards);
      ideal_contact = pe.x <= -0.003 && std::fabs(pe.y) <= 0.010 && std::fabs(pe.yaw_err) <= deg(2.0);
      odom = pose;
      measured = f;
    }
    t += kCtlDt;
  }
  const PadState pe = pad_of(pose, spec.backwards);
  res.lateral_m = pe.y;
  res.yaw_deg = pe.yaw_err * 180.0 / kPiD;
  if (!res.arrived && !res.failed) res.time_s = t;
  return res;
}

bool report_enabled() {
  const char* e = std::getenv("DOCKCORE_CTL_REPORT");
  return e != nullptr && e[0] == '1';
}

void report(const char* label, const DockingController& ctl, const Start& s, const RunResult& r) {
  if (!report_enabled()) return;
  std::printf(
      "%-8s %-8s d=%.1f b=%+4.0f h=%+4.0f  %-7s t=%6.2fs lat=%+7.2fmm yaw=%+6.2fdeg rev=%d inplace=%5.1fdeg phase=%s\n",
      label, ctl.name(), s.dist_m, s.bearing_deg, s.heading_deg,
      r.arrived ? "ARRIVED" : (r.failed ? "FAILED" : "TIMEOUT"), r.time_s, r.lateral_m * 1e3, r.yaw_deg, r.reversals,
      r.max_inplace_deg, ctl.phase_name(r.last_phase));
}

// Runs every start; returns the number of arrivals and the largest |lateral| among them.
struct Sweep {
  std::size_t arrived = 0;
  double max_lat_m = 0, max_yaw_deg = 0, max_time_s = 0;
  int reversals = 0;
  double max_inplace_deg = 0;
  bool zero_ok = true;
  bool arrived_at[kNumStarts] = {};
};

Sweep sweep(DockingController& ctl, const RunSpec& spec, const char* label) {
  Sweep sw;
  for (std::size_t i = 0; i < kNumStarts; ++i) {
    const RunResult r = run_docking(ctl, spec, kStarts[i]);
    report(label, ctl, kStarts[i], r);
    sw.zero_ok = sw.zero_ok && r.zero_after_arrival;
    if (r.reversals > sw.reversals) sw.reversals = r.reversals;
    if (r.max_inplace_deg > sw.max_inplace_deg) sw.max_inplace_deg = r.max_inplace_deg;
    if (!r.arrived) continue;
    sw.arrived_at[i] = true;
    ++sw.arrived;
    if (std::fabs(r.lateral_m) > sw.max_lat_m) sw.max_lat_m = std::fabs(r.lateral_m);
    if (std::fabs(r.yaw_deg) > sw.max_yaw_deg) sw.max_yaw_deg = std::fabs(r.yaw_deg);
    if (r.time_s > sw.max_time_s) sw.max_time_s = r.time_s;
  }
  return sw;
}

}  // namespace

TEST_GROUP(Controllers){};

TEST(Controllers, SmoothIdealPlantDiff) {
  SmoothController ctl;
  RunSpec spec;
  const Sweep sw = sweep(ctl, spec, "ideal");
  LONGS_EQUAL(kNumStarts, sw.arrived);
  CHECK(sw.max_lat_m <= 0.010);
  LONGS_EQUAL(0, sw.reversals);
  CHECK(sw.max_inplace_deg <= 45.0);
  CHECK(sw.zero_ok);
}

TEST(Controllers, SmoothChassisDiff) {
  SmoothController ctl;
  RunSpec spec;
  spec.plant = PlantKind::kChassis;
  const Sweep sw = sweep(ctl, spec, "chassis");
  LONGS_EQUAL(kNumStarts, sw.arrived);
  CHECK(sw.max_lat_m <= 0.010);
  LONGS_EQUAL(0, sw.reversals);
  CHECK(sw.max_inplace_deg <= 45.0);
  CHECK(sw.zero_ok);
}

TEST(Controllers, SmoothChassisMecanum) {
  SmoothController ctl;
  RunSpec spec;
  spec.plant = PlantKind::kChassis;
  spec.drive = DriveKind::kMecanum;
  const Sweep sw = sweep(ctl, spec, "mecanum");
  LONGS_EQUAL(kNumStarts, sw.arrived);
  CHECK(sw.max_lat_m <= 0.010);
  LONGS_EQUAL(0, sw.reversals);
  CHECK(sw.max_inplace_deg <= 45.0);
}

TEST(Controllers, SmoothChassisBackwards) {
  SmoothParams p;
  p.backwards = true;
  SmoothController ctl(p);
  RunSpec spec;
  spec.plant = PlantKind::kChassis;
  spec.backwards = true;
  const Sweep sw = sweep(ctl, spec, "backward");
  LONGS_EQUAL(kNumStarts, sw.arrived);
  CHECK(sw.max_lat_m <= 0.010);
  LONGS_EQUAL(0, sw.reversals);
}

TEST(Controllers, Seed004Chassis) {
  Seed004Controller ctl;
  RunSpec spec;
  spec.plant = PlantKind::kChassis;
  const Sweep sw = sweep(ctl, spec, "chassis");
  // Measured: 9/10 (the seed's 10 mm lateral tolerance equals the contacts' tolerance; one start ends 18 mm off).
  CHECK(sw.arrived >= 9);
  CHECK(sw.max_lat_m <= 0.010);
  CHECK(sw.zero_ok);
}

TEST(Controllers, Seed004Ideal) {
  Seed004Controller ctl;
  RunSpec spec;
  const Sweep sw = sweep(ctl, spec, "ideal");
  CHECK(sw.arrived >= 8);  // measured 8/10: two starts end 11–13 mm off after LATERAL's 10 mm tolerance
  CHECK(sw.max_lat_m <= 0.010);
}

TEST(Controllers, Seed000Chassis) {
  Seed000Controller ctl;
  RunSpec spec;
  spec.plant = PlantKind::kChassis;
  const Sweep sw = sweep(ctl, spec, "chassis");
  CHECK(sw.arrived_at[0]);  // head-on
  CHECK(sw.zero_ok);
}

TEST(Controllers, Seed000Ideal) {
  Seed000Controller ctl;
  RunSpec spec;
  const Sweep sw = sweep(ctl, spec, "ideal");
  CHECK(sw.arrived_at[0]);
}

TEST(Controllers, Seed003ChassisDiff) {
  Seed003Controller ctl;
  RunSpec spec;
  spec.plant = PlantKind::kChassis;
  spec.with_camera = true;
  const Sweep sw = sweep(ctl, spec, "chassis");
  CHECK(sw.arrived_at[0]);
  CHECK(sw.zero_ok);
}

TEST(Controllers, Seed003ChassisMecanum) {
  Seed003Params p;
  p.holonomic = true;
  Seed003Controller ctl(p);
  RunSpec spec;
  spec.plant = PlantKind::kChassis;
  spec.drive = DriveKind::kMecanum;
  spec.with_camera = true;
  const Sweep sw = sweep(ctl, spec, "mecanum");
  CHECK(sw.arrived_at[0]);
}

TEST(Controllers, Seed003Ideal) {
  Seed003Controller ctl;
  RunSpec spec;
  spec.with_camera = true;
  const Sweep sw = sweep(ctl, spec, "ideal");
  CHECK(sw.arrived_at[0]);
}

TEST(Controllers, DeterministicCommandSequence) {
  static Twist2 a[8000], b[8000];
  SmoothController s1, s2;
  Seed003Controller c1, c2;
  RunSpec spec;
  spec.plant = PlantKind::kChassis;
  spec.with_camera = true;
  const RunResult r1 = run_docking(s1, spec, kStarts[7], a, 8000);
  const RunResult r2 = run_docking(s2, spec, kStarts[7], b, 8000);
  LONGS_EQUAL(r1.ncmd, r2.ncmd);
  CHECK(r1.ncmd <= 8000);
  CHECK(std::memcmp(a, b, sizeof(Twist2) * r1.ncmd) == 0);
  const RunResult q1 = run_docking(c1, spec, kStarts[1], a, 8000);
  const RunResult q2 = run_docking(c1, spec, kStarts[1], b, 8000);  // same object after reset()
  LONGS_EQUAL(q1.ncmd, q2.ncmd);
  CHECK(std::memcmp(a, b, sizeof(Twist2) * (q1.ncmd < 8000 ? q1.ncmd : 8000)) == 0);
  (void)c2;
}
