// camera-check calib on frames rendered by the simulator's pinhole renderer (docsim/tag_render.hpp): a 150 mm
// tag36h11 tag facing a 640×480 camera with f = 600 px and the principal point at the image centre, at a known
// distance and lateral offset, with pixel noise, written as JPEG files. Checked with deliberately wrong intrinsics,
// the tool must report the focal-length correction factor within 0.5 % and the principal point's offset within 1 px;
// with the right ones it must say ok.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "calib.hpp"
#include "docksim/rendered_camera.hpp"
#include "docksim/rng.hpp"
#include "docksim/tag_render.hpp"
#include "jpeg_encode.hpp"
#include "tag_pose.hpp"

#include <CppUTest/TestHarness.h>

namespace {

constexpr double kTrueF = 600, kTrueCx = 319.5, kTrueCy = 239.5, kTagSize = 0.15;

struct Frames {
  std::vector<std::string> paths;
  ~Frames() {
    for (const std::string& p : paths) std::remove(p.c_str());
  }
};

/// `n` frames of the tag (id 3) at (lateral, 0, distance) in the camera frame, facing it, with Gaussian noise.
void render(Frames& out, double distance_m, double lateral_m, int n) {
  docksim::TagPatternImage tag;
  std::string err;
  CHECK_TRUE(docksim::make_tag_pattern("tag36h11", 3, kTagSize, tag, err));
  const docksim::TagPattern& pattern = tag.pattern;
  docksim::PinholeView view;
  view.fx_px = view.fy_px = kTrueF;
  view.cx_px = kTrueCx;
  view.cy_px = kTrueCy;
  view.translation_m[0] = lateral_m;
  view.translation_m[2] = distance_m;
  docksim::Rng rng(11);
  std::vector<std::uint8_t> img(static_cast<std::size_t>(view.width_px) * view.height_px);
  for (int i = 0; i < n; ++i) {
    view.background = static_cast<std::uint8_t>(110 + 10 * i);
    CHECK_TRUE(docksim::render_tag(pattern, view, img.data(), view.width_px));
    for (std::uint8_t& px : img) {
      px = static_cast<std::uint8_t>(std::clamp(std::lround(px + rng.normal() * 3.0), 0L, 255L));
    }
    const std::string path =
        "/tmp/camera_calib_" + std::to_string(::getpid()) + "_" + std::to_string(out.paths.size()) + ".jpg";
    CHECK_TRUE(camera_test::write_file(path, camera_test::encode_jpeg(img, 1, view.width_px, view.height_px, 92)));
    out.paths.push_back(path);
  }
}

dockcore::drivers::TagDetectorOptions config(double fx_px, double cx_px) {
  dockcore::drivers::TagDetectorOptions det;
  det.tag_size_m = kTagSize;
  det.intrinsics = dockcore::drivers::CameraIntrinsics{fx_px, fx_px, cx_px, kTrueCy};
  return det;
}

}  // namespace

TEST_GROUP(CameraCalib){};

TEST(CameraCalib, AWrongFocalLengthIsReportedWithItsCorrectionFactor) {
  Frames f;
  render(f, 1.0, 0.0, 6);
  camera_check::CalibOptions o;
  o.distance_m = 1.0;
  camera_check::CalibReport r;
  CHECK_EQUAL(camera_check::kCalibOff, camera_check::run_calib_images(f.paths, o, config(630, kTrueCx), &r));
  CHECK_EQUAL(6u, r.frames);
  CHECK_FALSE(r.depth_ok);
  CHECK_TRUE(r.lateral_ok);
  const double want = kTrueF / 630;
  CHECK_TEXT(std::fabs(r.focal_factor / want - 1) <= 0.005, std::to_string(r.focal_factor).c_str());
  CHECK_TEXT(std::fabs(r.cx_offset_px) <= 1.0, std::to_string(r.cx_offset_px).c_str());
  // Too short a focal length the other way round.
  CHECK_EQUAL(camera_check::kCalibOff, camera_check::run_calib_images(f.paths, o, config(570, kTrueCx), &r));
  CHECK_TEXT(std::fabs(r.focal_factor / (kTrueF / 570) - 1) <= 0.005, std::to_string(r.focal_factor).c_str());
}

TEST(CameraCalib, APrincipalPointOffIsReportedInPixelsAlsoBesideTheAxis) {
  Frames f;
  render(f, 1.2, 0.25, 6);
  camera_check::CalibOptions o;
  o.distance_m = 1.2;
  o.lateral_m = 0.25;
  camera_check::CalibReport r;
  // cx 12 px too far right and fx 4 % too long: both reported.
  CHECK_EQUAL(camera_check::kCalibOff, camera_check::run_calib_images(f.paths, o, config(624, kTrueCx + 12), &r));
  CHECK_FALSE(r.lateral_ok);
  CHECK_TEXT(std::fabs(r.cx_offset_px - -12) <= 1.0, std::to_string(r.cx_offset_px).c_str());
  CHECK_TEXT(std::fabs(r.focal_factor / (kTrueF / 624) - 1) <= 0.005, std::to_string(r.focal_factor).c_str());
}

TEST(CameraCalib, TheRightCalibrationIsOk) {
  Frames f;
  render(f, 1.0, 0.1, 4);
  camera_check::CalibOptions o;
  o.distance_m = 1.0;
  o.lateral_m = 0.1;
  camera_check::CalibReport r;
  CHECK_EQUAL(camera_check::kCalibOk, camera_check::run_calib_images(f.paths, o, config(kTrueF, kTrueCx), &r));
  CHECK_TEXT(std::fabs(r.focal_factor - 1) <= 0.005, std::to_string(r.focal_factor).c_str());
  CHECK_TEXT(std::fabs(r.cx_offset_px) <= 1.0, std::to_string(r.cx_offset_px).c_str());
  CHECK(r.z_std_m < 0.005);
}

TEST(CameraCalib, NoTagNoCalibrationOrNoDistanceAreTheirOwnExits) {
  Frames f;
  render(f, 30.0, 0.0, 1);  // a tag of a pixel or two: not found
  camera_check::CalibOptions o;
  o.distance_m = 30.0;
  CHECK_EQUAL(camera_check::kCalibNoTag, camera_check::run_calib_images(f.paths, o, config(kTrueF, kTrueCx)));
  o.distance_m = 0;
  CHECK_EQUAL(camera_check::kCalibUsage, camera_check::run_calib_images(f.paths, o, config(kTrueF, kTrueCx)));
  o.distance_m = 1.0;
  CHECK_EQUAL(camera_check::kCalibUsage, camera_check::run_calib_images(f.paths, o, config(0, kTrueCx)));
  CHECK_EQUAL(camera_check::kCalibUsage,
              camera_check::run_calib_images({"/nonexistent/frame.jpg"}, o, config(kTrueF, kTrueCx)));
}
