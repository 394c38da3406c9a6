#include "docksim/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>
#include <string_view>
#include <utility>

#include <toml++/toml.h>

#include "dockcore/params/param_toml.hpp"
#include "dockcore/params/profile_toml.hpp"
#include "dockcore/params/toml_reader.hpp"

#include "docksim/profile_file.hpp"

namespace docksim {

const char* to_string(EventKind k) {
  switch (k) {
    case EventKind::kPush:
      return "push";
    case EventKind::kOccludeDock:
      return "occlude_dock";
    case EventKind::kObstacle:
      return "obstacle";
    case EventKind::kLidarDropout:
      return "lidar_dropout";
    case EventKind::kChargingNeverStarts:
      return "charging_never_starts";
    case EventKind::kChassisSilent:
      return "chassis_silent";
    case EventKind::kHostStall:
      return "host_stall";
  }
  return "?";
}

const char* to_string(FurnitureKind k) {
  switch (k) {
    case FurnitureKind::kBox:
      return "box";
    case FurnitureKind::kBin:
      return "bin";
    case FurnitureKind::kChair:
      return "chair";
    case FurnitureKind::kDock:
      return "dock";
  }
  return "?";
}

const std::vector<std::string>& controller_names() {
  static const std::vector<std::string> names = {"seed000", "seed004", "seed003", "smooth"};
  return names;
}

bool is_controller_name(const std::string& name) {
  const auto& n = controller_names();
  return std::find(n.begin(), n.end(), name) != n.end();
}

double pad_reach_of(const ChassisParams& c) {
  const double sgn = c.footprint.pad_side == PadSide::kRear ? -1.0 : 1.0;
  return sgn * static_cast<double>(pad_point_body(c.footprint).x());
}

namespace {

using dockcore::Real;
using dockcore::Vec2;
using dockcore::params::toml_reader::dir_of;
using dockcore::params::toml_reader::Handler;
using dockcore::params::toml_reader::Handlers;
using dockcore::params::toml_reader::kDeg;
using dockcore::params::toml_reader::type_name;

std::string stem_of(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
  if (base.size() > 5 && base.compare(base.size() - 5, 5, ".toml") == 0) base.resize(base.size() - 5);
  return base;
}

/// The strict key reader (shared with dockd's config) plus the scenario's array forms.
class Parser : public dockcore::params::toml_reader::Reader<ScenarioError> {
 public:
  using Reader::Reader;

  /// [lo, hi] pair of numbers with lo <= hi.
  std::pair<double, double> range(const toml::node& n, double lo, double hi) const {
    const toml::array* a = n.as_array();
    if (a == nullptr || a->size() != 2) fail(n.source(), key() + " must be [min, max]");
    const double x = number((*a)[0], lo, hi), y = number((*a)[1], lo, hi);
    if (x > y) fail(n.source(), key() + ": min > max");
    return {x, y};
  }

