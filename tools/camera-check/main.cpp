// camera-check: the camera driver and the AprilTag detector outside dockd (docs/camera.md).
//   camera-check capture --device /dev/video0 --frames 100          frames from a V4L2 device, stamps and counters
//   camera-check capture --detect --fx 600 --tag-size 0.1 ...        the same, with the tags of every frame (pose)
//   camera-check detect --image photo.jpg --fx 600 ...               tags in one image, with pose
//   camera-check bench --image photo.jpg --frames 200                detection time per 640×480 grey frame
//   camera-check tag-pose --frames 300 --distance 1.0                 dock pose from a tag on rendered frames
//   camera-check calib --distance 1.0 --fx 610 ... --image a.jpg      a calibration against a tag at a known distance
// Output is JSON, one object per line. Exit status: 0 ok, 1 the check failed (capture: no frame, stamps not
// increasing, --expect-reconnect without a loss and reopen; detect: no tag; calib: off by more than the tolerance),
// 2 usage or option error, 3 the device could not be used (refused, or no frame for --give-up-seconds), 4 calib: no
// frame held the tag.
#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "calib.hpp"
#include "dockcore/drivers/apriltag_detector.hpp"
#include "dockcore/drivers/jpeg_grey.hpp"
#include "dockcore/drivers/v4l2_camera.hpp"
#include "tag_pose.hpp"

using namespace dockcore::drivers;

namespace {

std::uint64_t mono_us() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000u + static_cast<std::uint64_t>(ts.tv_nsec) / 1000u;
}

std::string json_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    o += c;
  }
  return o;
}

/// "Name=value": sets the device control whose name is Name (VIDIOC_QUERYCTRL enumeration, then VIDIOC_S_CTRL) on a
/// second descriptor of the device. For the HIL case's error injection (vivid's "Percentage of Dropped Buffers").
bool set_control(const std::string& device, const std::string& spec, std::string& err) {
  const std::size_t eq = spec.rfind('=');
  if (eq == std::string::npos) {
    err = "--control '" + spec + "' is not Name=value";
    return false;
  }
  const std::string name = spec.substr(0, eq);
  long value = 0;
  try {
    value = std::stol(spec.substr(eq + 1));
  } catch (...) {
    err = "--control '" + spec + "': value is not an integer";
    return false;
  }
  const int fd = ::open(device.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) {
    err = "camera " + device + ": open: " + std::strerror(errno);
    return false;
  }
  v4l2_queryctrl q{};
  q.id = V4L2_CTRL_FLAG_NEXT_CTRL;
  bool found = false;
  while (::ioctl(fd, VIDIOC_QUERYCTRL, &q) == 0) {
    if (name == reinterpret_cast<const char*>(q.name)) {
      found = true;
      break;
    }
    q.id |= V4L2_CTRL_FLAG_NEXT_CTRL;
  }
  if (!found) {
    err = "camera " + device + ": no control named '" + name + "' (VIDIOC_QUERYCTRL)";
    ::close(fd);
    return false;
  }
  v4l2_control c{};
  c.id = q.id;
  c.value = static_cast<std::int32_t>(value);
  const bool ok = ::ioctl(fd, VIDIOC_S_CTRL, &c) == 0;
  if (!ok) err = "camera " + device + ": VIDIOC_S_CTRL '" + name + "': " + std::strerror(errno);
  ::close(fd);
  return ok;
}

