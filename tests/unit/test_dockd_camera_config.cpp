// dockd's own camera in the config ([camera.device], [camera.intrinsics], [camera.mount], [camera.tag];
// docs/camera.md): values and defaults, seed003's camera model taken from the camera, and every missing or
// inconsistent key reported at file:line:column naming the key.
#include <algorithm>
#include <string>
#include <vector>

#include "config.hpp"

#include "CppUTest/TestHarness.h"

namespace {

std::string error_of(const std::string& text) {
  try {
    dockd::parse_config_toml(text, "t.toml");
  } catch (const dockd::ConfigError& e) {
    return e.what();
  }
  return "";
}

const char* const kCamera =
    "[camera]\ntarget_id = 3\n"
    "[camera.device]\npath = \"/dev/video2\"\nformat = \"yuyv\"\nwidth_px = 640\nheight_px = 480\nfps = 30\n"
    "[camera.intrinsics]\nfx_px = 610.5\nfy_px = 612\ncx_px = 318\ncy_px = 241\ndistortion = [-0.1, 0.02, 0.001, "
    "-0.002]\n"
    "[camera.mount]\nx_m = 0.2\ny_m = -0.01\nz_m = 0.15\nyaw_deg = 2\npitch_deg = 10\n"
    "[camera.tag]\nfamily = \"tag36h11\"\nsize_m = 0.08\n";

}  // namespace

TEST_GROUP(DockdCameraConfig){};

TEST(DockdCameraConfig, NoDeviceByDefault) {
  const dockd::DockdConfig c = dockd::parse_config_toml("", "t.toml");
  CHECK_FALSE(c.camera_device.enabled);
  STRCMP_EQUAL("tag36h11", c.camera_device.tag.family.c_str());
}

TEST(DockdCameraConfig, ValuesArrive) {
  const dockd::DockdConfig c = dockd::parse_config_toml(kCamera, "t.toml");
  const dockd::CameraDeviceConfig& d = c.camera_device;
  CHECK_TRUE(d.enabled);
  STRCMP_EQUAL("/dev/video2", d.capture.device.c_str());
  CHECK(d.capture.format == dockcore::drivers::CameraPixelFormat::kYuyv);
  std::string mjpeg = kCamera;
  mjpeg.replace(mjpeg.find("\"yuyv\""), 6, "\"mjpeg\"");
  CHECK(dockd::parse_config_toml(mjpeg, "t.toml").camera_device.capture.format ==
        dockcore::drivers::CameraPixelFormat::kMjpeg);
  CHECK_EQUAL(640u, d.capture.width_px);
  CHECK_EQUAL(30u, d.capture.fps);
  CHECK_EQUAL(200u, d.stall_ms);  // default
  DOUBLES_EQUAL(610.5, d.tag.intrinsics.fx_px, 0);
  DOUBLES_EQUAL(241, d.tag.intrinsics.cy_px, 0);
  DOUBLES_EQUAL(-0.1, d.tag.intrinsics.k1, 0);
  DOUBLES_EQUAL(-0.002, d.tag.intrinsics.p2, 0);
  DOUBLES_EQUAL(0, d.tag.intrinsics.k3, 0);
  DOUBLES_EQUAL(0.08, d.tag.tag_size_m, 0);
  DOUBLES_EQUAL(0.15, d.mount.z_m, 0);
  DOUBLES_EQUAL(10 * 3.14159265358979 / 180, d.mount.pitch_rad, 1e-9);
  // The seed003 controller's pinhole model is this camera's.
  DOUBLES_EQUAL(610.5, static_cast<double>(c.seed003.camera.fx_px), 1e-9);
  DOUBLES_EQUAL(318, static_cast<double>(c.seed003.camera.cx_px), 1e-9);
  DOUBLES_EQUAL(640, static_cast<double>(c.seed003.camera.image_width_px), 1e-9);
  DOUBLES_EQUAL(0.2, static_cast<double>(c.seed003.camera.mount.x_m), 1e-6);
  DOUBLES_EQUAL(2 * 3.14159265358979 / 180, static_cast<double>(c.seed003.camera.mount.yaw_rad), 1e-6);
}

TEST(DockdCameraConfig, MissingRequiredKeysAreNamed) {
  STRCMP_CONTAINS("t.toml:1:1: camera.intrinsics.fx_px is required with [camera.device]",
                  error_of("[camera.device]\npath = \"/dev/video0\"\n").c_str());
  STRCMP_CONTAINS(
      "camera.tag.size_m is required with [camera.device]",
      error_of("[camera.device]\n[camera.intrinsics]\nfx_px = 600\nfy_px = 600\ncx_px = 320\ncy_px = 240\n").c_str());
  STRCMP_CONTAINS(
      "camera.intrinsics.cy_px is required",
      error_of(
          "[camera.device]\n[camera.intrinsics]\nfx_px = 600\nfy_px = 600\ncx_px = 320\n[camera.tag]\nsize_m = 0.1\n")
          .c_str());
}