  Vec2 point(const toml::node& n) const {
    const toml::array* a = n.as_array();
    if (a == nullptr || a->size() != 2) fail(n.source(), key() + ": a point must be [x_m, y_m]");
    return Vec2(static_cast<Real>(number((*a)[0], -1e4, 1e4)), static_cast<Real>(number((*a)[1], -1e4, 1e4)));
  }
};

struct ParseState {
  double motor_latency_s = -1;
  double lidar_sigma_m = -1, lidar_sigma_prop = -1, lidar_dropout = -1, lidar_jitter_rad = -1, lidar_rate_hz = -1,
         lidar_max_range_m = -1;
  int mixed_pixels = -1;
  std::string lidar_model = "ld06";
  const toml::node* lidar_model_node = nullptr;
  std::string lidar_intensity;  ///< [lidar] intensity, empty: the model's own.
  struct FurnitureProfile {
    std::size_t index;  ///< Into Scenario::furniture.
    std::string ref;    ///< A built-in name or a profile file (relative to the scenario).
    const toml::node* node;
  };
  std::vector<FurnitureProfile> furniture_profiles;
  std::string profile = "plate-v";
  const toml::node* profile_node = nullptr;
  bool mounting_set = false;
  dockcore::DockMounting mounting{};
};

/// A profile reference as resolve_profile takes it: a built-in name as it is, a relative file path relative to the
/// scenario file `source_name`.
std::string profile_ref(const std::string& ref, const std::string& source_name) {
  const bool is_file =
      ref.find('/') != std::string::npos || (ref.size() > 5 && ref.compare(ref.size() - 5, 5, ".toml") == 0);
  return is_file && !ref.empty() && ref[0] != '/' ? dir_of(source_name) + ref : ref;
}

/// A profile's outline extent in its dock frame: its back (smallest x) and its sides (smallest and largest y), m.
struct Extent {
  double min_x = 0, min_y = 0, max_y = 0;
};
Extent extent_of(const dockcore::DockProfile& prof) {
  Extent e;
  for (std::size_t i = 0; i < prof.vertex_count; ++i) {
    const Vec2& v = prof.vertices_m[i];
    e.min_x = i == 0 ? static_cast<double>(v.x()) : std::min(e.min_x, static_cast<double>(v.x()));
    e.min_y = i == 0 ? static_cast<double>(v.y()) : std::min(e.min_y, static_cast<double>(v.y()));
    e.max_y = i == 0 ? static_cast<double>(v.y()) : std::max(e.max_y, static_cast<double>(v.y()));
  }
  return e;
}

/// Adds the furniture beside the dock to the scenario's world boxes and circles (docs/scenarios.md, [dock]).
void place_furniture(Scenario& sc) {
  const auto [min_x, min_y, max_y] = extent_of(sc.profile);
  const double back_x = sc.wall ? min_x - sc.wall_gap_m + kFurnitureWallClearanceM : min_x;
  auto world = [&](double x, double y) {
    return sc.dock_pose.transform(Vec2(static_cast<Real>(x), static_cast<Real>(y)));
  };
  for (const DockFurniture& f : sc.furniture) {
    const double near = (f.side > 0 ? max_y : -min_y) + f.gap_m;  // nearest point's |y|, dock frame
    const double sgn = f.side > 0 ? 1.0 : -1.0;
    switch (f.kind) {
      case FurnitureKind::kBox: {
        WorldBox b;
        b.centre = world(f.x_set ? f.x_m : back_x + f.depth_m / 2, sgn * (near + f.width_m / 2));
        b.size_x_m = f.depth_m;
        b.size_y_m = f.width_m;
        b.yaw_rad = static_cast<double>(sc.dock_pose.yaw_rad);
        sc.boxes.push_back(b);
        break;
      }
      case FurnitureKind::kBin: {
        WorldCircle c;
        c.centre = world(f.x_set ? f.x_m : back_x + f.radius_m, sgn * (near + f.radius_m));
        c.r_m = f.radius_m;
        sc.circles.push_back(c);
        break;
      }
      case FurnitureKind::kChair: {
        const double half = f.seat_m / 2, in = half - f.leg_radius_m;
        const double cx = f.x_set ? f.x_m : back_x + half, cy = sgn * (near + half);
        for (const double dx : {-in, in}) {
          for (const double dy : {-in, in}) {
            WorldCircle c;
            c.centre = world(cx + dx, cy + dy);
            c.r_m = f.leg_radius_m;
            sc.circles.push_back(c);
          }
        }
        break;
      }
      case FurnitureKind::kDock: {
        // Its nearest vertex `near` beside the dock, its back plane on the dock's.
        const Extent o = extent_of(f.profile);
        const double y = f.side > 0 ? near - o.min_y : -near - o.max_y;
        const double x = f.x_set ? f.x_m : min_x - o.min_x;
        Scenario::OtherDock d;
        d.profile = f.profile;
        d.pose = sc.dock_pose.compose(Pose2{static_cast<Real>(x), static_cast<Real>(y), 0});
        sc.other_docks.push_back(d);
        break;
      }
    }
  }
}

}  // namespace

Scenario parse_scenario_toml(const std::string& text, const std::string& source_name) {
  Parser p(source_name);
  toml::table root;
  try {
    root = toml::parse(std::string_view(text), std::string_view(source_name));
  } catch (const toml::parse_error& e) {
    p.fail(e.source(), std::string(e.description()));
  }

  Scenario sc;
  sc.source = source_name;
  sc.name = stem_of(source_name);
  ParseState st;
  // dockcore's parameters: the keys, bounds and defaults of the parameter table, the same as dockd's config. The
  // obstacle footprint's body is derived from the chassis below.
  namespace params = dockcore::params;
  const params::ParamTargets targets{nullptr,      &sc.limits,   &sc.safety,   &sc.task,     &sc.estimator,
                                     &sc.seed000,  &sc.seed004,  &sc.seed003,  &sc.smooth,   &sc.tag_fusion,
                                     &sc.watchdog, &sc.deadband, &sc.detector, &sc.intensity};
  params::apply_defaults(targets, params::kScenario);
  auto table_keys = [&](const std::string& table, Handlers h) {
    params::add_params(p, h, table, targets, params::kScenario);
    return h;
  };

  auto robot_handlers = [&]() {
    ChassisParams& c = sc.chassis;
    Handlers h;
    h.emplace_back("kinematics", [&](const toml::node& n) {
      c.geometry.kind = p.choice(n, {"diff", "mecanum"}) == "mecanum" ? DriveKind::kMecanum : DriveKind::kDifferential;
    });
    // The chassis' geometry, with the bounds of dockd's drive geometry keys.
    h.emplace_back("wheel_radius_m", params::bounded_by(p, "robot", "wheel_radius_m", &c.geometry.wheel_radius_m));
    h.emplace_back("wheel_base_m", params::bounded_by(p, "robot", "track_m", &c.geometry.wheel_base_m));
    h.emplace_back("lx_m", params::bounded_by(p, "robot", "half_wheelbase_m", &c.geometry.lx_m));
    h.emplace_back("ly_m", params::bounded_by(p, "robot", "half_track_m", &c.geometry.ly_m));
    h.emplace_back("limits", params::param_sub(p, "robot.limits", targets, params::kScenario));
    h.emplace_back("deadband", params::param_sub(p, "robot.deadband", targets, params::kScenario));
    h.emplace_back("footprint", p.sub("robot.footprint.", [&]() {
      FootprintParams& f = c.footprint;
      // The table's keys (shape, check area, margins) plus the chassis outline the obstacle check's body comes from.
      return table_keys("robot.footprint",
                        Handlers{
                            {"length_m", p.num(&f.length_m, 0.05, 5.0)},
                            {"width_m", p.num(&f.width_m, 0.05, 5.0)},
                            {"radius_m", params::bounded_by(p, "robot.footprint", "radius_m", &f.radius_m)},
                            {"centre_x_m", p.num(&f.centre_x_m, -2.0, 2.0)},
                            {"pads",
                             [&](const toml::node& n) {
                               f.pad_side = p.choice(n, {"front", "rear"}) == "rear" ? PadSide::kRear : PadSide::kFront;
                             }},
                            {"pad_offset_y_m", p.num(&f.pad_offset_y_m, -1.0, 1.0)},
                        });
    }));
    h.emplace_back("lidar", p.sub("robot.lidar.", [&]() {
      return Handlers{{"x_m", p.real(&sc.lidar_mount.x_m, -2, 2)},
                      {"y_m", p.real(&sc.lidar_mount.y_m, -2, 2)},
                      {"yaw_deg", p.real_deg(&sc.lidar_mount.yaw_rad, -180, 180)},
                      // The calibration error dockcore is not told: a lidar bracket is rarely where its drawing says.
                      {"error_x_m", p.real(&sc.lidar_mount_error.x_m, -0.1, 0.1)},
                      {"error_y_m", p.real(&sc.lidar_mount_error.y_m, -0.1, 0.1)},
                      {"error_yaw_deg", p.real_deg(&sc.lidar_mount_error.yaw_rad, -10, 10)}};
    }));
    h.emplace_back("camera", p.sub("robot.camera.", [&]() {
      CameraSpec& cam = sc.camera;
      return Handlers{
          {"enabled", p.flag(&cam.enabled)},
          // The camera seed 003 steers by: the bounds of dockd's [controller.seed003] camera keys.
          {"fx_px", params::bounded_by(p, "controller.seed003", "fx_px", &cam.model.fx_px)},
          {"cx_px", params::bounded_by(p, "controller.seed003", "cx_px", &cam.model.cx_px)},
          {"width_px", params::bounded_by(p, "controller.seed003", "image_width_px", &cam.model.image_width_px)},
          {"x_m", params::bounded_by(p, "controller.seed003", "mount_x_m", &cam.model.mount.x_m)},
          {"y_m", params::bounded_by(p, "controller.seed003", "mount_y_m", &cam.model.mount.y_m)},
          {"yaw_deg", params::bounded_by(p, "controller.seed003", "mount_yaw_deg", &cam.model.mount.yaw_rad)},
          {"rate_hz", p.num(&cam.rate_hz, 0.1, 1000)},
          {"latency_s", p.num(&cam.latency_s, 0, 5)},
          {"sigma_px", p.num(&cam.sigma_px, 0, 1000)},
          {"dropout", p.num(&cam.dropout_prob, 0, 1)},
          {"min_depth_m", p.num(&cam.min_depth_m, 0, 100)},
          {"max_depth_m", p.num(&cam.max_depth_m, 0, 100)},
          {"target_x_m", [&](const toml::node& n) { cam.target_in_dock.x() = static_cast<Real>(p.number(n, -2, 2)); }},
          {"target_y_m", [&](const toml::node& n) { cam.target_in_dock.y() = static_cast<Real>(p.number(n, -2, 2)); }},
          {"render", p.flag(&cam.render)},
          {"fuse_tags", p.flag(&cam.fuse_tags)},
          {"z_m", p.num(&cam.z_m, 0, 3)},
          {"height_px",
           [&](const toml::node& n) { cam.height_px = static_cast<std::uint32_t>(p.integer(n, 16, 8192)); }},
          {"cy_px", p.num(&cam.cy_px, 0, 8192)},
          {"blur_px", p.num(&cam.blur_px, 0, 5)},
          {"noise_grey", p.num(&cam.noise_grey, 0, 64)},
          {"exposure", p.num(&cam.exposure, 0.05, 8)},
          {"decimate", p.num(&cam.decimate, 1, 8)},
      };
    }));
    h.emplace_back("motor", p.sub("robot.motor.", [&]() {
      MotorParams& m = c.motor;
      return Handlers{{"latency_s", [&](const toml::node& n) { st.motor_latency_s = p.number(n, 0, 1.0); }},
                      {"time_constant_s", p.num(&m.time_constant_s, 0, 10)},
                      {"max_accel_radps2", p.num(&m.max_accel_radps2, 0, 1e4)},
                      {"max_speed_radps", p.num(&m.max_speed_radps, 0, 1e4)},
                      {"deadband_radps", p.num(&m.deadband_radps, 0, 100)},
                      {"deadband_diff_radps", p.num(&m.deadband_diff_radps, -100, 100)},
                      {"command_timeout_s", p.num(&m.command_timeout_s, 0, 60)}};
    }));
    h.emplace_back("odometry", p.sub("robot.odometry.", [&]() {
      NoiseParams& o = c.noise;
      return Handlers{
          {"slip_sigma", p.num(&o.slip_sigma, 0, 0.5)},
          {"slip_correlation_s", p.num(&o.slip_correlation_s, 0, 100)},
          {"encoder_cpr",
           [&](const toml::node& n) { o.encoder_cpr = static_cast<std::int32_t>(p.integer(n, 1, 1 << 24)); }},
          {"radius_error", p.num(&o.odom_radius_error, -0.5, 0.5)},
          {"radius_diff", p.num(&o.odom_radius_diff, -0.5, 0.5)},
          {"base_error", p.num(&o.odom_base_error, -0.5, 0.5)},
          {"source", [&](const toml::node& n) {
             sc.odometry_source =
                 p.choice(n, {"chassis", "wheels"}) == "wheels" ? OdometrySource::kWheels : OdometrySource::kChassis;
           }}};
    }));
    return h;
  };

  auto lidar_handlers = [&]() {
    return Handlers{
        {"model",
         [&](const toml::node& n) {
           st.lidar_model = p.string(n);
           st.lidar_model_node = &n;
         }},
        {"sigma_range_m", [&](const toml::node& n) { st.lidar_sigma_m = p.number(n, 0, 1); }},
        {"sigma_prop", [&](const toml::node& n) { st.lidar_sigma_prop = p.number(n, 0, 1); }},
        {"dropout", [&](const toml::node& n) { st.lidar_dropout = p.number(n, 0, 1); }},
        {"angular_jitter_deg", [&](const toml::node& n) { st.lidar_jitter_rad = p.number(n, 0, 10) * kDeg; }},
        {"mixed_pixels", [&](const toml::node& n) { st.mixed_pixels = p.boolean(n) ? 1 : 0; }},
        {"intensity", [&](const toml::node& n) { st.lidar_intensity = p.choice(n, intensity_output_names()); }},
        {"rate_hz", [&](const toml::node& n) { st.lidar_rate_hz = p.number(n, 0.5, 100); }},
        // The sensor's range, under the name of dockd's [lidar] range key: it takes that key's bounds.
        {"max_range_m", params::bounded_by(p, "lidar", "max_range_m", &st.lidar_max_range_m)},
        {"latency_s", p.num(&sc.scan_latency_s, 0, 2)},
    };
  };

  auto dock_handlers = [&]() {
    ContactParams& k = sc.chassis.contact;
    return Handlers{
        {"profile",
         [&](const toml::node& n) {
           st.profile = p.string(n);
           st.profile_node = &n;
         }},
        {"x_m", p.real(&sc.dock_pose.x_m, -1e3, 1e3)},
        {"y_m", p.real(&sc.dock_pose.y_m, -1e3, 1e3)},
        {"yaw_deg", p.real_deg(&sc.dock_pose.yaw_rad, -180, 180)},
        {"face_half_width_m", p.num(&sc.dock_face_half_width_m, 0.005, 2)},
        {"dead", p.flag(&sc.dock_dead)},
        {"stop_short_m", p.num(&sc.dock_stop_short_m, 0, 0.5)},
        {"wall", p.flag(&sc.wall)},
        {"wall_gap_m", p.num(&sc.wall_gap_m, 0, static_cast<double>(dockcore::kMaxWallGapM))},
        {"wall_glass", p.flag(&sc.wall_glass)},
        {"wall_half_length_m", p.num(&sc.wall_half_length_m, 0.1, 100)},
        {"mounting",
         [&](const toml::node& n) {
           st.mounting = dockcore::params::profile_toml::read_mounting(p, n, "dock.mounting.");
           st.mounting_set = true;
         }},
        {"furniture",
         [&](const toml::node& n) {
           const toml::array* a = n.as_array();
           if (a == nullptr) p.fail(n.source(), "dock.furniture must be an array of tables ([[dock.furniture]])");
           for (const toml::node& e : *a) {
             const toml::table* t = e.as_table();
             if (t == nullptr) p.fail(e.source(), "dock.furniture entries must be tables");
             const toml::node* kind_node = t->get("kind");
             if (kind_node == nullptr) p.fail(t->source(), "dock.furniture entry without 'kind' (box, bin, chair)");
             DockFurniture f;
             const toml::value<std::string>* kind_str = kind_node->as_string();
             if (kind_str == nullptr) {
               p.fail(kind_node->source(),
                      std::string("dock.furniture.kind must be a string, not ") + type_name(*kind_node));
             }
             const std::string kind = kind_str->get();
             if (kind != "box" && kind != "bin" && kind != "chair" && kind != "dock") {
               p.fail(kind_node->source(),
                      "dock.furniture.kind = \"" + kind + "\" is not one of box, bin, chair, dock");
             }
             Handlers h{{"kind", [](const toml::node&) {}},
                        {"side",
                         [&](const toml::node& v) {
                           f.side = p.choice(v, {"left", "right"}) == "left" ? 1 : -1;
                         }},
                        {"gap_m", p.num(&f.gap_m, 0, 3)},
                        {"x_m", [&](const toml::node& v) {
                           f.x_m = p.number(v, -3, 3);
                           f.x_set = true;
                         }}};
             if (kind == "box") {
               f.kind = FurnitureKind::kBox;
               h.emplace_back("depth_m", p.num(&f.depth_m, 0.05, 2));
               h.emplace_back("width_m", p.num(&f.width_m, 0.05, 2));
             } else if (kind == "bin") {
               f.kind = FurnitureKind::kBin;
               h.emplace_back("radius_m", p.num(&f.radius_m, 0.05, 1));
             } else if (kind == "dock") {
               f.kind = FurnitureKind::kDock;
               h.emplace_back("profile", [&, index = sc.furniture.size()](const toml::node& v) {
                 st.furniture_profiles.push_back({index, p.string(v), &v});
               });
             } else {
               f.kind = FurnitureKind::kChair;
               h.emplace_back("seat_m", p.num(&f.seat_m, 0.2, 1));
               h.emplace_back("leg_radius_m", p.num(&f.leg_radius_m, 0.005, 0.05));
             }
             p.each(*t, "dock.furniture." + kind + ".", h);
             if (f.kind == FurnitureKind::kDock &&
                 (st.furniture_profiles.empty() || st.furniture_profiles.back().index != sc.furniture.size())) {
               p.fail(t->source(), "dock.furniture entry of kind dock without 'profile'");
             }
             sc.furniture.push_back(f);
           }
         }},
        {"tag", p.sub("dock.tag.",
                      [&]() {
                        DockTagSpec& t = sc.dock_tag;
                        return Handlers{
                            {"id", [&](const toml::node& n) { t.id = static_cast<int>(p.integer(n, 0, 65535)); }},
                            {"family", [&](const toml::node& n) { t.family = p.string(n); }},
                            {"size_m", p.num(&t.size_m, 0.005, 5)},
                            {"z_m", p.num(&t.z_m, 0, 3)}};
                      })},
        {"contacts", p.sub("dock.contacts.",
                           [&]() {
                             return Handlers{{"lateral_tolerance_m", p.num(&k.lateral_tolerance_m, 0, 0.5)},
                                             {"yaw_tolerance_deg", p.deg(&k.yaw_tolerance_rad, 0, 45)},
                                             {"min_press_m", p.num(&k.min_press_m, 0, 0.1)},
                                             {"press_limit_m", p.num(&k.press_limit_m, 0, 0.1)},
                                             {"charge_delay_s", p.num(&k.charge_delay_s, 0, 60)},
                                             {"charge_current_a", p.num(&k.charge_current_a, 0, 1000)},
                                             {"switched", p.flag(&k.switched)}};
                           })},
    };
  };

  auto world_handlers = [&]() {
    auto array_of_tables = [&](const toml::node& n, const std::string& what,
                               const std::function<void(const toml::table&)>& one) {
      const toml::array* a = n.as_array();
      if (a == nullptr) p.fail(n.source(), "world." + what + " must be an array of tables ([[world." + what + "]])");
      for (const toml::node& e : *a) {
        const toml::table* t = e.as_table();
        if (t == nullptr) p.fail(e.source(), "world." + what + " entries must be tables");
        one(*t);
      }
    };
    return Handlers{
        {"polylines",
         [&, array_of_tables](const toml::node& n) {
           array_of_tables(n, "polylines", [&](const toml::table& t) {
             WorldPolyline pl;
             p.each(t, "world.polylines.",
                    {{"points",
                      [&](const toml::node& pn) {
                        const toml::array* a = pn.as_array();
                        if (a == nullptr || a->size() < 2) {
                          p.fail(pn.source(), "points must be an array of >= 2 [x_m, y_m]");
                        }
                        for (const toml::node& q : *a) pl.points.push_back(p.point(q));
                      }},
                     {"closed", p.flag(&pl.closed)}});
             if (pl.points.size() < 2) p.fail(t.source(), "a polyline needs points");
             sc.polylines.push_back(pl);
           });
         }},
        {"boxes",
         [&, array_of_tables](const toml::node& n) {
           array_of_tables(n, "boxes", [&](const toml::table& t) {
             WorldBox b;
             p.each(t, "world.boxes.",
                    {{"x_m", [&](const toml::node& v) { b.centre.x() = static_cast<Real>(p.number(v, -1e3, 1e3)); }},
                     {"y_m", [&](const toml::node& v) { b.centre.y() = static_cast<Real>(p.number(v, -1e3, 1e3)); }},
                     {"size_x_m", p.num(&b.size_x_m, 0.001, 1e3)},
                     {"size_y_m", p.num(&b.size_y_m, 0.001, 1e3)},
                     {"yaw_deg", p.deg(&b.yaw_rad, -180, 180)}});
             sc.boxes.push_back(b);
           });
         }},
        {"circles",
         [&, array_of_tables](const toml::node& n) {
           array_of_tables(n, "circles", [&](const toml::table& t) {
             WorldCircle c;
             p.each(t, "world.circles.",
                    {{"x_m", [&](const toml::node& v) { c.centre.x() = static_cast<Real>(p.number(v, -1e3, 1e3)); }},
                     {"y_m", [&](const toml::node& v) { c.centre.y() = static_cast<Real>(p.number(v, -1e3, 1e3)); }},
                     {"r_m", p.num(&c.r_m, 0.001, 100)}});
             sc.circles.push_back(c);
           });
         }},
    };
  };

  auto start_handlers = [&]() {
    StartEnvelope& s = sc.start;
    return Handlers{
        {"distance_m",
         [&](const toml::node& n) {
           const auto r = p.range(n, 0.05, 50);
           s.distance_min_m = r.first;
           s.distance_max_m = r.second;
         }},
        {"bearing_deg",
         [&](const toml::node& n) {
           const auto r = p.range(n, -90, 90);
           s.bearing_min_rad = r.first * kDeg;
           s.bearing_max_rad = r.second * kDeg;
         }},
        {"heading_deg",
         [&](const toml::node& n) {
           const auto r = p.range(n, -180, 180);
           s.heading_min_rad = r.first * kDeg;
           s.heading_max_rad = r.second * kDeg;
         }},
    };
  };

  auto events_handler = [&](const toml::node& n) {
    const toml::array* a = n.as_array();
    if (a == nullptr) p.fail(n.source(), "events must be an array of tables ([[events]])");
    for (const toml::node& e : *a) {
      const toml::table* t = e.as_table();
      if (t == nullptr) p.fail(e.source(), "events entries must be tables");
      ScenarioEvent ev;
      const toml::node* type = t->get("type");
      if (type == nullptr) p.fail(t->source(), "event without 'type'");
      if (t->get("t_s") == nullptr) p.fail(t->source(), "event without 't_s'");
      const std::string kind = p.choice(*type, {"push", "occlude_dock", "obstacle", "lidar_dropout",
                                                "charging_never_starts", "chassis_silent", "host_stall"});
      Handlers h{{"type", [](const toml::node&) {}},
                 {"t_s", p.num(&ev.t_s, 0, 1e5)},
                 {"in_state", [&](const toml::node& s_node) {
                    std::vector<std::string> names;
                    for (std::uint8_t i = 0; i <= static_cast<std::uint8_t>(dockcore::TaskState::kTestMode); ++i) {
                      names.emplace_back(dockcore::to_string(static_cast<dockcore::TaskState>(i)));
                    }
                    const std::string name = p.choice(s_node, names);
                    for (std::uint8_t i = 0; i < names.size(); ++i) {
                      if (names[i] == name) ev.state = static_cast<dockcore::TaskState>(i);
                    }
                    ev.after_state = true;
                  }}};
      const Handler dur = p.num(&ev.duration_s, 0, 1e5);
      if (kind == "push") {
        ev.kind = EventKind::kPush;
        h.emplace_back("dx_m", p.num(&ev.dx_m, -10, 10));
        h.emplace_back("dy_m", p.num(&ev.dy_m, -10, 10));
        h.emplace_back("dyaw_deg", p.deg(&ev.dyaw_rad, -180, 180));
      } else if (kind == "occlude_dock") {
        ev.kind = EventKind::kOccludeDock;
        h.emplace_back("duration_s", dur);
      } else if (kind == "obstacle") {
        ev.kind = EventKind::kObstacle;
        h.emplace_back("x_m", p.num(&ev.x_m, -1e3, 1e3));
        h.emplace_back("y_m", p.num(&ev.y_m, -1e3, 1e3));
        h.emplace_back("r_m", p.num(&ev.r_m, 0.005, 10));
        h.emplace_back("vx_mps", p.num(&ev.vx_mps, -5, 5));
        h.emplace_back("vy_mps", p.num(&ev.vy_mps, -5, 5));
        h.emplace_back("duration_s", dur);
      } else if (kind == "lidar_dropout") {
        ev.kind = EventKind::kLidarDropout;
        h.emplace_back("duration_s", dur);
      } else if (kind == "charging_never_starts") {
        ev.kind = EventKind::kChargingNeverStarts;
      } else if (kind == "host_stall") {
        ev.kind = EventKind::kHostStall;
        h.emplace_back("duration_s", dur);
      } else {
        ev.kind = EventKind::kChassisSilent;
        h.emplace_back("duration_s", dur);
        h.emplace_back("motion", [&](const toml::node& m) {
          ev.hold_last_command = p.choice(m, {"stop", "hold"}) == "hold";
        });
      }
      p.each(*t, "events." + kind + ".", h);
      sc.events.push_back(ev);
    }
  };

  auto host_handlers = [&]() {
    HostSpec& h = sc.host;
    return Handlers{{"redock_after_fault",
                     [&](const toml::node& n) { h.redock_after_fault = static_cast<int>(p.integer(n, 0, 100)); }},
                    {"redock_delay_s", p.num(&h.redock_delay_s, 0, 100)}};
  };

  auto controller_handlers = [&]() {
    Handlers h =
        table_keys("controller",
                   Handlers{{"name", [&](const toml::node& n) { sc.controller = p.choice(n, controller_names()); }}});
    for (const std::string& name : controller_names()) {
      h.emplace_back(name, params::param_sub(p, "controller." + name, targets, params::kScenario));
    }
    return h;
  };

  const Handlers top{
      {"name", [&](const toml::node& n) { sc.name = p.string(n); }},
      {"seed", [&](const toml::node& n) { sc.seed = static_cast<std::uint64_t>(p.integer(n, 0, INT64_MAX)); }},
      {"max_time_s", p.num(&sc.max_time_s, 0.1, 1e5)},
      {"settle_after_end_s", p.num(&sc.settle_after_end_s, 0, 100)},
      {"robot", p.sub("robot.", robot_handlers)},
      {"lidar", p.sub("lidar.", lidar_handlers)},
      {"dock", p.sub("dock.",
                     [&]() {
                       Handlers h = dock_handlers();
                       params::add_params(p, h, "dock", targets, params::kScenario);  // detector
                       return h;
                     })},
      {"world", p.sub("world.", world_handlers)},
      {"start", p.sub("start.", start_handlers)},
      {"events", events_handler},
      {"task", params::param_sub(p, "task", targets, params::kScenario)},
      {"estimator", p.sub("estimator.",
                          [&]() {
                            return table_keys("estimator",
                                              Handlers{{"segments", params::param_sub(p, "estimator.segments", targets,
                                                                                      params::kScenario)}});
                          })},
      {"host", p.sub("host.", host_handlers)},
      {"watchdog", params::param_sub(p, "watchdog", targets, params::kScenario)},
      {"intensity", params::param_sub(p, "intensity", targets, params::kScenario)},
      {"controller", p.sub("controller.", controller_handlers)},
      {"camera", p.sub("camera.",
                       [&]() {
                         return Handlers{{"fusion", params::param_sub(p, "camera.fusion", targets, params::kScenario)}};
                       })},
  };
  p.each(root, "", top);

  // --- Derived values and cross-checks ---
  ChassisParams& c = sc.chassis;
  c.footprint.shape =
      sc.safety.shape == dockcore::FootprintShape::kCircular ? FootprintShape::kCircle : FootprintShape::kRectangle;
  if (st.motor_latency_s >= 0) {
    c.motor.latency_steps = static_cast<std::size_t>(std::lround(st.motor_latency_s / c.dt_s));
  }
  if (const char* bad = check_chassis_params(c)) p.fail(root.source(), std::string("robot: ") + bad);

  if (!lidar_model(st.lidar_model, &sc.lidar)) {
    std::string names;
    for (const auto& n : lidar_model_names()) names += (names.empty() ? "" : ", ") + n;
    p.fail(st.lidar_model_node != nullptr ? st.lidar_model_node->source() : root.source(),
           "lidar.model = \"" + st.lidar_model + "\" is not one of " + names);
  }
  if (st.lidar_sigma_m >= 0) sc.lidar.sigma_const_m = st.lidar_sigma_m;
  if (st.lidar_sigma_prop >= 0) sc.lidar.sigma_prop = st.lidar_sigma_prop;
  if (st.lidar_dropout >= 0) sc.lidar.dropout_prob = st.lidar_dropout;
  if (st.lidar_jitter_rad >= 0) sc.lidar.angular_jitter_rad = st.lidar_jitter_rad;
  if (st.mixed_pixels >= 0) sc.lidar.mixed_pixels = st.mixed_pixels == 1;
  if (st.lidar_rate_hz > 0) sc.lidar.rate_hz = st.lidar_rate_hz;
  if (st.lidar_max_range_m > 0) sc.lidar.max_range_m = st.lidar_max_range_m;
  if (!st.lidar_intensity.empty()) intensity_output(st.lidar_intensity, &sc.lidar.intensity_output);

  sc.profile_name = st.profile;
  {
    try {
      sc.profile = resolve_profile(profile_ref(st.profile, source_name));
    } catch (const ProfileFileError& e) {
      p.fail(st.profile_node != nullptr ? st.profile_node->source() : root.source(),
             std::string("dock.profile: ") + e.what());
    }
  }
  // What the detector is told is independent of the world: [dock.mounting] replaces the profile file's.
  if (st.mounting_set) sc.profile.mounting = st.mounting;
  for (std::size_t i = 0; i < sc.furniture.size(); ++i) {
    if (sc.furniture[i].kind != FurnitureKind::kDock) continue;
    const auto it = std::find_if(st.furniture_profiles.begin(), st.furniture_profiles.end(),
                                 [i](const ParseState::FurnitureProfile& f) { return f.index == i; });
    try {
      sc.furniture[i].profile = resolve_profile(profile_ref(it->ref, source_name));
    } catch (const ProfileFileError& e) {
      p.fail(it->node->source(), std::string("dock.furniture.profile: ") + e.what());
    }
  }
  // The detector must be able to find this dock (refused here rather than when the run configures the core).
  const dockcore::ConfigureStatus detector_ok = dockcore::detector_supports(sc.detector, sc.profile);
  if (detector_ok != dockcore::ConfigureStatus::kOk) {
    p.fail(p.where("dock.detector", root.source()), std::string("dock.detector = \"") +
                                                        dockcore::to_string(sc.detector) +
                                                        "\": " + dockcore::to_string(detector_ok));
  }
  if (!sc.wall) {
    for (const char* key : {"dock.wall_gap_m", "dock.wall_glass"}) {
      const toml::source_region none{};
      const toml::source_region at = p.where(key, none);
      if (at.begin.line != 0) p.fail(at, std::string(key) + " is only meaningful with dock.wall = true");
    }
  }
  place_furniture(sc);

  // Obstacle-check footprint from the chassis outline (centred on the footprint's extent about the rotation centre).
  dockcore::FootprintParams& f = sc.safety;
  if (c.footprint.shape == FootprintShape::kCircle) {
    f.shape = dockcore::FootprintShape::kCircular;
    f.radius_m = static_cast<Real>(std::fabs(c.footprint.centre_x_m) + c.footprint.radius_m);
    f.circumscribed_radius_m = f.radius_m;
  } else {
    f.shape = dockcore::FootprintShape::kSquare;
    f.half_length_m = static_cast<Real>(std::fabs(c.footprint.centre_x_m) + c.footprint.length_m / 2);
    f.half_width_m = static_cast<Real>(c.footprint.width_m / 2);
    f.circumscribed_radius_m =
        static_cast<Real>(std::hypot(static_cast<double>(f.half_length_m), c.footprint.width_m / 2));
  }

  params::RobotFacts robot;
  robot.pads_rear = c.footprint.pad_side == PadSide::kRear;
  robot.mecanum = c.geometry.kind == DriveKind::kMecanum;
  robot.charger_switched = c.contact.switched;
  bool pad_reach_set = p.given("controller.pad_reach_m");
  for (const std::string& name : controller_names()) pad_reach_set |= p.given("controller." + name + ".pad_reach_m");
  if (!pad_reach_set) robot.pad_reach_m = pad_reach_of(c);
  robot.holonomic_given = p.given("controller.seed003.holonomic");
  robot.backwards_given = p.given("controller.smooth.backwards");
  params::derive_from_robot(robot, targets);
  sc.seed003.camera = sc.camera.model;

  std::stable_sort(sc.events.begin(), sc.events.end(),
                   [](const ScenarioEvent& a, const ScenarioEvent& b) { return a.t_s < b.t_s; });
  return sc;
}

Scenario load_scenario_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ScenarioError("cannot open scenario file " + path);
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw ScenarioError("cannot read scenario file " + path);
  return parse_scenario_toml(ss.str(), path);
}

}  // namespace docksim