void print_counters(const char* type, const V4l2Camera& cam, std::uint64_t backsteps, std::uint64_t max_age_us) {
  const auto& c = cam.counters();
  std::printf(
      "{\"type\":\"%s\",\"t_us\":%llu,\"connected\":%s,\"frames\":%llu,\"dropped\":%llu,\"late\":%llu,"
      "\"corrupt\":%llu,\"disconnects\":%u,\"reconnects\":%u,\"driver_stamps\":%s,\"stamp_backsteps\":%llu,"
      "\"max_age_us\":%llu,\"error\":\"%s\"}\n",
      type, static_cast<unsigned long long>(mono_us()), cam.connected() ? "true" : "false",
      static_cast<unsigned long long>(c.frames), static_cast<unsigned long long>(c.dropped),
      static_cast<unsigned long long>(c.late), static_cast<unsigned long long>(c.corrupt), c.disconnects, c.reconnects,
      cam.driver_stamps() ? "true" : "false", static_cast<unsigned long long>(backsteps),
      static_cast<unsigned long long>(max_age_us), json_escape(cam.last_error()).c_str());
  std::fflush(stdout);
}

void print_detection(const TagDetection& d) {
  std::printf(
      "{\"type\":\"tag\",\"id\":%d,\"u_px\":%.3f,\"v_px\":%.3f,\"decision_margin\":%.2f,\"hamming\":%d,"
      "\"corners_px\":[[%.3f,%.3f],[%.3f,%.3f],[%.3f,%.3f],[%.3f,%.3f]]",
      d.id, d.u_px, d.v_px, d.decision_margin, d.hamming, d.corners_px[0][0], d.corners_px[0][1], d.corners_px[1][0],
      d.corners_px[1][1], d.corners_px[2][0], d.corners_px[2][1], d.corners_px[3][0], d.corners_px[3][1]);
  if (d.has_pose) {
    std::printf(",\"x_m\":%.4f,\"y_m\":%.4f,\"z_m\":%.4f,\"pose_error\":%.3g", d.translation_m[0], d.translation_m[1],
                d.translation_m[2], d.pose_error);
  }
  std::printf("}\n");
}

