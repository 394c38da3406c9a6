// camera-check calib (see calib.hpp).
#include "calib.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "dockcore/drivers/jpeg_grey.hpp"

namespace camera_check {

using dockcore::drivers::CameraIntrinsics;
using dockcore::drivers::TagDetection;
using dockcore::drivers::TagDetector;
using dockcore::drivers::TagDetectorOptions;

namespace {

void mean_std(const std::vector<double>& v, double& mean, double& std_dev) {
  mean = 0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  double ss = 0;
  for (double x : v) ss += (x - mean) * (x - mean);
  std_dev = v.size() > 1 ? std::sqrt(ss / static_cast<double>(v.size() - 1)) : 0.0;
}

/// The option checks shared by images and device; false (message printed) when calib cannot run.
bool usable(const CalibOptions& o, const TagDetectorOptions& det) {
  if (!(o.distance_m > 0) || !std::isfinite(o.lateral_m) || o.frames == 0 || !(o.tolerance > 0)) {
    std::fprintf(stderr, "camera-check calib: --distance and --frames must be > 0\n");
    return false;
  }
  if (!(det.intrinsics.fx_px > 0) || !(det.tag_size_m > 0)) {
    std::fprintf(stderr,
                 "camera-check calib: the calibration to check needs --fx (and --fy, --cx, --cy) and --tag-size\n");
    return false;
  }
  return true;
}

/// The tag to use in one frame's detections (sorted by decision margin): `tag_id`, or the strongest; with a pose.
const TagDetection* pick(const TagDetection* d, std::size_t n, int tag_id) {
  for (std::size_t i = 0; i < n; ++i) {
    if ((tag_id < 0 || d[i].id == tag_id) && d[i].has_pose) return &d[i];
  }
  return nullptr;
}

/// The detector for `det`, or nullptr after printing why.
std::unique_ptr<TagDetector> make_detector(const TagDetectorOptions& det) {
  std::string err;
  std::unique_ptr<TagDetector> detector = TagDetector::create(det, err);
  if (!detector) std::fprintf(stderr, "camera-check calib: %s\n", err.c_str());
  return detector;
}

void print_frame(const char* source, const TagDetection& t) {
  std::printf(
      "{\"type\":\"calib_frame\",\"source\":\"%s\",\"id\":%d,\"u_px\":%.2f,\"x_m\":%.4f,\"z_m\":%.4f,"
      "\"decision_margin\":%.1f}\n",
      source, t.id, t.u_px, t.translation_m[0], t.translation_m[2], t.decision_margin);
}

int finish(const std::vector<CalibSample>& samples, const CalibOptions& o, const CameraIntrinsics& k,
           CalibReport* report) {
  if (samples.empty()) {
    std::fprintf(stderr, "camera-check calib: no frame held the tag%s\n", o.tag_id >= 0 ? " (--tag-id)" : "");
    return kCalibNoTag;
  }
  const CalibReport r = calib_report(samples, o, k);
  print_calib_report(r, o, k);
  if (report != nullptr) *report = r;
  return r.ok() ? kCalibOk : kCalibOff;
}

}  // namespace

CalibReport calib_report(const std::vector<CalibSample>& samples, const CalibOptions& o, const CameraIntrinsics& k) {
  CalibReport r;
  std::vector<double> z, x;
  for (const CalibSample& s : samples) {
    z.push_back(s.z_m);
    x.push_back(s.x_m);
  }
  r.frames = static_cast<std::uint32_t>(samples.size());
  mean_std(z, r.z_mean_m, r.z_std_m);
  mean_std(x, r.x_mean_m, r.x_std_m);
  // Depth scales with the focal length (and with the tag size): z = f·s / (apparent side).
  r.focal_factor = o.distance_m / r.z_mean_m;
  // x = (u − cx)·z / fx. A principal point off by δ shifts x by δ·z/fx wherever the tag is; the tag's true x is the
  // measured lateral. (A camera turned on its mount shifts x the same way: measure with the axis square to the tag.)
  r.cx_offset_px = k.fx_px * (r.x_mean_m - o.lateral_m) / r.z_mean_m;
  r.depth_ok = std::fabs(r.z_mean_m - o.distance_m) <= o.tolerance * o.distance_m;
  r.lateral_ok = std::fabs(r.x_mean_m - o.lateral_m) <= o.tolerance * o.distance_m;
  return r;
}

void print_calib_report(const CalibReport& r, const CalibOptions& o, const CameraIntrinsics& k) {
  std::string fix;
  char buf[256];
  if (!r.depth_ok) {
    std::snprintf(buf, sizeof buf,
                  "depth %.1f %% off: multiply fx_px and fy_px by %.4f (%.1f, %.1f), or check camera.tag.size_m "
                  "(black square side) and the measured distance",
                  100 * (r.z_mean_m / o.distance_m - 1), r.focal_factor, k.fx_px * r.focal_factor,
                  k.fy_px * r.focal_factor);
    fix += buf;
  }
  if (!r.lateral_ok) {
    std::snprintf(buf, sizeof buf,
                  "%slateral %.1f mm off: add %.1f px to cx_px (%.1f), or check that the camera looks square at the "
                  "tag",
                  fix.empty() ? "" : "; ", 1000 * (r.x_mean_m - o.lateral_m), r.cx_offset_px, k.cx_px + r.cx_offset_px);
    fix += buf;
  }
  std::printf(
      "{\"type\":\"calib\",\"frames\":%u,\"distance_m\":%.4f,\"lateral_m\":%.4f,\"z_mean_m\":%.4f,\"z_std_m\":%.4f,"
      "\"x_mean_m\":%.4f,\"x_std_m\":%.4f,\"focal_factor\":%.4f,\"fx_px_suggested\":%.1f,\"fy_px_suggested\":%.1f,"
      "\"cx_offset_px\":%.2f,\"cx_px_suggested\":%.1f,\"tolerance\":%.3f,\"verdict\":\"%s\",\"fix\":\"%s\"}\n",
      r.frames, o.distance_m, o.lateral_m, r.z_mean_m, r.z_std_m, r.x_mean_m, r.x_std_m, r.focal_factor,
      k.fx_px * r.focal_factor, k.fy_px * r.focal_factor, r.cx_offset_px, k.cx_px + r.cx_offset_px, o.tolerance,
      r.ok() ? "ok" : "off", fix.c_str());
  std::fflush(stdout);
}

int run_calib_images(const std::vector<std::string>& images, const CalibOptions& o, const TagDetectorOptions& det,
                     CalibReport* report) {
  if (!usable(o, det)) return kCalibUsage;
  std::string err;
  std::unique_ptr<TagDetector> detector = make_detector(det);
  if (!detector) return kCalibUsage;
  std::vector<CalibSample> samples;
  for (const std::string& path : images) {
    dockcore::drivers::GreyImage img;
    if (!dockcore::drivers::read_jpeg_grey(path, img, err)) {
      std::fprintf(stderr, "camera-check calib: %s\n", err.c_str());
      return kCalibUsage;
    }
    TagDetection d[dockcore::drivers::kMaxTagDetections];
    const std::size_t n = detector->detect(img.pixels.data(), img.width_px, img.height_px, img.width_px, d,
                                           dockcore::drivers::kMaxTagDetections);
    const TagDetection* t = pick(d, n, o.tag_id);
    if (t == nullptr) {
      std::fprintf(stderr, "camera-check calib: %s: no tag%s\n", path.c_str(), o.tag_id >= 0 ? " with --tag-id" : "");
      continue;
    }
    print_frame(path.c_str(), *t);
    samples.push_back({t->translation_m[0], t->translation_m[2]});
  }
  return finish(samples, o, det.intrinsics, report);
}

int run_calib_device(const dockcore::drivers::V4l2CameraOptions& cam_opt, const CalibOptions& o,
                     const TagDetectorOptions& det) {
  if (!usable(o, det)) return kCalibUsage;
  std::string err;
  std::unique_ptr<TagDetector> detector = make_detector(det);
  if (!detector) return kCalibUsage;
  auto cam = dockcore::drivers::open_v4l2_camera(cam_opt, err);
  if (!cam) {
    std::fprintf(stderr, "camera-check calib: %s\n", err.c_str());
    return kCalibDevice;
  }
  std::vector<CalibSample> samples;
  auto last_tag = std::chrono::steady_clock::now();
  bool any_frame = false;
  while (samples.size() < o.frames) {
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - last_tag).count() > o.give_up_s) {
      if (!any_frame) {
        std::fprintf(stderr, "camera-check calib: no frame for %.1f s (%s)\n", o.give_up_s, cam->last_error());
        return kCalibDevice;
      }
      break;  // frames, but too few with the tag: judge those (or report none)
    }
    dockcore::hal::CameraFrame f;
    if (cam->next_frame(f, 100) != dockcore::hal::CameraFrameStatus::kFrame) continue;
    any_frame = true;
    TagDetection d[dockcore::drivers::kMaxTagDetections];
    const std::size_t n =
        detector->detect(f.grey, f.width_px, f.height_px, f.stride_bytes, d, dockcore::drivers::kMaxTagDetections);
    const TagDetection* t = pick(d, n, o.tag_id);
    if (t == nullptr) continue;
    last_tag = std::chrono::steady_clock::now();
    print_frame(cam_opt.device.c_str(), *t);
    samples.push_back({t->translation_m[0], t->translation_m[2]});
  }
  return finish(samples, o, det.intrinsics, nullptr);
}

}  // namespace camera_check