TEST(DockdCameraConfig, InconsistentKeysAreNamed) {
  const std::string base =
      "[camera.device]\nwidth_px = 640\nheight_px = 480\n[camera.tag]\nsize_m = 0.1\n[camera.intrinsics]\n";
  STRCMP_CONTAINS("t.toml:9:9: camera.intrinsics.cx_px = 700 is not inside the image (camera.device.width_px = 640)",
                  error_of(base + "fx_px = 600\nfy_px = 600\ncx_px = 700\ncy_px = 240\n").c_str());
  STRCMP_CONTAINS("camera.intrinsics.cy_px = 480 is not inside the image",
                  error_of(base + "fx_px = 600\nfy_px = 600\ncx_px = 320\ncy_px = 480\n").c_str());
  STRCMP_CONTAINS("camera.intrinsics.fy_px = 1500 and fx_px = 600 differ by more than a factor 2",
                  error_of(base + "fx_px = 600\nfy_px = 1500\ncx_px = 320\ncy_px = 240\n").c_str());
  STRCMP_CONTAINS("camera.intrinsics.distortion must be [k1, k2, p1, p2] or [k1, k2, p1, p2, k3]",
                  error_of(base + "fx_px = 600\nfy_px = 600\ncx_px = 320\ncy_px = 240\ndistortion = [0.1]\n").c_str());
  STRCMP_CONTAINS("camera.device.width_px must be even for format = \"yuyv\"",
                  error_of("[camera.device]\nformat = \"yuyv\"\nwidth_px = 641\n[camera.tag]\nsize_m = 0.1\n"
                           "[camera.intrinsics]\nfx_px = 600\nfy_px = 600\ncx_px = 320\ncy_px = 240\n")
                      .c_str());
  STRCMP_CONTAINS(
      "camera.device.reconnect_max_ms must be >= reconnect_min_ms",
      error_of("[camera.device]\nreconnect_min_ms = 500\nreconnect_max_ms = 100\n[camera.tag]\nsize_m = 0.1\n"
               "[camera.intrinsics]\nfx_px = 600\nfy_px = 600\ncx_px = 320\ncy_px = 240\n")
          .c_str());
  // seed003's camera keys may repeat the camera's values but not contradict them.
  STRCMP_CONTAINS("controller.seed003.fx_px = 500 contradicts camera.intrinsics.fx_px = 610.5",
                  error_of(std::string("[controller.seed003]\nfx_px = 500\n") + kCamera).c_str());
  STRCMP_EQUAL("", error_of(std::string("[controller.seed003]\nfx_px = 610.5\n") + kCamera).c_str());
}

TEST(DockdCameraConfig, BadValuesAreNamed) {
  STRCMP_CONTAINS("camera.tag.family = \"tag37h11\" is not a family libapriltag provides (tag16h5",
                  error_of("[camera.tag]\nfamily = \"tag37h11\"\n").c_str());
  STRCMP_CONTAINS("camera.device.format = \"mjpg\" is not one of grey, yuyv, mjpeg",
                  error_of("[camera.device]\nformat = \"mjpg\"\n").c_str());
  STRCMP_CONTAINS("camera.device.stall_ms = 20 is out of range", error_of("[camera.device]\nstall_ms = 20\n").c_str());
  // At 10 frames/s a 150 ms window would call every frame gap a stall.
  std::string slow = kCamera;
  slow.replace(slow.find("fps = 30"), 8, "fps = 10\nstall_ms = 150");
  STRCMP_CONTAINS("camera.device.stall_ms = 150 is shorter than two frame periods at fps = 10 (at least 200)",
                  error_of(slow).c_str());
  slow.replace(slow.find("stall_ms = 150"), 14, "stall_ms = 200");
  STRCMP_EQUAL("", error_of(slow).c_str());
  CHECK_EQUAL(200u, dockd::parse_config_toml(slow, "t.toml").camera_device.stall_ms);
  STRCMP_CONTAINS("unknown key 'camera.intrinsics.f_px'", error_of("[camera.intrinsics]\nf_px = 1\n").c_str());
  STRCMP_CONTAINS("camera.intrinsics.fx_px = 0 is out of range", error_of("[camera.intrinsics]\nfx_px = 0\n").c_str());
  // Intrinsics without a device would do nothing: refused.
  STRCMP_CONTAINS("[camera.intrinsics] needs [camera.device]", error_of("[camera.intrinsics]\nfx_px = 600\n").c_str());
}

