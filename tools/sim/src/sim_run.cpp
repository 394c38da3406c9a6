#include "docksim/sim_run.hpp"
#include "docksim/angles.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <memory>

#include "dockcore/control/controllers.hpp"
#include "dockcore/control/kinematics.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/task/faults.hpp"
#include "docksim/camera_sim.hpp"
#include "docksim/chassis.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/rng.hpp"

namespace docksim {

using dockcore::Real;
using dockcore::Vec2;

namespace {

constexpr int kStepsPerTick = 4;  // 4 x 5 ms = 20 ms control period (50 Hz)
constexpr int kStartDraws = 40;   // draws of a start clear of the furniture before the last one is kept
constexpr double kStartClearanceM = 0.10;  // a start this close to furniture is drawn again

std::uint64_t mix64(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

Vec2 v2(double x, double y) {
  return Vec2(static_cast<Real>(x), static_cast<Real>(y));
}
double dd(Real r) {
  return static_cast<double>(r);
}

double wrapd(double a) {
  double r = std::remainder(a, 2.0 * kPiD);
  if (r <= -kPiD) r += 2.0 * kPiD;
  return r;
}

// --- clearance geometry (double precision) ---
struct P {
  double x, y;
};
P pd(const Vec2& v) {
  return P{dd(v.x()), dd(v.y())};
}
double cross(P a, P b, P c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}
double point_seg(P p, P a, P b) {
  const double vx = b.x - a.x, vy = b.y - a.y;
  const double l2 = vx * vx + vy * vy;
  double t = l2 > 0 ? ((p.x - a.x) * vx + (p.y - a.y) * vy) / l2 : 0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p.x - (a.x + t * vx), p.y - (a.y + t * vy));
}
bool segs_cross(P a, P b, P c, P d) {
  const double d1 = cross(c, d, a), d2 = cross(c, d, b), d3 = cross(a, b, c), d4 = cross(a, b, d);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0));
}
double seg_seg(P a, P b, P c, P d) {
  if (segs_cross(a, b, c, d)) return 0;
  return std::min({point_seg(a, c, d), point_seg(b, c, d), point_seg(c, a, b), point_seg(d, a, b)});
}
bool inside_poly(P p, const std::vector<P>& poly) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    if ((poly[i].y > p.y) != (poly[j].y > p.y) &&
        p.x < (poly[j].x - poly[i].x) * (p.y - poly[i].y) / (poly[j].y - poly[i].y) + poly[i].x) {
      in = !in;
    }
  }
  return in;
}

struct Obstacles {
  std::vector<std::pair<P, P>> segments;
  struct Disc {
    P c;
    double r;
  };
  std::vector<Disc> discs;
};

/// Clearance between the robot outline (polygon in world, or a disc) and the obstacles.
double clearance(const std::vector<P>& poly, bool is_disc, P disc_c, double disc_r, const Obstacles& obs) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& s : obs.segments) {
    double d;
    if (is_disc) {
      d = std::max(0.0, point_seg(disc_c, s.first, s.second) - disc_r);
    } else {
      d = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < poly.size(); ++i)
        d = std::min(d, seg_seg(poly[i], poly[(i + 1) % poly.size()], s.first, s.second));
      if (d > 0 && inside_poly(s.first, poly)) d = 0;
    }
    best = std::min(best, d);
  }
  for (const auto& c : obs.discs) {
    double d;
    if (is_disc) {
      d = std::hypot(disc_c.x - c.c.x, disc_c.y - c.c.y) - disc_r - c.r;
    } else if (inside_poly(c.c, poly)) {
      d = 0;
    } else {
      d = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < poly.size(); ++i)
        d = std::min(d, point_seg(c.c, poly[i], poly[(i + 1) % poly.size()]) - c.r);
    }
    best = std::min(best, std::max(0.0, d));
  }
  return best;
}

std::string fault_text(int code) {
  return "fault " + std::to_string(code) + " " + dockcore::to_string(static_cast<dockcore::FaultCode>(code));
}

}  // namespace

const char* to_string(TimelineKind k) {
  switch (k) {
    case TimelineKind::kState:
      return "state";
    case TimelineKind::kPhase:
      return "phase";
    case TimelineKind::kFault:
      return "fault";
    case TimelineKind::kEvent:
      return "event";
    case TimelineKind::kContact:
      return "contact";
    case TimelineKind::kHost:
      return "host";
  }
  return "?";
}

dockcore::DriveGeometry core_drive_geometry(const DriveGeometry& g) {
  dockcore::DriveGeometry c;
  c.kind = g.kind == DriveKind::kMecanum ? dockcore::DriveKind::kMecanum : dockcore::DriveKind::kDifferential;
  c.wheel_radius_m = static_cast<Real>(g.wheel_radius_m);
  c.wheel_base_m = static_cast<Real>(g.wheel_base_m);
  c.lx_m = static_cast<Real>(g.lx_m);
  c.ly_m = static_cast<Real>(g.ly_m);
  return c;
}

