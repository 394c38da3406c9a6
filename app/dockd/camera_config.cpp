#include "camera_config_keys.hpp"

#include <cmath>
#include <sstream>

#include "config.hpp"

namespace dockd {

using dockcore::params::toml_reader::Handlers;
using dockcore::params::toml_reader::kDeg;

void add_camera_device_keys(const ConfigReader& reader, Handlers& h, CameraDeviceConfig& config) {
  // The handlers run later, while parse_config_toml reads the file: they hold pointers to the reader and the config.
  const ConfigReader* pr = &reader;
  CameraDeviceConfig* pc = &config;
  h.emplace_back("device", [pr, pc](const toml::node& n) {
    const ConfigReader& p = *pr;
    CameraDeviceConfig& c = *pc;
    c.enabled = true;
    auto& k = c.capture;
    p.each(p.table(n), "camera.device.",
           Handlers{{"path", p.str(&k.device)},
                    {"format",
                     [&p, &k](const toml::node& v) {
                       k.format = *dockcore::drivers::parse_camera_pixel_format(p.choice(v, {"grey", "yuyv", "mjpeg"}));
                     }},
                    {"width_px", p.integ(&k.width_px, 16, dockcore::drivers::kMaxCameraSidePx)},
                    {"height_px", p.integ(&k.height_px, 16, dockcore::drivers::kMaxCameraSidePx)},
                    {"fps", p.integ(&k.fps, 0, 240)},
                    {"buffers", p.integ(&k.buffers, 2, dockcore::drivers::kMaxV4l2Buffers)},
                    {"late_ms", p.integ(&k.late_ms, 1, 10000)},
                    {"reconnect_min_ms", p.integ(&k.reconnect_min_ms, 10, 60000)},
                    {"reconnect_max_ms", p.integ(&k.reconnect_max_ms, 10, 600000)},
                    {"stall_ms", p.integ(&c.stall_ms, 50, 10000)}});
  });
  h.emplace_back("intrinsics", [pr, pc](const toml::node& n) {
    const ConfigReader& p = *pr;
    CameraDeviceConfig& c = *pc;
    auto& k = c.tag.intrinsics;
    p.each(p.table(n), "camera.intrinsics.",
           Handlers{{"fx_px", [&p, &k](const toml::node& v) { k.fx_px = p.number(v, 1, 20000); }},
                    {"fy_px", [&p, &k](const toml::node& v) { k.fy_px = p.number(v, 1, 20000); }},
                    {"cx_px", [&p, &k](const toml::node& v) { k.cx_px = p.number(v, 0, 20000); }},
                    {"cy_px", [&p, &k](const toml::node& v) { k.cy_px = p.number(v, 0, 20000); }},
                    {"distortion", [&p, &k](const toml::node& v) {
                       // OpenCV's order: [k1, k2, p1, p2] or [k1, k2, p1, p2, k3].
                       const toml::array* a = v.as_array();
                       if (a == nullptr || (a->size() != 4 && a->size() != 5)) {
                         p.fail(v.source(), p.key() + " must be [k1, k2, p1, p2] or [k1, k2, p1, p2, k3]");
                       }
                       double d[5] = {0, 0, 0, 0, 0};
                       for (std::size_t i = 0; i < a->size(); ++i) d[i] = p.number((*a)[i], -100, 100);
                       k.k1 = d[0];
                       k.k2 = d[1];
                       k.p1 = d[2];
                       k.p2 = d[3];
                       k.k3 = d[4];
                     }}});
  });
  h.emplace_back("mount", [pr, pc](const toml::node& n) {
    const ConfigReader& p = *pr;
    CameraDeviceConfig& c = *pc;
    auto& m = c.mount;
    p.each(p.table(n), "camera.mount.",
           Handlers{{"x_m", p.num(&m.x_m, -2, 2)},
                    {"y_m", p.num(&m.y_m, -2, 2)},
                    {"z_m", p.num(&m.z_m, -2, 2)},
                    {"yaw_deg", p.deg(&m.yaw_rad, -180, 180)},
                    {"pitch_deg", p.deg(&m.pitch_rad, -90, 90)},
                    {"roll_deg", p.deg(&m.roll_rad, -180, 180)}});
  });
  h.emplace_back("tag", [pr, pc](const toml::node& n) {
    const ConfigReader& p = *pr;
    CameraDeviceConfig& c = *pc;
    auto& t = c.tag;
    p.each(p.table(n), "camera.tag.",
           Handlers{{"family",
                     [&p, &t](const toml::node& v) {
                       t.family = p.string(v);
                       if (!dockcore::drivers::is_tag_family(t.family)) {
                         std::string names;
                         for (const char* const* f = dockcore::drivers::kTagFamilyNames; *f != nullptr; ++f) {
                           names += (names.empty() ? "" : ", ") + std::string(*f);
                         }
                         p.fail(v.source(), p.key() + " = \"" + t.family + "\" is not a family libapriltag provides (" +
                                                names + ")");
                       }
                     }},
                    {"size_m", [&p, &t](const toml::node& v) { t.tag_size_m = p.number(v, 0.005, 5); }},
                    {"decimate", p.num(&t.quad_decimate, 1, 8)},
                    {"sigma_px", p.num(&t.quad_sigma, 0, 5)},
                    {"threads", p.integ(&t.threads, 1, 16)},
                    {"refine_edges", p.flag(&t.refine_edges)},
                    {"max_hamming", p.integ(&t.max_hamming, 0, 2)},
                    {"min_decision_margin", p.num(&t.min_decision_margin, 0, 1000)},
                    {"full_confidence_margin", p.num(&c.full_confidence_margin, 1, 1000)}});
  });
}

void finish_camera_device(const ConfigReader& p, const toml::source_region& root, DockdConfig& c) {
  CameraDeviceConfig& d = c.camera_device;
  const toml::source_region none{};
  auto given = [&p, &none](const char* key) { return p.where(key, none).begin.line != 0; };
  auto at = [&p, &root](const char* key) { return p.where(key, root); };
  if (!d.enabled) {
    // Intrinsics or a tag without a device would silently do nothing: say so.
    for (const char* k : {"camera.intrinsics", "camera.mount", "camera.tag"}) {
      if (given(k)) p.fail(at(k), std::string("[") + k + "] needs [camera.device] (dockd's own capture)");
    }
    return;
  }
  // Required with a device: what the pose and the controller's model cannot do without.
  for (const char* k : {"camera.intrinsics.fx_px", "camera.intrinsics.fy_px", "camera.intrinsics.cx_px",
                        "camera.intrinsics.cy_px", "camera.tag.size_m"}) {
    if (!given(k)) p.fail(at("camera.device"), std::string(k) + " is required with [camera.device] (docs/camera.md)");
  }
  const auto& k = d.tag.intrinsics;
  const auto& cap = d.capture;
  std::ostringstream s;
  if (k.cx_px >= static_cast<double>(cap.width_px)) {
    s << "camera.intrinsics.cx_px = " << k.cx_px
      << " is not inside the image (camera.device.width_px = " << cap.width_px << ")";
    p.fail(at("camera.intrinsics.cx_px"), s.str());
  }
  if (k.cy_px >= static_cast<double>(cap.height_px)) {
    s << "camera.intrinsics.cy_px = " << k.cy_px
      << " is not inside the image (camera.device.height_px = " << cap.height_px << ")";
    p.fail(at("camera.intrinsics.cy_px"), s.str());
  }
  if (k.fy_px > 2 * k.fx_px || k.fx_px > 2 * k.fy_px) {
    s << "camera.intrinsics.fy_px = " << k.fy_px << " and fx_px = " << k.fx_px
      << " differ by more than a factor 2 (pixels that far from square are a calibration mistake)";
    p.fail(at("camera.intrinsics.fy_px"), s.str());
  }
  if (cap.format == dockcore::drivers::CameraPixelFormat::kYuyv && cap.width_px % 2 != 0) {
    p.fail(at("camera.device.width_px"), "camera.device.width_px must be even for format = \"yuyv\"");
  }
  // A stall is a missing frame, not a slow one: the window must hold at least two frame periods.
  if (cap.fps > 0 && static_cast<std::uint64_t>(d.stall_ms) * cap.fps < 2000u) {
    s << "camera.device.stall_ms = " << d.stall_ms << " is shorter than two frame periods at fps = " << cap.fps
      << " (at least " << (2000u + cap.fps - 1u) / cap.fps << ")";
    p.fail(at("camera.device.stall_ms"), s.str());
  }
  if (cap.reconnect_max_ms < cap.reconnect_min_ms) {
    p.fail(at("camera.device.reconnect_max_ms"), "camera.device.reconnect_max_ms must be >= reconnect_min_ms");
  }
  // seed003's pinhole model (X = (u − cx)·Z / fx) is this camera: taken from it. A controller key that says
  // otherwise is a contradiction, not an override.
  dockcore::CameraModel& m = c.seed003.camera;
  struct Pair {
    const char* key;
    double controller, camera;
    const char* camera_key;
  };
  const Pair pairs[] = {
      {"controller.seed003.fx_px", static_cast<double>(m.fx_px), k.fx_px, "camera.intrinsics.fx_px"},
      {"controller.seed003.cx_px", static_cast<double>(m.cx_px), k.cx_px, "camera.intrinsics.cx_px"},
      {"controller.seed003.image_width_px", static_cast<double>(m.image_width_px), static_cast<double>(cap.width_px),
       "camera.device.width_px"},
      {"controller.seed003.mount_x_m", static_cast<double>(m.mount.x_m), d.mount.x_m, "camera.mount.x_m"},
      {"controller.seed003.mount_y_m", static_cast<double>(m.mount.y_m), d.mount.y_m, "camera.mount.y_m"},
      {"controller.seed003.mount_yaw_deg", static_cast<double>(m.mount.yaw_rad) / kDeg, d.mount.yaw_rad / kDeg,
       "camera.mount.yaw_deg"},
  };
  for (const Pair& q : pairs) {
    if (given(q.key) && std::fabs(q.controller - q.camera) > 1e-6 * std::fmax(1.0, std::fabs(q.camera))) {
      s << q.key << " = " << q.controller << " contradicts " << q.camera_key << " = " << q.camera
        << " (with [camera.device] the controller uses the camera's values: remove the controller key)";
      p.fail(at(q.key), s.str());
    }
  }
  m.fx_px = static_cast<dockcore::Real>(k.fx_px);
  m.cx_px = static_cast<dockcore::Real>(k.cx_px);
  m.image_width_px = static_cast<dockcore::Real>(cap.width_px);
  m.mount = dockcore::Pose2{static_cast<dockcore::Real>(d.mount.x_m), static_cast<dockcore::Real>(d.mount.y_m),
                            static_cast<dockcore::Real>(d.mount.yaw_rad)};
}

void camera_device_restart_changes(const CameraDeviceConfig& a, const CameraDeviceConfig& b,
                                   std::vector<std::string>& out) {
  auto check = [&out](bool equal, const char* key) {
    if (!equal) out.emplace_back(key);
  };
  const auto& ca = a.capture;
  const auto& cb = b.capture;
  check(a.enabled == b.enabled, "camera.device");
  check(ca.device == cb.device && ca.format == cb.format && ca.width_px == cb.width_px &&
            ca.height_px == cb.height_px && ca.fps == cb.fps && ca.buffers == cb.buffers && ca.late_ms == cb.late_ms &&
            ca.reconnect_min_ms == cb.reconnect_min_ms && ca.reconnect_max_ms == cb.reconnect_max_ms &&
            a.stall_ms == b.stall_ms,
        "camera.device.*");
  const auto& ka = a.tag.intrinsics;
  const auto& kb = b.tag.intrinsics;
  check(ka.fx_px == kb.fx_px && ka.fy_px == kb.fy_px && ka.cx_px == kb.cx_px && ka.cy_px == kb.cy_px &&
            ka.k1 == kb.k1 && ka.k2 == kb.k2 && ka.p1 == kb.p1 && ka.p2 == kb.p2 && ka.k3 == kb.k3,
        "camera.intrinsics.*");
  check(a.mount.x_m == b.mount.x_m && a.mount.y_m == b.mount.y_m && a.mount.z_m == b.mount.z_m &&
            a.mount.yaw_rad == b.mount.yaw_rad && a.mount.pitch_rad == b.mount.pitch_rad &&
            a.mount.roll_rad == b.mount.roll_rad,
        "camera.mount.*");
  const auto& ta = a.tag;
  const auto& tb = b.tag;
  check(ta.family == tb.family && ta.tag_size_m == tb.tag_size_m && ta.quad_decimate == tb.quad_decimate &&
            ta.quad_sigma == tb.quad_sigma && ta.threads == tb.threads && ta.refine_edges == tb.refine_edges &&
            ta.max_hamming == tb.max_hamming && ta.min_decision_margin == tb.min_decision_margin &&
            a.full_confidence_margin == b.full_confidence_margin,
        "camera.tag.*");
}

}  // namespace dockd
