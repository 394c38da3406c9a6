#include "config.hpp"
#include "camera_config_keys.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <utility>

#include <arpa/inet.h>
#include <sys/stat.h>

#include <toml++/toml.h>

#include "dockcore/params/param_toml.hpp"
#include "dockcore/params/profile_toml.hpp"
#include "dockcore/params/toml_reader.hpp"

namespace dockd {

using dockcore::Real;
using dockcore::Vec2;

namespace {

using dockcore::params::toml_reader::dir_of;
using dockcore::params::toml_reader::Handler;
using dockcore::params::toml_reader::Handlers;
using dockcore::params::toml_reader::kDeg;
using dockcore::params::toml_reader::type_name;
/// Every key dispatched to a handler, unknown keys and bad values reported at their TOML source position (the same
/// reader as dock-sim's scenarios).
using Parser = dockcore::params::toml_reader::Reader<ConfigError>;

/// Reads a regular file of at most `max_bytes` into `out`. False + reason otherwise: a FIFO, a device (/dev/zero)
/// or an oversized file must not block dockd or grow its memory without bound.
bool read_bounded(const std::string& path, std::size_t max_bytes, std::string& out, std::string& why) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    why = "cannot open";
    return false;
  }
  if (!S_ISREG(st.st_mode)) {
    why = "not a regular file";
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    why = "cannot open";
    return false;
  }
  out.assign(max_bytes + 1, '\0');
  in.read(&out[0], static_cast<std::streamsize>(out.size()));
  if (in.bad()) {
    why = "cannot read";
    return false;
  }
  out.resize(static_cast<std::size_t>(in.gcount()));
  if (out.size() > max_bytes) {
    why = "larger than " + std::to_string(max_bytes) + " bytes";
    return false;
  }
  return true;
}

/// robot.footprint.self_sectors_deg = [[from_deg, to_deg], ...]: the lidar-frame bearings where the lidar sees the
/// robot's own structure (FootprintParams::self_sectors, at most kMaxSelfSectors). Bounds in [-180, 180]; from > to
/// wraps through 180 (a sector behind the lidar). Stored through wrap_angle, the core's (-pi, pi] convention, so
/// -180 is the same bearing as 180. A sector whose bounds name one bearing ([10, 10], [-180, 180]) is refused: it
/// holds no beam in practice, and [-180, 180] reads as "all round", which would hide every obstacle inside the body.
void self_sectors(const Parser& p, const toml::node& n, dockcore::FootprintParams& f) {
  const std::string key = p.key();
  const toml::array* a = n.as_array();
  if (a == nullptr) {
    p.fail(n.source(), key + " must be an array of [from_deg, to_deg] pairs, not " + type_name(n));
  }
  if (a->size() > dockcore::kMaxSelfSectors) {
    p.fail(n.source(), key + " has " + std::to_string(a->size()) + " sectors (at most " +
                           std::to_string(dockcore::kMaxSelfSectors) + ")");
  }
  dockcore::AngleSector out[dockcore::kMaxSelfSectors] = {};
  for (std::size_t i = 0; i < a->size(); ++i) {
    const toml::node& e = (*a)[i];
    const toml::array* pair = e.as_array();
    if (pair == nullptr || pair->size() != 2) {
      p.fail(e.source(), key + " sector " + std::to_string(i + 1) + " must be a [from_deg, to_deg] pair, not " +
                             (pair == nullptr ? std::string(type_name(e))
                                              : "an array of " + std::to_string(pair->size())));
    }
    // number() reports with the key name; the sector's position is in the file:line:col.
    const double from_deg = p.number((*pair)[0], -180, 180);
    const double to_deg = p.number((*pair)[1], -180, 180);
    out[i].min_rad = dockcore::wrap_angle(static_cast<Real>(from_deg * kDeg));
    out[i].max_rad = dockcore::wrap_angle(static_cast<Real>(to_deg * kDeg));
    if (out[i].min_rad == out[i].max_rad) {
      std::ostringstream s;
      s << key << " sector " << i + 1 << " [" << from_deg << ", " << to_deg
        << "] has from and to on the same bearing (an empty sector, or all round: give its real extent)";
      p.fail(e.source(), s.str());
    }
  }
  for (std::size_t i = 0; i < dockcore::kMaxSelfSectors; ++i) f.self_sectors[i] = out[i];
  f.self_sector_count = static_cast<std::uint8_t>(a->size());
}