namespace {

/// The geometry the robot believes it has: the chassis's odometry radius and base errors applied.
DriveGeometry believed_geometry(const ChassisParams& c) {
  DriveGeometry g = c.geometry;
  g.wheel_radius_m *= 1.0 + c.noise.odom_radius_error;
  g.wheel_base_m *= 1.0 + c.noise.odom_base_error;
  g.lx_m *= 1.0 + c.noise.odom_base_error;
  g.ly_m *= 1.0 + c.noise.odom_base_error;
  return g;
}

}  // namespace

dockcore::DockcoreConfig core_config(const Scenario& sc) {
  dockcore::DockcoreConfig cfg;
  cfg.estimator = sc.estimator;
  cfg.task = sc.task;
  cfg.footprint = sc.safety;
  cfg.lidar_mount = sc.lidar_mount;
  cfg.drive = core_drive_geometry(sc.odometry_source == OdometrySource::kWheels ? believed_geometry(sc.chassis)
                                                                                : sc.chassis.geometry);
  cfg.limits = sc.limits;
  cfg.control_period_s = static_cast<Real>(sc.chassis.dt_s * kStepsPerTick);
  cfg.watchdog = sc.watchdog;
  cfg.deadband = sc.deadband;
  cfg.intensity = sc.intensity;
  cfg.detector = sc.detector;
  return cfg;
}

void feed_chassis(dockcore::DockcoreBase& core, const Scenario& sc, const ChassisState& reported,
                  std::uint64_t now_us) {
  if (sc.odometry_source == OdometrySource::kChassis) {
    core.on_odometry(reported.odom_pose, measured_twist(core.config().drive, reported), now_us);
    return;
  }
  const NoiseParams& n = sc.chassis.noise;
  dockcore::WheelSpeeds w;
  w.count = reported.wheel_count;
  for (std::size_t i = 0; i < w.count; ++i) {
    const double side = is_left_wheel(sc.chassis.geometry.kind, i) ? 0.5 : -0.5;
    const double scale = (1.0 + n.odom_radius_error + side * n.odom_radius_diff) / (1.0 + n.odom_radius_error);
    w.radps[i] = static_cast<Real>(reported.wheel_measured_radps[i] * scale);
  }
  core.on_wheels(w, now_us);
}

dockcore::Twist2 measured_twist(const dockcore::DriveGeometry& g, const ChassisState& reported) {
  dockcore::WheelSpeeds m;
  m.count = reported.wheel_count;
  for (std::size_t i = 0; i < m.count; ++i) m.radps[i] = static_cast<Real>(reported.wheel_measured_radps[i]);
  return dockcore::wheels_to_twist(g, m);
}

dockcore::TagFusionParams tag_fusion_params(const Scenario& sc) {
  dockcore::TagFusionParams p = sc.tag_fusion;
  const dockcore::CameraModel& m = sc.camera.model;
  p.mount = dockcore::CameraMount3{m.mount.x_m, m.mount.y_m, static_cast<Real>(sc.camera.z_m), m.mount.yaw_rad, 0, 0};
  p.fx_px = m.fx_px;
  p.tag_size_m = static_cast<Real>(sc.dock_tag.size_m);
  p.dock_tag.id = sc.dock_tag.id;
  p.dock_tag.x_m = sc.camera.target_in_dock.x();
  p.dock_tag.y_m = sc.camera.target_in_dock.y();
  p.dock_tag.z_m = static_cast<Real>(std::isnan(sc.dock_tag.z_m) ? sc.camera.z_m : sc.dock_tag.z_m);
  return p;
}

CameraSimParams camera_sim_params(const Scenario& sc) {
  CameraSimParams camp;
  camp.model = sc.camera.model;
  camp.rate_hz = sc.camera.rate_hz;
  camp.latency_s = sc.camera.latency_s;
  camp.sigma_px = sc.camera.sigma_px;
  camp.dropout_prob = sc.camera.dropout_prob;
  camp.min_depth_m = sc.camera.min_depth_m;
  camp.max_depth_m = sc.camera.max_depth_m;
  camp.v_px = sc.camera.v_px;
  return camp;
}

std::uint64_t seed_stream(std::uint64_t seed, std::uint64_t salt) {
  return mix64(seed ^ salt);
}

std::uint64_t trial_seed(std::uint64_t base, std::uint64_t index) {
  return mix64(mix64(base) ^ (index * 0xD1B54A32D192ED03ull));
}

StartPose start_from(const Scenario& sc, double distance_m, double bearing_rad, double heading_rad) {
  StartPose s;
  s.distance_m = distance_m;
  s.bearing_rad = bearing_rad;
  s.heading_rad = heading_rad;
  const double x = distance_m * std::cos(bearing_rad), y = distance_m * std::sin(bearing_rad);
  const bool rear = sc.chassis.footprint.pad_side == PadSide::kRear;
  const double yaw = wrapd(std::atan2(-y, -x) + heading_rad + (rear ? kPiD : 0.0));
  s.robot_in_dock = Pose2{static_cast<Real>(x), static_cast<Real>(y), static_cast<Real>(yaw)};
  s.robot_world = sc.dock_pose.compose(s.robot_in_dock);
  return s;
}