/// The image as a width×height grey frame: decoded, then the centre cropped (or padded with mid-grey) to the size.
bool load_frame(const std::string& path, std::uint32_t w, std::uint32_t h, std::vector<std::uint8_t>& out,
                std::string& err) {
  GreyImage img;
  if (!read_jpeg_grey(path, img, err)) return false;
  out.assign(static_cast<std::size_t>(w) * h, 128);
  const long ox = (static_cast<long>(img.width_px) - static_cast<long>(w)) / 2;
  const long oy = (static_cast<long>(img.height_px) - static_cast<long>(h)) / 2;
  for (std::uint32_t r = 0; r < h; ++r) {
    const long sr = static_cast<long>(r) + oy;
    if (sr < 0 || sr >= static_cast<long>(img.height_px)) continue;
    for (std::uint32_t c = 0; c < w; ++c) {
      const long sc = static_cast<long>(c) + ox;
      if (sc < 0 || sc >= static_cast<long>(img.width_px)) continue;
      out[static_cast<std::size_t>(r) * w + c] =
          img.pixels[static_cast<std::size_t>(sr) * img.width_px + static_cast<std::size_t>(sc)];
    }
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"camera-check: V4L2 capture and AprilTag detection outside dockd (docs/camera.md)"};
  app.require_subcommand(1);

  TagDetectorOptions det_opt;
  std::string image;
  double fx = 0, fy = 0, cx = -1, cy = -1;
  std::vector<double> distortion;
  bool live_detect = false;
  V4l2CameraOptions cam_opt;
  std::string format = "grey";
  std::uint64_t frames = 0;
  double seconds = 0;
  std::uint32_t every = 1;
  std::vector<std::string> controls;
  bool expect_reconnect = false;
  double give_up_s = 10;
  std::uint64_t after_reconnect = 0;
  auto* cap =
      app.add_subcommand("capture", "capture frames; one JSON line per frame (--every N), state changes and a summary");
  cap->add_option("--device", cam_opt.device, "V4L2 device")->capture_default_str();
  cap->add_option("--format", format, "grey | yuyv | mjpeg")
      ->check(CLI::IsMember({"grey", "yuyv", "mjpeg"}))
      ->capture_default_str();
  cap->add_option("--width", cam_opt.width_px, "px")->capture_default_str();
  cap->add_option("--height", cam_opt.height_px, "px")->capture_default_str();
  cap->add_option("--fps", cam_opt.fps, "frame rate to ask for (0 = device default)")->capture_default_str();
  cap->add_option("--late-ms", cam_opt.late_ms, "a frame dequeued later than this after its stamp is late")
      ->capture_default_str();
  cap->add_option("--reconnect-min-ms", cam_opt.reconnect_min_ms)->capture_default_str();
  cap->add_option("--reconnect-max-ms", cam_opt.reconnect_max_ms)->capture_default_str();
  cap->add_option("--frames", frames, "stop after this many frames (0 = no limit)");
  cap->add_option("--seconds", seconds, "stop after this long (0 = no limit)");
  cap->add_option("--every", every, "print every N-th frame line (0 = none)")->capture_default_str();
  cap->add_option("--control", controls, "set a device control first, \"Name=value\" (repeatable)");
  cap->add_option("--give-up-seconds", give_up_s, "exit 3 after this long without a frame")->capture_default_str();
  cap->add_option("--stop-after-reconnect-frames", after_reconnect,
                  "stop once this many frames arrived after a reopen (0 = off)");
  cap->add_flag("--expect-reconnect", expect_reconnect, "exit 1 unless the device was lost and reopened");

  std::uint32_t bench_frames = 200, width = 640, height = 480;
  auto add_detector_options = [&](CLI::App* s, const char* image_help) {
    if (image_help != nullptr) s->add_option("--image", image, image_help);
    s->add_option("--family", det_opt.family, "tag family")->capture_default_str();
    s->add_option("--decimate", det_opt.quad_decimate, "quad_decimate")->capture_default_str();
    s->add_option("--sigma", det_opt.quad_sigma, "quad_sigma, px")->capture_default_str();
    s->add_option("--threads", det_opt.threads, "detector threads")->capture_default_str();
    s->add_option("--refine-edges", det_opt.refine_edges, "true | false")->capture_default_str();
    s->add_option("--refine-corners", det_opt.refine_corners, "sub-pixel corners from the edges: true | false")
        ->capture_default_str();
    s->add_option("--tag-size", det_opt.tag_size_m, "black square side, m")->capture_default_str();
  };
  auto add_intrinsics = [&](CLI::App* s) {
    s->add_option("--fx", fx, "px (with the tag size: poses)");
    s->add_option("--fy", fy, "px (default: fx)");
    s->add_option("--cx", cx, "px (default: image centre)");
    s->add_option("--cy", cy, "px (default: image centre)");
    s->add_option("--distortion", distortion, "k1 k2 p1 p2 [k3]")->expected(4, 5);
  };
  cap->add_flag("--detect", live_detect, "run the detector on every frame and print its tags (calibration check)");
  add_detector_options(cap, nullptr);
  add_intrinsics(cap);
  auto* det = app.add_subcommand("detect", "tags in one image (JSON line per tag)");
  add_detector_options(det, "JPEG file");
  add_intrinsics(det);
  auto* bench = app.add_subcommand("bench", "detection time per grey frame (default 640×480; no timing assertion)");
  add_detector_options(bench, "JPEG file, its centre cropped to the size (default: a drawn frame of four tags)");
  bench->add_option("--frames", bench_frames, "detections timed")->capture_default_str();
  bench->add_option("--width", width, "frame width, px (the image's centre is cropped to it)")->capture_default_str();
  bench->add_option("--height", height, "frame height, px")->capture_default_str();

  camera_check::TagPoseOptions tp;
  double tp_fx = 600;
  auto* tagpose = app.add_subcommand(
      "tag-pose", "error of the dock pose derived from a tag on rendered frames with noise and blur");
  add_detector_options(tagpose, nullptr);
  tagpose->add_option("--frames", tp.frames, "rendered frames")->capture_default_str();
  tagpose->add_option("--distance", tp.distance_m, "camera to tag, m")->capture_default_str();
  tagpose->add_option("--lateral", tp.lateral_m, "robot offset from the dock axis: uniform in ±this, m")
      ->capture_default_str();
  tagpose->add_option("--yaw", tp.yaw_deg, "dock turned: uniform in ±this, °")->capture_default_str();
  tagpose->add_option("--noise", tp.noise_grey, "Gaussian pixel noise σ, grey levels")->capture_default_str();
  tagpose->add_option("--blur", tp.blur_px, "Gaussian blur σ, px")->capture_default_str();
  tagpose->add_option("--sigma-px", tp.sigma_px, "the covariance model's corner noise, px")->capture_default_str();
  tagpose->add_option("--focal", tp_fx, "focal length of the rendered 640×480 camera, px")->capture_default_str();
  tagpose->add_option("--seed", tp.seed)->capture_default_str();
  tagpose
      ->add_option("--corner-fit", tp.corner_fit,
                   "fit the dock pose to the corners (true) or take libapriltag's pose alone (false)")
      ->capture_default_str();

  camera_check::CalibOptions calib_opt;
  std::vector<std::string> calib_images;
  V4l2CameraOptions calib_cam;
  std::string calib_format = "grey";
  auto* calib = app.add_subcommand(
      "calib", "check a calibration: a tag at a measured distance in a few frames (device or JPEG images)");
  calib->add_option("--distance", calib_opt.distance_m, "lens to tag along the optical axis, m (measured)")->required();
  calib->add_option("--lateral", calib_opt.lateral_m, "tag centre right of the optical axis, m (measured)")
      ->capture_default_str();
  calib->add_option("--frames", calib_opt.frames, "device: frames with the tag to average")->capture_default_str();
  calib->add_option("--tag-id", calib_opt.tag_id, "the tag to use (-1: the strongest)")->capture_default_str();
  calib->add_option("--tolerance", calib_opt.tolerance, "ok within this fraction of the distance")
      ->capture_default_str();
  calib->add_option("--image", calib_images, "JPEG frame (repeatable) instead of a device");
  calib->add_option("--device", calib_cam.device, "V4L2 device")->capture_default_str();
  calib->add_option("--format", calib_format, "grey | yuyv | mjpeg")
      ->check(CLI::IsMember({"grey", "yuyv", "mjpeg"}))
      ->capture_default_str();
  calib->add_option("--width", calib_cam.width_px, "px")->capture_default_str();
  calib->add_option("--height", calib_cam.height_px, "px")->capture_default_str();
  calib->add_option("--give-up-seconds", calib_opt.give_up_s, "device: stop after this long without the tag")
      ->capture_default_str();
  add_detector_options(calib, nullptr);
  add_intrinsics(calib);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }

  if (tagpose->parsed()) return camera_check::run_tag_pose(tp, det_opt, tp_fx);
  std::string err;
  auto set_intrinsics = [&](std::uint32_t w, std::uint32_t h) {
    if (fx <= 0) return;
    CameraIntrinsics k{fx, fy > 0 ? fy : fx, cx >= 0 ? cx : (w - 1) / 2.0, cy >= 0 ? cy : (h - 1) / 2.0};
    double d[5] = {0, 0, 0, 0, 0};
    for (std::size_t i = 0; i < distortion.size() && i < 5; ++i) d[i] = distortion[i];
    k.k1 = d[0];
    k.k2 = d[1];
    k.p1 = d[2];
    k.p2 = d[3];
    k.k3 = d[4];
    det_opt.intrinsics = k;
  };
  if (calib->parsed()) {
    // A default tag size would silently scale every distance: the size of the tag in front of the camera is required.
    if (calib->get_option("--tag-size")->count() == 0) {
      std::fprintf(stderr, "camera-check calib: --tag-size (the black square's side, camera.tag.size_m) is required\n");
      return camera_check::kCalibUsage;
    }
    if (!calib_images.empty()) {
      // The principal point defaults to the centre of the first image.
      GreyImage first;
      if (!read_jpeg_grey(calib_images.front(), first, err)) {
        std::fprintf(stderr, "camera-check calib: %s\n", err.c_str());
        return camera_check::kCalibUsage;
      }
      set_intrinsics(first.width_px, first.height_px);
      return camera_check::run_calib_images(calib_images, calib_opt, det_opt);
    }
    calib_cam.format = *parse_camera_pixel_format(calib_format);
    set_intrinsics(calib_cam.width_px, calib_cam.height_px);
    return camera_check::run_calib_device(calib_cam, calib_opt, det_opt);
  }
  if (cap->parsed()) {
    cam_opt.format = *parse_camera_pixel_format(format);
    std::unique_ptr<TagDetector> live;
    if (live_detect) {
      set_intrinsics(cam_opt.width_px, cam_opt.height_px);
      live = TagDetector::create(det_opt, err);
      if (!live) {
        std::fprintf(stderr, "camera-check: %s\n", err.c_str());
        return 2;
      }
    }
    for (const std::string& c : controls) {
      if (!set_control(cam_opt.device, c, err)) {
        std::fprintf(stderr, "camera-check: %s\n", err.c_str());
        return 3;
      }
    }
    auto cam = open_v4l2_camera(cam_opt, err);
    if (!cam) {
      std::fprintf(stderr, "camera-check: %s\n", err.c_str());
      return 3;
    }
    const std::uint64_t start = mono_us();
    std::uint64_t prev_stamp = 0, backsteps = 0, max_age = 0;
    bool was_connected = cam->connected();
    std::uint64_t last_frame_us = start;
    std::uint64_t frames_at_reconnect = 0;
    print_counters("start", *cam, 0, 0);
    for (;;) {
      if (after_reconnect > 0 && cam->counters().reconnects > 0 &&
          cam->counters().frames >= frames_at_reconnect + after_reconnect) {
        break;
      }
      if (mono_us() - last_frame_us > static_cast<std::uint64_t>(give_up_s * 1e6)) {
        print_counters("summary", *cam, backsteps, max_age);
        std::fprintf(stderr, "camera-check: no frame for %.1f s (%s)\n", give_up_s, cam->last_error());
        return 3;
      }
      if (frames > 0 && cam->counters().frames >= frames) break;
      if (seconds > 0 && mono_us() - start >= static_cast<std::uint64_t>(seconds * 1e6)) break;
      dockcore::hal::CameraFrame f;
      const auto st = cam->next_frame(f, 100);
      if (cam->connected() != was_connected) {
        was_connected = cam->connected();
        if (was_connected) frames_at_reconnect = cam->counters().frames;
        print_counters("state", *cam, backsteps, max_age);
      }
      if (st != dockcore::hal::CameraFrameStatus::kFrame) continue;
      const std::uint64_t now = mono_us();
      last_frame_us = now;
      if (prev_stamp != 0 && f.stamp_us <= prev_stamp) ++backsteps;
      prev_stamp = f.stamp_us;
      const std::uint64_t age = now >= f.stamp_us ? now - f.stamp_us : 0;
      max_age = std::max(max_age, age);
      if (every > 0 && cam->counters().frames % every == 0) {
        std::printf(
            "{\"type\":\"frame\",\"seq\":%u,\"stamp_us\":%llu,\"age_us\":%llu,\"mean\":%u}\n", f.sequence,
            static_cast<unsigned long long>(f.stamp_us), static_cast<unsigned long long>(age),
            static_cast<unsigned>(f.grey[static_cast<std::size_t>(f.height_px / 2) * f.stride_bytes + f.width_px / 2]));
        std::fflush(stdout);
      }
      if (live) {
        TagDetection tags[kMaxTagDetections];
        const std::size_t n = live->detect(f.grey, f.width_px, f.height_px, f.stride_bytes, tags, kMaxTagDetections);
        for (std::size_t i = 0; i < n; ++i) print_detection(tags[i]);
        std::fflush(stdout);
      }
    }
    print_counters("summary", *cam, backsteps, max_age);
    const auto& c = cam->counters();
    if (c.frames == 0 || backsteps > 0) return 1;
    if (expect_reconnect && (c.disconnects == 0 || c.reconnects == 0)) return 1;
    return 0;
  }

  std::vector<std::uint8_t> frame;
  std::uint32_t w = width, h = height;
  if (image.empty() && det->parsed()) {
    std::fprintf(stderr, "camera-check: detect needs --image\n");
    return 2;
  }
  if (image.empty()) {
    // No image: a drawn frame, mid-grey with four tag36h11 tags of 4, 6, 8 and 12 px per cell (ids 0..3).
    frame.assign(static_cast<std::size_t>(w) * h, 128);
    const std::uint32_t cells[4] = {4, 6, 8, 12};
    std::uint32_t x = 10;
    for (int i = 0; i < 4; ++i) {
      if (!draw_tag_upright("tag36h11", i, cells[i], x, 20 + 20 * static_cast<std::uint32_t>(i), frame.data(), w, h,
                            w)) {
        std::fprintf(stderr, "camera-check: a %ux%u frame is too small for the drawn tags\n", w, h);
        return 2;
      }
      x += 10 * cells[i] + 20;
    }
    image = "drawn";
  } else if (det->parsed()) {
    GreyImage img;
    if (!read_jpeg_grey(image, img, err)) {
      std::fprintf(stderr, "camera-check: %s\n", err.c_str());
      return 2;
    }
    w = img.width_px;
    h = img.height_px;
    frame = std::move(img.pixels);
    set_intrinsics(w, h);
  } else if (!load_frame(image, w, h, frame, err)) {  // bench on a photo
    std::fprintf(stderr, "camera-check: %s\n", err.c_str());
    return 2;
  }
  auto detector = TagDetector::create(det_opt, err);
  if (!detector) {
    std::fprintf(stderr, "camera-check: %s\n", err.c_str());
    return 2;
  }
  TagDetection d[kMaxTagDetections];
  if (det->parsed()) {
    const std::size_t n = detector->detect(frame.data(), w, h, w, d, kMaxTagDetections);
    for (std::size_t i = 0; i < n; ++i) print_detection(d[i]);
    return n > 0 ? 0 : 1;
  }
  std::vector<double> ms;
  std::size_t tags = 0;
  for (std::uint32_t i = 0; i < bench_frames + 3; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::size_t n = detector->detect(frame.data(), w, h, w, d, kMaxTagDetections);
    const double t = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (i >= 3) ms.push_back(t);  // the first calls warm caches and the worker pool
    tags = n;
  }
  std::sort(ms.begin(), ms.end());
  double sum = 0;
  for (double v : ms) sum += v;
  const auto pct = [&](double p) {
    return ms[std::min(ms.size() - 1, static_cast<std::size_t>(p * static_cast<double>(ms.size())))];
  };
  std::printf(
      "{\"type\":\"bench\",\"image\":\"%s\",\"width_px\":%u,\"height_px\":%u,\"family\":\"%s\",\"decimate\":%g,"
      "\"threads\":%d,\"frames\":%zu,\"tags\":%zu,\"mean_ms\":%.3f,\"median_ms\":%.3f,\"p95_ms\":%.3f,\"max_ms\":%.3f}"
      "\n",
      json_escape(image).c_str(), w, h, det_opt.family.c_str(), det_opt.quad_decimate, det_opt.threads, ms.size(), tags,
      sum / static_cast<double>(ms.size()), pct(0.5), pct(0.95), ms.back());
  return 0;
}