/// A profile file (docs/docks.md), parsed by the parser dock-sim uses. An error inside the file is reported at the
/// profile file's line and column, naming the config key that refers to it; a file that cannot be read is reported
/// at that key.
dockcore::DockProfile load_profile(const Parser& p, const toml::node& at, const std::string& path) {
  std::string text, why;
  if (!read_bounded(path, kMaxProfileFileBytes, text, why)) p.fail(at.source(), "profile file " + path + ": " + why);
  try {
    return dockcore::params::profile_toml::parse<ConfigError>(text, path,
                                                               dockcore::params::profile_toml::name_from_path(path));
  } catch (const ConfigError& e) {
    const toml::source_position& w = at.source().begin;
    throw ConfigError(std::string(e.what()) + " (dock profile named at " + p.src() + ":" + std::to_string(w.line) +
                          ":" + std::to_string(w.column) + ")",
                      e.line(), e.column());
  }
}

}  // namespace

bool parse_log_level(const std::string& s, LogLevel& out) {
  if (s == "error") out = LogLevel::kError;
  else if (s == "warn") out = LogLevel::kWarn;
  else if (s == "info") out = LogLevel::kInfo;
  else if (s == "debug") out = LogLevel::kDebug;
  else return false;
  return true;
}

const DockEntry* DockdConfig::find_dock(std::uint16_t id) const {
  for (const DockEntry& d : docks) {
    if (d.id == id) return &d;
  }
  return nullptr;
}

dockcore::StripeReadParams stripe_read_params(const DockdConfig& c) {
  dockcore::StripeReadParams p;
  p.inlier_gate_m = c.estimator.inlier_gate_m;
  p.min_intensity = c.estimator.reflector_min_intensity;
  p.min_range_m = c.estimator.min_range_m;
  p.min_inlier_beams = c.estimator.min_inliers;
  return p;
}

Pose2 nominal_docked_target(const DockdConfig& c) {
  const Real reach = static_cast<Real>(c.pad_reach_m);
  return c.pads_rear ? Pose2{-reach, 0, 0} : Pose2{reach, 0, dockcore::kPi};
}

dockcore::DockProfile profile_for_target(const dockcore::DockProfile& profile, const Pose2& nominal,
                                         const Pose2& target) {
  const Pose2 m = nominal.inverse().compose(target);
  dockcore::DockProfile out = profile;
  for (std::size_t i = 0; i < out.vertex_count; ++i) out.vertices_m[i] = m.transform(profile.vertices_m[i]);
  return out;
}