std::unique_ptr<dockcore::BreakpointDetector> attach_detector(const Scenario& sc, dockcore::DockcoreBase& core) {
  if (sc.detector != dockcore::DockDetector::kBreakpoint) return nullptr;
  auto breakpoint = std::make_unique<dockcore::BreakpointDetector>();
  core.attach_breakpoint(breakpoint.get());
  return breakpoint;
}

DockPlacement dock_placement(const Scenario& sc) {
  DockPlacement dp;
  dp.pose_world = sc.dock_pose;
  dp.face_half_width_m = sc.dock_face_half_width_m;
  dp.dead = sc.dock_dead;
  dp.stop_short_m = sc.dock_stop_short_m;
  return dp;
}

std::vector<Vec2> footprint_outline(const ChassisParams& c) {
  const FootprintParams& f = c.footprint;
  std::vector<Vec2> pts;
  if (f.shape == FootprintShape::kCircle) {
    for (int i = 0; i < 24; ++i) {
      const double a = 2 * kPiD * i / 24;
      pts.push_back(v2(f.centre_x_m + f.radius_m * std::cos(a), f.radius_m * std::sin(a)));
    }
  } else {
    const double hx = f.length_m / 2, hy = f.width_m / 2, cx = f.centre_x_m;
    pts = {v2(cx + hx, hy), v2(cx - hx, hy), v2(cx - hx, -hy), v2(cx + hx, -hy)};
  }
  return pts;
}

/// The obstacles the robot must keep clear of: [world] objects, furniture and other docks (not the dock or its
/// wall). `occluders`, when given, receives the same objects as lidar geometry (what may hide the dock's tag).
Obstacles static_obstacles(const Scenario& sc, World* occluders) {
  World o;
  for (const auto& pl : sc.polylines) o.add_polyline(pl.points, pl.closed);
  for (const auto& b : sc.boxes) o.add_box(b.centre, b.size_x_m, b.size_y_m, b.yaw_rad);
  for (const auto& d : sc.other_docks) o.add_dock(d.profile, d.pose);
  Obstacles obs;
  for (const auto& seg : o.segments) obs.segments.push_back({pd(seg.a), pd(seg.b)});
  for (const auto& c : sc.circles) obs.discs.push_back({pd(c.centre), c.r_m});
  for (const auto& c : sc.circles) o.add_circle(c.centre, c.r_m);
  if (occluders != nullptr) *occluders = std::move(o);
  return obs;
}

/// Clearance between the robot's outline (`outline`, robot frame) at `pose` (world) and `obs`, m. O(obstacles).
double robot_clearance(const Scenario& sc, const std::vector<Vec2>& outline, const Pose2& pose, const Obstacles& obs) {
  std::vector<P> poly;
  for (const auto& q : outline) poly.push_back(pd(pose.transform(q)));
  const P centre = pd(pose.transform(v2(sc.chassis.footprint.centre_x_m, 0)));
  return clearance(poly, sc.chassis.footprint.shape == FootprintShape::kCircle, centre, sc.chassis.footprint.radius_m,
                   obs);
}

Vec2 obstacle_entry(const Scenario& sc, const ScenarioEvent& ev, const Pose2& robot_pose, double clearance_m) {
  const std::vector<Vec2> outline = footprint_outline(sc.chassis);
  const bool walks = ev.vx_mps != 0 || ev.vy_mps != 0;
  Vec2 at = v2(ev.x_m, ev.y_m);
  // A passer-by comes from further back on its way; someone standing stands further from the robot's centre.
  const Vec2 away = walks ? v2(-ev.vx_mps, -ev.vy_mps) : at - Vec2(robot_pose.x_m, robot_pose.y_m);
  const double step_m = walks ? 0.05 : 0.01;
  const Vec2 step = (away.norm() > 0 ? Vec2(away.normalized()) : v2(1, 0)) * static_cast<Real>(step_m);
  for (int i = 0; i < static_cast<int>(std::lround(5.0 / step_m)); ++i) {
    Obstacles one;
    one.discs.push_back({pd(at), ev.r_m});
    const double c = robot_clearance(sc, outline, robot_pose, one);  // 0 when touching or overlapping
    if (c >= clearance_m && c > 0) break;
    at = at + step;
  }
  return at;
}