TEST(DockdCameraConfig, EveryCameraKeyIsRestartOnly) {
  const dockd::DockdConfig a = dockd::parse_config_toml(kCamera, "t.toml");
  std::string text = kCamera;
  text.replace(text.find("size_m = 0.08"), 13, "size_m = 0.09");
  text.replace(text.find("fps = 30"), 8, "fps = 15");
  const dockd::DockdConfig b = dockd::parse_config_toml(text, "t.toml");
  const std::vector<std::string> changed = dockd::restart_only_changes(a, b);
  CHECK_EQUAL(2u, changed.size());
  STRCMP_EQUAL("camera.device.*", changed[0].c_str());
  STRCMP_EQUAL("camera.tag.*", changed[1].c_str());
  std::string stall = kCamera;
  stall.replace(stall.find("fps = 30"), 8, "fps = 30\nstall_ms = 300");
  const std::vector<std::string> stall_changed =
      dockd::restart_only_changes(a, dockd::parse_config_toml(stall, "t.toml"));
  CHECK_EQUAL(1u, stall_changed.size());
  STRCMP_EQUAL("camera.device.*", stall_changed[0].c_str());
}

TEST(DockdCameraConfig, TagFusionKeysArrive) {
  const std::string text = std::string(kCamera) +
                           "[camera.fusion]\nsigma_px = 0.5\nmax_lag_s = 0.03\n[dock]\ndefault_id = 1\n"
                           "[[docks]]\nid = 1\ntag_id = 7\ntag_y_m = 0.05\ntag_z_m = 0.2\ntag_yaw_deg = 3\n"
                           "[[docks]]\nid = 2\n";
  const dockd::DockdConfig c = dockd::parse_config_toml(text, "t.toml");
  const double tol = 1e-6;  // the values are Real: float in the float build
  DOUBLES_EQUAL(0.5, static_cast<double>(c.tag_fusion.sigma_px), tol);
  DOUBLES_EQUAL(0.03, static_cast<double>(c.tag_fusion.max_lag_s), tol);
  DOUBLES_EQUAL(1, static_cast<double>(c.tag_fusion.sigma_scale), 0);  // the struct's default
  const dockd::DockEntry* d1 = c.find_dock(1);
  const dockd::DockEntry* d2 = c.find_dock(2);
  CHECK(d1 != nullptr && d2 != nullptr);
  LONGS_EQUAL(7, d1->tag.id);
  DOUBLES_EQUAL(0.05, static_cast<double>(d1->tag.y_m), tol);
  DOUBLES_EQUAL(0.2, static_cast<double>(d1->tag.z_m), tol);
  DOUBLES_EQUAL(3 * 3.14159265358979 / 180, static_cast<double>(d1->tag.yaw_rad), 1e-6);
  LONGS_EQUAL(-1, d2->tag.id);  // no tag on dock 2
}

TEST(DockdCameraConfig, TagFusionMistakesAreNamedAtTheirLine) {
  STRCMP_CONTAINS("t.toml:3:11: docks.tag_x_m / tag_y_m / tag_z_m / tag_yaw_deg need docks.tag_id",
                  error_of(std::string("[[docks]]\nid = 1\ntag_y_m = 0.05\n")).c_str());
  STRCMP_CONTAINS("t.toml:3:10: docks.tag_id needs [camera.device]",
                  error_of(std::string("[[docks]]\nid = 1\ntag_id = 4\n")).c_str());
  STRCMP_CONTAINS("[camera.fusion] needs [camera.device]", error_of("[camera.fusion]\nsigma_px = 0.4\n").c_str());
  const std::string cam(kCamera);
  const int lines = static_cast<int>(std::count(cam.begin(), cam.end(), '\n'));
  STRCMP_CONTAINS(("t.toml:" + std::to_string(lines + 2) + ":12: camera.fusion.sigma_px = 0 is out of range").c_str(),
                  error_of(cam + "[camera.fusion]\nsigma_px = 0\n").c_str());
  STRCMP_CONTAINS("unknown key 'camera.fusion.sigma'", error_of(cam + "[camera.fusion]\nsigma = 1\n").c_str());
  STRCMP_CONTAINS("docks.tag_z_m = 3 is out of range", error_of(cam + "[[docks]]\ntag_id = 1\ntag_z_m = 3\n").c_str());
  STRCMP_CONTAINS("docks.tag_id = -1 is out of range", error_of(cam + "[[docks]]\ntag_id = -1\n").c_str());
}