DockdConfig parse_config_toml(const std::string& text, const std::string& source_name) {
  Parser p(source_name);
  if (text.size() > kMaxConfigBytes) {
    throw ConfigError(source_name + ":1:1: config larger than " + std::to_string(kMaxConfigBytes) + " bytes", 1, 1);
  }
  toml::table root;
  try {
    root = toml::parse(text, source_name);
  } catch (const toml::parse_error& e) {
    p.fail(e.source(), std::string(e.description()));
  }
  DockdConfig c;
  c.source = source_name;
  std::string lidar_protocol = "ld06", lidar_transport = "serial", can_protocol = "dockcore-v1";
  std::string drive_kind = "differential", pad_side = "front";
  const toml::node* lidar_protocol_node = nullptr;
  // The core structs' keys, with their bounds, come from the parameter table (the same as dock-sim's scenarios).
  namespace params = dockcore::params;
  const params::ParamTargets targets{&c.drive,    &c.limits,   &c.footprint, &c.task,     &c.estimator,
                                     &c.seed000,  &c.seed004,  &c.seed003,   &c.smooth,   &c.tag_fusion,
                                     &c.watchdog, &c.deadband, nullptr,      &c.intensity};
  auto table_keys = [&](const std::string& table, Handlers h) {
    params::add_params(p, h, table, targets, params::kDockd);
    return h;
  };
  std::vector<const toml::node*> dock_profile_nodes;
  std::vector<const toml::node*> dock_detector_nodes;  ///< Where each dock set its detector (nullptr: not given).
  // The detector key of one dock entry, from the parameter table: its values, stored into `d`.
  const params::ParamSpec* const detector_spec = params::find_param("docks", "detector", params::kDockd);
  auto detector_key = [&](DockEntry* d, const toml::node** where) {
    return [&p, detector_spec, d, where](const toml::node& v) {
      const params::ParamTargets t{nullptr, nullptr, nullptr, nullptr, nullptr, nullptr,     nullptr,
                                   nullptr, nullptr, nullptr, nullptr, nullptr, &d->detector};
      params::param_handler(p, *detector_spec, t)(v);
      *where = &v;
    };
  };
  std::vector<toml::source_region> dock_tag_nodes;  ///< Where a [[docks]] entry set tag_id (for the camera check).
  // Per dock: the [mounting] given in its entry, which replaces the profile's own (the same dock shape may stand
  // against a wall in one place and free in another).
  std::vector<std::pair<bool, dockcore::DockMounting>> dock_mountings;
  auto mounting_handler = [&](std::pair<bool, dockcore::DockMounting>* out, const std::string& path) {
    return [&p, out, path](const toml::node& v) {
      *out = {true, dockcore::params::profile_toml::read_mounting(p, v, path)};
    };
  };

  auto lidar = [&]() {
    auto& l = c.lidar;
    return table_keys("lidar", Handlers{
        {"protocol", [&](const toml::node& n) {
           lidar_protocol = p.choice(n, {"ld06", "rplidar", "lakibeam"});
           lidar_protocol_node = &n;
         }},
        {"transport", [&](const toml::node& n) { lidar_transport = p.choice(n, {"serial", "udp"}); }},
        {"device", p.str(&l.device)},
        {"baud", [&](const toml::node& n) {
           l.baud = static_cast<std::uint32_t>(p.integer(n, 9600, 4000000));
         }},
        {"udp_bind", p.str(&l.udp_bind_address)},
        {"udp_source", [&](const toml::node& n) {
           l.udp_source_address = p.string(n);
           in_addr a{};
           if (!l.udp_source_address.empty() && ::inet_pton(AF_INET, l.udp_source_address.c_str(), &a) != 1) {
             p.fail(n.source(), p.key() + " = \"" + l.udp_source_address + "\" is not an IPv4 address");
           }
         }},
        {"udp_port", p.integ(&l.udp_port, 1, 65535)},
        {"reconnect_min_ms", p.integ(&l.reconnect_min_ms, 10, 60000)},
        {"reconnect_max_ms", p.integ(&l.reconnect_max_ms, 10, 600000)},
        {"mount_x_m", p.real(&c.lidar_mount.x_m, -2, 2)},
        {"mount_y_m", p.real(&c.lidar_mount.y_m, -2, 2)},
        {"mount_yaw_deg", p.real_deg(&c.lidar_mount.yaw_rad, -180, 180)},
    });
  };

  auto can = [&]() {
    return Handlers{
        {"interface", p.str(&c.can_interface)},
        {"protocol", [&](const toml::node& n) { can_protocol = p.choice(n, {"dockcore-v1", "agilex-v2"}); }},
        {"chassis_base_id", p.integ(&c.can.chassis_base_id, 0, 0x7F0)},
        {"host_base_id", p.integ(&c.can.host_base_id, 0, 0x7F0)},
        {"status_rate_hz", p.num(&c.status_rate_hz, 1, 50)},
    };
  };

  auto robot = [&]() {
    Handlers h = table_keys("robot", Handlers{
        {"drive", [&](const toml::node& n) { drive_kind = p.choice(n, {"differential", "mecanum"}); }},
        {"pad_side", [&](const toml::node& n) { pad_side = p.choice(n, {"front", "rear"}); }},
    });
    h.emplace_back("limits", params::param_sub(p, "robot.limits", targets, params::kDockd));
    h.emplace_back("deadband", params::param_sub(p, "robot.deadband", targets, params::kDockd));
    h.emplace_back("footprint", p.sub("robot.footprint.", [&]() {
      return table_keys("robot.footprint", Handlers{
          {"self_sectors_deg", [&](const toml::node& n) { self_sectors(p, n, c.footprint); }},
      });
    }));
    return h;
  };

  auto dock_entry = [&](const toml::node& n) {
    const toml::table& t = p.table(n);
    DockEntry d;
    const toml::node* profile_node = &n;
    double tx = 0, ty = 0, tyaw = 0;
    bool tx_set = false, ty_set = false, tyaw_set = false;
    double tag_id = -1, tag_yaw_deg = 0;
    bool tag_id_set = false, tag_place_set = false;
    const toml::node* tag_place_node = nullptr;
    toml::source_region tag_id_region{};
    auto tag_place = [&](dockcore::Real* out) {
      return [&, out](const toml::node& v) {
        *out = static_cast<Real>(p.number(v, -2, 2));
        tag_place_set = true;
        tag_place_node = &v;
      };
    };
    std::pair<bool, dockcore::DockMounting> mounting{false, {}};
    const toml::node* detector_node = nullptr;
    const std::string base = p.key() + ".";
    p.each(t, base,
           Handlers{{"id", p.integ(&d.id, 0, 31)},
                    {"detector", detector_key(&d, &detector_node)},
                    {"profile",
                     [&](const toml::node& v) {
                       d.profile_ref = p.string(v);
                       profile_node = &v;
                     }},
                    {"target_x_m",
                     [&](const toml::node& v) {
                       tx = p.number(v, -3, 3);
                       tx_set = true;
                     }},
                    {"target_y_m",
                     [&](const toml::node& v) {
                       ty = p.number(v, -3, 3);
                       ty_set = true;
                     }},
                    {"target_yaw_deg",
                     [&](const toml::node& v) {
                       tyaw = p.number(v, -180, 180);
                       tyaw_set = true;
                     }},
                    {"tag_id",
                     [&](const toml::node& v) {
                       tag_id = static_cast<double>(p.integer(v, 0, 65535));
                       tag_id_set = true;
                       tag_id_region = v.source();
                     }},
                    {"tag_x_m", tag_place(&d.tag.x_m)},
                    {"tag_y_m", tag_place(&d.tag.y_m)},
                    {"tag_z_m", tag_place(&d.tag.z_m)},
                    {"tag_yaw_deg",
                     [&](const toml::node& v) {
                       tag_yaw_deg = p.number(v, -180, 180);
                       tag_place_set = true;
                       tag_place_node = &v;
                     }},
                    {"mounting", mounting_handler(&mounting, base + "mounting.")}});
    if (tag_place_set && !tag_id_set) {
      p.fail(tag_place_node->source(),
             base + "tag_x_m / tag_y_m / tag_z_m / tag_yaw_deg need " + base + "tag_id (the id of the tag they place)");
    }
    if (tag_id_set) {
      d.tag.id = static_cast<std::int32_t>(tag_id);
      d.tag.yaw_rad = static_cast<Real>(tag_yaw_deg * kDeg);
    }
    if (tx_set || ty_set || tyaw_set) {
      if (!(tx_set && ty_set && tyaw_set)) p.fail(n.source(), "dock target needs all of target_x_m, target_y_m, target_yaw_deg");
      d.has_target = true;
      d.target = Pose2{static_cast<Real>(tx), static_cast<Real>(ty), static_cast<Real>(tyaw * kDeg)};
    }
    for (const DockEntry& o : c.docks) {
      if (o.id == d.id) p.fail(n.source(), "dock id " + std::to_string(d.id) + " appears twice");
    }
    c.docks.push_back(d);
    dock_profile_nodes.push_back(profile_node);
    dock_detector_nodes.push_back(detector_node);
    dock_mountings.push_back(mounting);
    if (tag_id_set) dock_tag_nodes.push_back(tag_id_region);
  };

  auto controller = [&]() {
    Handlers h = table_keys("controller", Handlers{{"name", [&](const toml::node& n) {
                                                      c.controller = p.choice(n, {"seed000", "seed004", "seed003", "smooth"});
                                                    }}});
    for (const char* name : {"smooth", "seed000", "seed004", "seed003"}) {
      h.emplace_back(name, params::param_sub(p, std::string("controller.") + name, targets, params::kDockd));
    }
    return h;
  };

  auto host = [&]() {
    auto& h = c.host;
    return Handlers{{"enabled", p.flag(&c.host_enabled)},
                    {"bind", p.str(&h.bind_address)},
                    {"port", p.integ(&h.port, 1, 65535)},
                    {"allowlist", [&](const toml::node& n) {
                       const toml::array* a = n.as_array();
                       if (a == nullptr) p.fail(n.source(), p.key() + " must be an array of strings");
                       if (a->size() > kMaxAllowlistEntries) {
                         p.fail(n.source(), p.key() + " has " + std::to_string(a->size()) + " entries (at most " +
                                                std::to_string(kMaxAllowlistEntries) + ")");
                       }
                       h.allowlist.clear();
                       for (const toml::node& e : *a) {
                         const std::string s = p.string(e);
                         std::uint32_t ad = 0, m = 0;
                         if (!dockcore::drivers::parse_ipv4_cidr(s, ad, m)) {
                           p.fail(e.source(), p.key() + ": '" + s + "' is not an IPv4 address or a.b.c.d/prefix");
                         }
                         h.allowlist.push_back(s);
                       }
                     }},
                    {"max_subscribers", p.integ(&h.max_subscribers, 1, 64)},
                    {"subscription_ms", p.integ(&h.subscription_ms, 1000, 600000)}};
  };

  auto camera = [&]() {
    auto& k = c.camera;
    Handlers h{{"enabled", p.flag(&c.camera_enabled)},
               {"bind", p.str(&k.bind_address)},
               {"port", p.integ(&k.port, 1, 65535)},
               {"target_id", p.integ(&k.target_id, -1, 65535)},
               {"max_age_ms", p.integ(&k.max_age_ms, 10, 10000)}};
    add_camera_device_keys(p, h, c.camera_device);  // dockd's own capture and detector (camera_config.cpp)
    h.emplace_back("fusion", params::param_sub(p, "camera.fusion", targets, params::kDockd));
    return h;
  };

  auto record = [&]() {
    return Handlers{{"dir", p.str(&c.record_dir)},
                    {"max_bytes", p.integ(&c.record_max_bytes, 4096, std::int64_t{1} << 40)},
                    {"max_files", p.integ(&c.record_max_files, 1, 1000)},
                    {"loop", p.flag(&c.record_loop)}};
  };

  auto watchdog = [&]() {
    return table_keys("watchdog", Handlers{{"systemd_divider", p.integ(&c.systemd_watchdog_divider, 2, 10)}});
  };

  auto state = [&]() {
    return Handlers{{"file", p.str(&c.state_file)},
                    {"teach_scans", p.integ(&c.teach_scans, 1, 1000)},
                    {"teach_timeout_s", p.num(&c.teach_timeout_s, 1, 600)}};
  };

  auto log = [&]() {
    return Handlers{{"level", [&](const toml::node& n) {
      parse_log_level(p.choice(n, {"error", "warn", "info", "debug"}), c.log_level);
    }}};
  };

  const toml::node* docks_node = nullptr;
  const Handlers top{
      {"lidar", p.sub("lidar.", lidar)},
      {"can", p.sub("can.", can)},
      {"robot", p.sub("robot.", robot)},
      {"dock",
       [&](const toml::node& n) {
         // [dock] is the single-dock shorthand of [[docks]], plus default_id.
         const toml::table& t = p.table(n);
         DockEntry d;
         const toml::node* profile_node = &n;
         std::pair<bool, dockcore::DockMounting> mounting{false, {}};
         const toml::node* detector_node = nullptr;
         bool entry = false;
         p.each(t, "dock.",
                Handlers{{"default_id", p.integ(&c.default_dock_id, 0, 31)},
                         {"id",
                          [&](const toml::node& v) {
                            d.id = static_cast<std::uint16_t>(p.integer(v, 0, 31));
                            entry = true;
                          }},
                         {"profile",
                          [&](const toml::node& v) {
                            d.profile_ref = p.string(v);
                            profile_node = &v;
                            entry = true;
                          }},
                         {"detector",
                          [&](const toml::node& v) {
                            detector_key(&d, &detector_node)(v);
                            entry = true;
                          }},
                         {"mounting", [&](const toml::node& v) {
                            mounting_handler(&mounting, "dock.mounting.")(v);
                            entry = true;
                          }}});
         if (entry) {
           for (const DockEntry& o : c.docks) {
             if (o.id == d.id) p.fail(n.source(), "dock id " + std::to_string(d.id) + " appears twice");
           }
           c.docks.push_back(d);
           dock_profile_nodes.push_back(profile_node);
           dock_detector_nodes.push_back(detector_node);
           dock_mountings.push_back(mounting);
         }
       }},
      {"docks",
       [&](const toml::node& n) {
         const toml::array* a = n.as_array();
         if (a == nullptr) p.fail(n.source(), "docks must be an array of tables ([[docks]])");
         docks_node = &n;
         for (const toml::node& e : *a) dock_entry(e);
       }},
      {"estimator", p.sub("estimator.",
                          [&]() {
                            // The estimator's tuning; its range keys are in [lidar].
                            return table_keys("estimator",
                                              Handlers{{"segments", params::param_sub(p, "estimator.segments", targets,
                                                                                      params::kDockd)}});
                          })},
      {"controller", p.sub("controller.", controller)},
      {"task", params::param_sub(p, "task", targets, params::kDockd)},
      {"host", p.sub("host.", host)},
      {"camera", p.sub("camera.", camera)},
      {"record", p.sub("record.", record)},
      {"watchdog", p.sub("watchdog.", watchdog)},
      {"intensity", params::param_sub(p, "intensity", targets, params::kDockd)},
      {"state", p.sub("state.", state)},
      {"log", p.sub("log.", log)},
  };
  p.each(root, "", top);
  (void)docks_node;

  // Derived values and cross-key checks.
  c.lidar.protocol = *dockcore::drivers::parse_lidar_protocol(lidar_protocol);
  c.lidar.transport = lidar_transport == "udp" ? dockcore::drivers::LidarTransport::kUdp
                                               : dockcore::drivers::LidarTransport::kSerial;
  if (c.lidar.protocol == dockcore::drivers::LidarProtocol::kLakibeam &&
      c.lidar.transport == dockcore::drivers::LidarTransport::kSerial) {
    p.fail(lidar_protocol_node != nullptr ? lidar_protocol_node->source() : root.source(),
           "lidar.protocol = \"lakibeam\" needs lidar.transport = \"udp\"");
  }
  if (c.lidar.reconnect_max_ms < c.lidar.reconnect_min_ms) {
    p.fail(p.where("lidar.reconnect_max_ms", root.source()), "lidar.reconnect_max_ms must be >= lidar.reconnect_min_ms");
  }
  if (c.estimator.min_range_m >= c.estimator.max_range_m) p.fail(p.where("lidar.min_range_m", p.where("lidar.max_range_m", root.source())), "lidar.min_range_m must be < lidar.max_range_m");
  c.can.protocol = *dockcore::drivers::parse_chassis_protocol(can_protocol);
  c.drive.kind = drive_kind == "mecanum" ? dockcore::DriveKind::kMecanum : dockcore::DriveKind::kDifferential;
  c.can.drive = c.drive;
  c.pads_rear = pad_side == "rear";
  if (p.given("robot.pad_reach_m")) {
    c.pad_reach_m = static_cast<double>(c.smooth.common.pad_reach_m);
  } else {
    c.pad_reach_m = c.footprint.shape == dockcore::FootprintShape::kCircular
                        ? static_cast<double>(c.footprint.radius_m)
                        : static_cast<double>(c.footprint.half_length_m);
  }
  params::RobotFacts facts;
  facts.pads_rear = c.pads_rear;
  facts.mecanum = c.drive.kind == dockcore::DriveKind::kMecanum;
  facts.charger_switched = dockcore::drivers::switches_charger(c.can.protocol);
  facts.pad_reach_m = c.pad_reach_m;
  params::derive_from_robot(facts, targets);
  if (!c.host_enabled && c.host.allowlist.size() > 0) p.fail(p.where("host.allowlist", root.source()), "host.allowlist given but host.enabled = false");
  if (c.camera_enabled && c.host_enabled && c.camera.port == c.host.port && c.camera.bind_address == c.host.bind_address) {
    p.fail(p.where("camera.port", root.source()), "camera.port must differ from host.port");
  }

  finish_camera_device(p, root.source(), c);  // after [controller]: it sets seed003's camera model
  // The tag's pose comes from dockd's own camera only: a tag on a dock or the fusion's tuning without it would do
  // nothing.
  if (!c.camera_device.enabled) {
    if (!dock_tag_nodes.empty()) {
      p.fail(dock_tag_nodes.front(),
             "docks.tag_id needs [camera.device] (the tag's pose comes from dockd's own camera)");
    }
    if (p.where("camera.fusion", toml::source_region{}).begin.line != 0) {
      p.fail(p.where("camera.fusion", root.source()), "[camera.fusion] needs [camera.device] (dockd's own capture)");
    }
  }

  if (c.docks.empty()) {
    DockEntry d;
    c.docks.push_back(d);
    dock_profile_nodes.push_back(&root);
    dock_detector_nodes.push_back(nullptr);
    dock_mountings.push_back({false, {}});
  }
  std::uint32_t mask = 0;
  for (std::size_t i = 0; i < c.docks.size(); ++i) {
    DockEntry& d = c.docks[i];
    const std::string& ref = d.profile_ref;
    const bool is_file = ref.find('/') != std::string::npos || (ref.size() > 5 && ref.compare(ref.size() - 5, 5, ".toml") == 0);
    if (is_file) {
      const std::string path = (!ref.empty() && ref[0] != '/') ? dir_of(source_name) + ref : ref;
      d.profile = load_profile(p, *dock_profile_nodes[i], path);
    } else if (dockcore::builtin_profile(ref.c_str(), d.profile) != dockcore::ProfileError::kOk) {
      std::string names;
      for (const char* const* n = dockcore::kBuiltinProfileNames; *n != nullptr; ++n) names += (names.empty() ? "" : ", ") + std::string(*n);
      p.fail(dock_profile_nodes[i]->source(), "dock profile \"" + ref + "\" is neither a built-in (" + names +
                                                  ") nor a .toml file");
    }
    if (dock_mountings[i].first) d.profile.mounting = dock_mountings[i].second;
    const dockcore::ConfigureStatus detector_ok = dockcore::detector_supports(d.detector, d.profile);
    if (detector_ok != dockcore::ConfigureStatus::kOk) {
      const toml::node* at = dock_detector_nodes[i] != nullptr ? dock_detector_nodes[i] : dock_profile_nodes[i];
      p.fail(at->source(), std::string("dock ") + std::to_string(d.id) + ": detector = \"" +
                               dockcore::to_string(d.detector) + "\" with profile \"" + d.profile_ref +
                               "\": " + dockcore::to_string(detector_ok));
    }
    mask |= 1u << d.id;
  }
  c.task.accepted_dock_ids = mask;
  if (c.find_dock(c.default_dock_id) == nullptr) {
    p.fail(p.where("dock.default_id", root.source()), "dock.default_id = " + std::to_string(c.default_dock_id) + " is not a configured dock id");
  }
  return c;
}