StartPose draw_start(const Scenario& sc, std::uint64_t seed) {
  Rng rng(mix64(seed ^ 0x5354415254ull));
  const StartEnvelope& e = sc.start;
  // A start that overlaps furniture (or comes within kStartClearanceM of it) is drawn again: a robot is sent to dock
  // from where it can stand. Worlds without obstacles keep their first draw.
  const Obstacles obs = static_obstacles(sc, nullptr);
  const std::vector<Vec2> outline = footprint_outline(sc.chassis);
  StartPose s;
  for (int i = 0; i < kStartDraws; ++i) {
    const double d = rng.uniform(e.distance_min_m, e.distance_max_m);
    const double b = rng.uniform(e.bearing_min_rad, e.bearing_max_rad);
    const double h = rng.uniform(e.heading_min_rad, e.heading_max_rad);
    s = start_from(sc, d, b, h);
    if (obs.segments.empty() && obs.discs.empty()) break;
    // The outlines' distance misses a robot wholly inside a box or a disc: its centre is tested too.
    const Vec2 c = s.robot_world.transform(v2(sc.chassis.footprint.centre_x_m, 0));
    bool inside = false;
    for (const auto& box : sc.boxes) {
      const Vec2 q = Pose2{box.centre.x(), box.centre.y(), static_cast<Real>(box.yaw_rad)}.inverse_transform(c);
      inside = inside || (std::abs(dd(q.x())) <= box.size_x_m / 2 && std::abs(dd(q.y())) <= box.size_y_m / 2);
    }
    for (const auto& disc : sc.circles) inside = inside || dd((c - disc.centre).norm()) <= disc.r_m;
    if (!inside && robot_clearance(sc, outline, s.robot_world, obs) >= kStartClearanceM) break;
  }
  return s;
}

bool dock_wall(const Scenario& sc, Vec2* a, Vec2* b) {
  if (!sc.wall) return false;
  double min_x = 0;
  for (std::size_t i = 0; i < sc.profile.vertex_count; ++i) min_x = std::min(min_x, dd(sc.profile.vertices_m[i].x()));
  const double x = min_x - sc.wall_gap_m;
  *a = sc.dock_pose.transform(v2(x, -sc.wall_half_length_m));
  *b = sc.dock_pose.transform(v2(x, sc.wall_half_length_m));
  return true;
}

World scenario_world(const Scenario& sc, bool with_dock) {
  World w;
  if (with_dock) w.add_dock(sc.profile, sc.dock_pose);
  for (const auto& d : sc.other_docks) w.add_dock(d.profile, d.pose);
  Vec2 wall_a, wall_b;
  // Glass stands there but the lidar sees through it: it is not part of the lidar's world.
  if (dock_wall(sc, &wall_a, &wall_b) && !sc.wall_glass) w.add_polyline({wall_a, wall_b}, false, 0.5);
  for (const auto& pl : sc.polylines) w.add_polyline(pl.points, pl.closed);
  for (const auto& b : sc.boxes) w.add_box(b.centre, b.size_x_m, b.size_y_m, b.yaw_rad);
  for (const auto& c : sc.circles) w.add_circle(c.centre, c.r_m);
  return w;
}

SimRun run_docking(const Scenario& sc, const std::string& controller, std::uint64_t seed, const SimOptions& opt) {
  SimRun run;
  run.controller = controller;
  run.seed = seed;
  run.start = opt.start != nullptr ? *opt.start : draw_start(sc, seed);
  SimOutcome& out = run.outcome;

  auto ctrls = std::make_unique<dockcore::ControllerSet>(sc.seed000, sc.seed004, sc.seed003, sc.smooth);
  dockcore::DockingController* ctl = ctrls->by_name(controller.c_str());
  if (ctl == nullptr) throw ScenarioError("unknown controller '" + controller + "'");

  // Dockcore is large (estimator buffers, a scan copy): heap, not stack.
  auto core = std::make_unique<dockcore::Dockcore>(*ctl);
  dockcore::DockcoreConfig cfg = core_config(sc);
  // A rendered camera: images of the dock's tag through the detector; its tag poses fused with the lidar.
  std::unique_ptr<FrameCamera> frame_camera;
  const bool rendered = sc.camera.enabled && sc.camera.render;
  if (rendered) {
    if (!opt.make_frame_camera) {
      throw ScenarioError("robot.camera.render needs a tag detector: this dock-sim was built without libapriltag");
    }
    frame_camera = opt.make_frame_camera(sc);
    if (sc.camera.fuse_tags) cfg.tag = tag_fusion_params(sc);
  }
  const std::unique_ptr<dockcore::BreakpointDetector> breakpoint = attach_detector(sc, *core);
  if (!core->configure(sc.profile, cfg)) {
    throw ScenarioError(std::string("dock: ") + dockcore::to_string(core->configure_status()));
  }

  Chassis chassis(sc.chassis, mix64(seed ^ 0x43484153ull));
  chassis.set_dock(dock_placement(sc));
  chassis.set_true_pose(run.start.robot_world);
  chassis.reset_odometry(Pose2{});
  Rng lidar_rng(mix64(seed ^ 0x4C494441ull));

  CameraSim camera(camera_sim_params(sc), mix64(seed ^ 0x43414dull), frame_camera.get());
  const Vec2 target_world = sc.dock_pose.transform(sc.camera.target_in_dock);

  const double dt = sc.chassis.dt_s;

  // World state driven by events.
  const World world_with_dock = scenario_world(sc, true);
  const World world_no_dock = scenario_world(sc, false);
  World occluders;  // what may hide the dock's tag from the camera: everything but the dock and its wall
  const Obstacles static_obs = static_obstacles(sc, &occluders);
  struct ActiveObstacle {
    Vec2 c;
    double r;
    double until_s;
    Vec2 v{};                // walking velocity, world m/s
    double walk_left_s = 0;  // a walking obstacle leaves once it has walked this long
  };
  std::vector<ActiveObstacle> active_obs;
  double occluded_until = -1, dropout_until = -1, silent_until = -1, host_stalled_until = -1;
  bool silent = false, host_stalled = false;
  std::size_t next_event = 0;
  std::vector<bool> state_event_fired(sc.events.size(), false);
  double state_entered_s[static_cast<std::size_t>(dockcore::TaskState::kTestMode) + 1];
  std::fill(std::begin(state_entered_s), std::end(state_entered_s), -1.0);

  // Lidar pipeline.
  const double scan_period = 1.0 / sc.lidar.rate_hz;
  double next_scan_t = 0;
  struct PendingScan {
    dockcore::LaserScan scan;
    std::uint64_t stamp_us;
    Pose2 lidar_world;
  };
  std::vector<std::unique_ptr<PendingScan>> pending;
  std::unique_ptr<PendingScan> last_scan;

  // Footprint for clearance.
  const std::vector<Vec2> outline = footprint_outline(sc.chassis);

  // Host state.
  dockcore::TaskState prev_state = dockcore::TaskState::kNotTasking;
  std::uint8_t prev_phase = 255;
  dockcore::FaultCode prev_fault = dockcore::FaultCode::kNone;
  bool prev_contact = false, prev_charging = false, prev_blocked = false, prev_lost = false;
  int redocks_left = sc.host.redock_after_fault;
  double fault_since = -1;
  bool send_dock = false;
  bool first_dock_sent = false;
  double dock_cmd_t = 0;
  double end_at = -1;
  ChassisState reported = chassis.state();  // what the host last heard from the chassis
  int last_vx_sign = 0;
  double inplace_acc = 0;
  double next_traj_t = 0;

  auto add = [&](double t, TimelineKind k, int code, const std::string& text) {
    run.timeline.push_back(TimelineEntry{t, k, code, text});
  };
  auto close_inplace = [&]() {
    if (inplace_acc > kPiD / 4) ++out.inplace_turns_45;
    out.max_inplace_turn_rad = std::max(out.max_inplace_turn_rad, inplace_acc);
    inplace_acc = 0;
  };

  const std::uint64_t max_steps = static_cast<std::uint64_t>(std::ceil(sc.max_time_s / dt));
  std::uint64_t k = 0;
  for (; k <= max_steps; ++k) {
    const double t = static_cast<double>(k) * dt;
    const std::uint64_t now_us = static_cast<std::uint64_t>(std::llround(t * 1e6));
    if (end_at >= 0 && t >= end_at) break;

    // 1. Events: on the run's clock, or (in_state) on the clock of the first tick in their state.
    auto fire = [&](const ScenarioEvent& ev) {
      char buf[160];
      switch (ev.kind) {
        case EventKind::kPush:
          chassis.apply_pose_jump(ev.dx_m, ev.dy_m, ev.dyaw_rad);
          std::snprintf(buf, sizeof buf, "push dx %.3f m dy %.3f m dyaw %.1f deg", ev.dx_m, ev.dy_m,
                        ev.dyaw_rad * 180 / kPiD);
          break;
        case EventKind::kOccludeDock:
          occluded_until = std::max(occluded_until, t + ev.duration_s);
          std::snprintf(buf, sizeof buf, "dock occluded for %.2f s", ev.duration_s);
          break;
        case EventKind::kObstacle:
          if (ev.vx_mps != 0 || ev.vy_mps != 0) {
            const Vec2 from = obstacle_entry(sc, ev, chassis.state().true_pose, kPasserGiveWayM);
            active_obs.push_back(
                {from, ev.r_m, 1e300, v2(ev.vx_mps, ev.vy_mps), ev.duration_s > 0 ? ev.duration_s : 1e300});
            std::snprintf(buf, sizeof buf, "passer-by r %.2f m from (%.2f, %.2f) at (%.2f, %.2f) m/s for %.2f s",
                          ev.r_m, ev.x_m, ev.y_m, ev.vx_mps, ev.vy_mps, ev.duration_s);
          } else {
            const Vec2 at = obstacle_entry(sc, ev, chassis.state().true_pose, 0);
            active_obs.push_back({at, ev.r_m, ev.duration_s > 0 ? t + ev.duration_s : 1e300});
            std::snprintf(buf, sizeof buf, "obstacle r %.2f m at (%.2f, %.2f) for %.2f s", ev.r_m,
                          static_cast<double>(at.x()), static_cast<double>(at.y()), ev.duration_s);
          }
          break;
        case EventKind::kLidarDropout:
          dropout_until = std::max(dropout_until, t + ev.duration_s);
          std::snprintf(buf, sizeof buf, "lidar dropout for %.2f s", ev.duration_s);
          break;
        case EventKind::kChargingNeverStarts:
          chassis.set_charging_inhibited(true);
          std::snprintf(buf, sizeof buf, "charger will never deliver current");
          break;
        case EventKind::kChassisSilent:
          silent_until = std::max(silent_until, t + ev.duration_s);
          chassis.set_frozen(true, ev.hold_last_command ? FreezeMotion::kHoldLastCommand : FreezeMotion::kStop);
          silent = true;
          std::snprintf(buf, sizeof buf, "chassis silent for %.2f s (%s)", ev.duration_s,
                        ev.hold_last_command ? "motors hold the last command" : "motors stop");
          break;
        case EventKind::kHostStall:
          host_stalled_until = std::max(host_stalled_until, t + ev.duration_s);
          host_stalled = true;
          std::snprintf(buf, sizeof buf, "host stalled for %.2f s (motors keep the last command)", ev.duration_s);
          break;
      }
      add(t, TimelineKind::kEvent, static_cast<int>(ev.kind), buf);
    };
    while (next_event < sc.events.size() && sc.events[next_event].t_s <= t + 1e-9) {
      const ScenarioEvent& ev = sc.events[next_event++];
      if (!ev.after_state) fire(ev);
    }
    for (std::size_t i = 0; i < sc.events.size(); ++i) {
      const ScenarioEvent& ev = sc.events[i];
      const double entered = state_entered_s[static_cast<std::size_t>(ev.state)];
      if (ev.after_state && !state_event_fired[i] && entered >= 0 && entered + ev.t_s <= t + 1e-9) {
        state_event_fired[i] = true;
        fire(ev);
      }
    }
    if (silent && t >= silent_until) {
      chassis.set_frozen(false);
      silent = false;
      add(t, TimelineKind::kEvent, static_cast<int>(EventKind::kChassisSilent), "chassis answers again");
    }
    if (host_stalled && t >= host_stalled_until) {
      host_stalled = false;
      add(t, TimelineKind::kEvent, static_cast<int>(EventKind::kHostStall), "host runs again");
    }
    // Passers-by walk on; one whose step would bring it near the robot steps around it (turning from its way to the
    // side away from the robot, back if need be: a step is taken when it keeps the give-way distance or widens the
    // gap), so that neither waits for the other.
    for (auto& o : active_obs) {
      if (o.v.x() == 0 && o.v.y() == 0) continue;
      const Vec2 robot = chassis.state().true_pose.transform(v2(sc.chassis.footprint.centre_x_m, 0));
      const Vec2 to_robot = robot - o.c;
      const double away = dd(o.v.x() * to_robot.y() - o.v.y() * to_robot.x()) > 0 ? -1.0 : 1.0;
      Obstacles here;
      here.discs.push_back({pd(o.c), o.r});
      const double gap_m = robot_clearance(sc, outline, chassis.state().true_pose, here);
      for (const double turn_deg : {0.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0}) {
        const double a = away * turn_deg * kPiD / 180;
        const Vec2 step = Vec2(static_cast<Real>(std::cos(a) * dd(o.v.x()) - std::sin(a) * dd(o.v.y())),
                               static_cast<Real>(std::sin(a) * dd(o.v.x()) + std::cos(a) * dd(o.v.y()))) *
                          static_cast<Real>(dt);
        Obstacles one;
        one.discs.push_back({pd(o.c + step), o.r});
        const double next_gap_m = robot_clearance(sc, outline, chassis.state().true_pose, one);
        if (next_gap_m >= kPasserGiveWayM || next_gap_m > gap_m) {
          o.c = o.c + step;
          o.walk_left_s -= dt;
          if (o.walk_left_s <= 0) o.until_s = t;
          break;
        }
      }
    }
    active_obs.erase(
        std::remove_if(active_obs.begin(), active_obs.end(), [&](const ActiveObstacle& o) { return t >= o.until_s; }),
        active_obs.end());
    const bool occluded = t < occluded_until;

    const ChassisState& cs = chassis.state();
    if (cs.responding) {
      reported = cs;
      // The chassis firmware's odometry, as its feedback reaches the host (a stalled host reads none): the core
      // places each scan and tag frame by it, as in dockd.
      if (!host_stalled) feed_chassis(*core, sc, reported, now_us);
    }

    // 2. Lidar: capture at the model's rate from the true lidar pose, deliver after the scan latency.
    if (t + 1e-9 >= next_scan_t) {
      next_scan_t += scan_period;
      if (t >= dropout_until) {
        auto ps = std::make_unique<PendingScan>();
        ps->lidar_world = cs.true_pose.compose(sc.true_lidar_mount());
        World w = occluded ? world_no_dock : world_with_dock;
        for (const auto& o : active_obs) w.add_circle(o.c, o.r);
        simulate_scan(w, ps->lidar_world, sc.lidar, lidar_rng, &ps->scan, now_us);
        ps->stamp_us = now_us;
        pending.push_back(std::move(ps));
      }
    }
    // A stalled host reads nothing: the scans wait in its input (dockd's serial or socket buffer) and are read, in
    // order, when it runs again.
    while (!host_stalled && !pending.empty() &&
           static_cast<double>(now_us - pending.front()->stamp_us) * 1e-6 + 1e-9 >= sc.scan_latency_s) {
      core->on_scan(pending.front()->scan.view(), pending.front()->stamp_us, now_us);
      last_scan = std::move(pending.front());
      pending.erase(pending.begin());
    }

    // 3. Camera.
    if (sc.camera.enabled) {
      // Obstacle events join the occluders only for a frame that is taken (20 Hz, not every 5 ms step).
      if (rendered && !active_obs.empty() && camera.frame_due(now_us)) {
        World frame_occluders = occluders;
        for (const auto& o : active_obs) frame_occluders.add_circle(o.c, o.r);
        camera.update(now_us, cs.true_pose, target_world, !occluded, &frame_occluders);
      } else {
        camera.update(now_us, cs.true_pose, target_world, !occluded, &occluders);
      }
    }
    // The tag poses delivered, in frame order; the core places each at the odometry pose of its frame's capture.
    dockcore::TagObservation tag_obs;
    while (!host_stalled && camera.pop_tag(tag_obs)) {
      if (!rendered || !sc.camera.fuse_tags) continue;
      if (core->on_tag(tag_obs) == dockcore::TagStatus::kFused) {
        ++out.tags_fused;
      } else {
        ++out.tags_refused;
      }
    }

    // 4. Control tick.
    if (k % kStepsPerTick == 0 && !host_stalled) {
      dockcore::TickInput in;
      in.now_us = now_us;
      // The host sends the first dock command once the lidar has delivered a scan (dockd would not start blind).
      if (!first_dock_sent && last_scan) {
        send_dock = true;
        first_dock_sent = true;
        dock_cmd_t = t;
      }
      if (send_dock) {
        dockcore::QueuedCommand q;
        q.command = dockcore::HostCommand{dockcore::HostCommandType::kDock, 0};
        core->submit(q);
        send_dock = false;
        add(t, TimelineKind::kHost, 1, "host: dock");
      }
      if (sc.camera.enabled) in.camera = camera.latest();
      in.contact = reported.contact;
      in.charge_current_a = static_cast<Real>(reported.charge_current_a);
      const dockcore::TickOutput o = core->tick(in);

      const dockcore::WheelSpeeds& w = o.wheels;
      WheelRadps wr{};
      for (std::size_t i = 0; i < w.count && i < kMaxWheels; ++i) wr[i] = dd(w.radps[i]);
      chassis.command_wheels(wr);

      // Timeline.
      const dockcore::TaskStatus& s = o.status;
      if (s.state != prev_state) {
        add(t, TimelineKind::kState, static_cast<int>(s.state), dockcore::to_string(s.state));
        double& entered = state_entered_s[static_cast<std::size_t>(s.state)];
        if (entered < 0) entered = t;
        if (s.state == dockcore::TaskState::kFinishTasking && !out.charging_confirmed) {
          out.charging_confirmed = true;
          out.time_to_charging_s = t - dock_cmd_t;
          out.lateral_m = cs.pad_lateral_m;
          out.longitudinal_m = -cs.press_m;
          out.yaw_rad = cs.pad_yaw_error_rad;
          end_at = t + sc.settle_after_end_s;
        }
        prev_phase = 255;
      }
      if (s.state == dockcore::TaskState::kAlign && s.phase != prev_phase) {
        add(t, TimelineKind::kPhase, s.phase, std::string(ctl->name()) + " " + ctl->phase_name(s.phase));
        if (controller == "seed003" && s.phase == static_cast<std::uint8_t>(dockcore::Seed003Phase::kSeedSuccess) &&
            std::isnan(out.seed_success_t_s)) {
          const Pose2 cam = cs.true_pose.compose(sc.camera.model.mount);
          const Vec2 q = cam.inverse_transform(target_world);
          out.seed_success_t_s = t - dock_cmd_t;
          out.seed_success_z_err_m = dd(q.x()) - dd(sc.seed003.goal_z_m);
          out.seed_success_x_m = -dd(q.y());
        }
        prev_phase = s.phase;
      }
      if (s.fault != prev_fault && s.fault != dockcore::FaultCode::kNone) {
        add(t, TimelineKind::kFault, static_cast<int>(s.fault), fault_text(static_cast<int>(s.fault)));
        ++out.faults[static_cast<int>(s.fault)];
      }
      prev_fault = s.fault;
      if (o.blocked != prev_blocked) {
        add(t, TimelineKind::kHost, o.blocked ? 1 : 0,
            o.blocked ? "motion blocked by an obstacle" : "motion free again");
        prev_blocked = o.blocked;
      }
      if (o.target_lost != prev_lost) {
        add(t, TimelineKind::kHost, o.target_lost ? 1 : 0,
            o.target_lost ? "target lost: holding" : "target reacquired");
        prev_lost = o.target_lost;
      }
      if (o.resume == dockcore::ResumeEvent::kResumed)
        add(t, TimelineKind::kHost, 1, "resume: the interrupted command again");
      if (o.resume == dockcore::ResumeEvent::kGivenUp) add(t, TimelineKind::kHost, 0, "resume given up (max_resumes)");
      if (s.state == dockcore::TaskState::kFault) {
        if (prev_state != dockcore::TaskState::kFault) fault_since = t;
        if (redocks_left > 0 && t - fault_since >= sc.host.redock_delay_s) {
          --redocks_left;
          send_dock = true;
        } else if (redocks_left == 0 && end_at < 0 && !core->resume_pending()) {
          end_at = t + sc.settle_after_end_s;
        }
      }
      prev_state = s.state;
      out.retries = s.retries;

      // Metrics on the command actually sent.
      const double vx = dd(o.drive_cmd.vx_mps);
      const int sgn = vx > 1e-3 ? 1 : (vx < -1e-3 ? -1 : 0);
      if (sgn != 0) {
        if (last_vx_sign != 0 && sgn != last_vx_sign) ++out.reversals;
        last_vx_sign = sgn;
      }
    }
    // Measured on the tick clock whether or not the host ran: a stalled host's robot still moves.
    if (k % kStepsPerTick == 0) {
      if (!static_obs.segments.empty() || !static_obs.discs.empty() || !active_obs.empty()) {
        Obstacles obs = static_obs;
        for (const auto& a : active_obs) obs.discs.push_back({pd(a.c), a.r});
        out.min_clearance_m = std::min(out.min_clearance_m, robot_clearance(sc, outline, cs.true_pose, obs));
      }
      if (opt.record_trajectory && t + 1e-9 >= next_traj_t) {
        run.trajectory.push_back(
            TrajectorySample{t, cs.true_pose, dd(core->drive_cmd().vx_mps), static_cast<std::uint8_t>(prev_state)});
        next_traj_t += opt.trajectory_period_s;
      }
    }

    // 5. Physics.
    const Pose2 before = chassis.state().true_pose;
    chassis.step();
    const ChassisState& after = chassis.state();
    out.path_length_m += std::hypot(dd(after.true_pose.x_m - before.x_m), dd(after.true_pose.y_m - before.y_m));
    const double speed = std::hypot(after.true_twist.vx_mps, after.true_twist.vy_mps);
    if (speed < 0.01) {
      inplace_acc += std::fabs(after.true_twist.wz_radps) * dt;
    } else {
      close_inplace();
    }
    if (after.contact != prev_contact) {
      add(t + dt, TimelineKind::kContact, after.contact ? 1 : 0, after.contact ? "contacts closed" : "contacts open");
      prev_contact = after.contact;
    }
    if (after.charging != prev_charging) {
      add(t + dt, TimelineKind::kContact, after.charging ? 3 : 2,
          after.charging ? "charging current on" : "charging current off");
      prev_charging = after.charging;
    }
  }
  close_inplace();
  out.camera_rendered = rendered;
  out.camera_frames = camera.frames_delivered();
  out.camera_detections = camera.frames_with_target();
  out.intensity = core->intensity().verdict();
  out.intensity_scans_judged = core->intensity().scans_judged();
  out.intensity_scans_flat = core->intensity().scans_flat();
  out.detector = core->estimator().counters();
  out.calibrations = core->task_manager().calibrations();
  out.last_calibration = core->task_manager().last_calibration();
  out.lidar_mount_in_use = core->lidar_mount();
  const ChassisState& fs = chassis.state();
  out.end_time_s = static_cast<double>(k) * dt;
  out.final_state = prev_state;
  out.timed_out = !out.charging_confirmed && prev_state != dockcore::TaskState::kFault;
  if (!out.charging_confirmed) {
    out.lateral_m = fs.pad_lateral_m;
    out.longitudinal_m = -fs.press_m;
    out.yaw_rad = fs.pad_yaw_error_rad;
  }
  if (out.timed_out) add(out.end_time_s, TimelineKind::kHost, 0, "timeout: max_time_s reached");
  run.final_pose = fs.true_pose;
  if (opt.keep_last_scan && last_scan) {
    const dockcore::LaserScan& s = last_scan->scan;
    for (std::size_t i = 0; i < s.count; ++i) {
      const double r = dd(s.ranges_m[i]);
      if (!(r > 0)) continue;
      const double a = dd(s.angle_min_rad) + static_cast<double>(i) * dd(s.angle_increment_rad);
      run.last_scan_world.push_back(last_scan->lidar_world.transform(v2(r * std::cos(a), r * std::sin(a))));
    }
  }
  return run;
}

}  // namespace docksim