DockdConfig load_config_file(const std::string& path) {
  std::string text, why;
  if (!read_bounded(path, kMaxConfigBytes, text, why)) throw ConfigError(path + ": config file: " + why);
  return parse_config_toml(text, path);
}

namespace {

// Field-wise equality helpers for restart_only_changes (Real fields compare exactly: both come from the same parser).
bool same(const dockcore::DriveGeometry& a, const dockcore::DriveGeometry& b) {
  return a.kind == b.kind && a.wheel_radius_m == b.wheel_radius_m && a.wheel_base_m == b.wheel_base_m &&
         a.lx_m == b.lx_m && a.ly_m == b.ly_m;
}

}  // namespace

std::vector<std::string> restart_only_changes(const DockdConfig& a, const DockdConfig& b) {
  std::vector<std::string> out;
  auto check = [&out](bool equal, const char* key) {
    if (!equal) out.emplace_back(key);
  };
  // Opened or built once at start: the lidar driver, the CAN socket and link, the UDP sockets, the session record,
  // the state file and the systemd watchdog period.
  check(a.lidar.protocol == b.lidar.protocol, "lidar.protocol");
  check(a.lidar.transport == b.lidar.transport, "lidar.transport");
  check(a.lidar.device == b.lidar.device, "lidar.device");
  check(a.lidar.baud == b.lidar.baud, "lidar.baud");
  check(a.lidar.udp_bind_address == b.lidar.udp_bind_address, "lidar.udp_bind");
  check(a.lidar.udp_port == b.lidar.udp_port, "lidar.udp_port");
  check(a.lidar.udp_source_address == b.lidar.udp_source_address, "lidar.udp_source");
  check(a.lidar.reconnect_min_ms == b.lidar.reconnect_min_ms, "lidar.reconnect_min_ms");
  check(a.lidar.reconnect_max_ms == b.lidar.reconnect_max_ms, "lidar.reconnect_max_ms");
  check(a.can_interface == b.can_interface, "can.interface");
  check(a.can.protocol == b.can.protocol, "can.protocol");
  check(a.can.chassis_base_id == b.can.chassis_base_id, "can.chassis_base_id");
  check(a.can.host_base_id == b.can.host_base_id, "can.host_base_id");
  // The CAN link converts wheel rad/s <-> mm/s with the geometry it was built with.
  check(same(a.drive, b.drive), "robot.drive / wheel_radius_m / track_m / half_wheelbase_m / half_track_m");
  check(a.host_enabled == b.host_enabled, "host.enabled");
  check(a.host.bind_address == b.host.bind_address, "host.bind");
  check(a.host.port == b.host.port, "host.port");
  check(a.host.max_subscribers == b.host.max_subscribers, "host.max_subscribers");
  check(a.host.subscription_ms == b.host.subscription_ms, "host.subscription_ms");
  check(a.camera_enabled == b.camera_enabled, "camera.enabled");
  check(a.camera.bind_address == b.camera.bind_address, "camera.bind");
  check(a.camera.port == b.camera.port, "camera.port");
  check(a.camera.target_id == b.camera.target_id, "camera.target_id");
  check(a.camera.max_age_ms == b.camera.max_age_ms, "camera.max_age_ms");
  camera_device_restart_changes(a.camera_device, b.camera_device, out);
  check(a.record_dir == b.record_dir, "record.dir");
  check(a.record_max_bytes == b.record_max_bytes, "record.max_bytes");
  check(a.record_max_files == b.record_max_files, "record.max_files");
  check(a.record_loop == b.record_loop, "record.loop");
  check(a.systemd_watchdog_divider == b.systemd_watchdog_divider, "watchdog.systemd_divider");
  check(a.state_file == b.state_file, "state.file");
  return out;
}

}  // namespace dockd
