#pragma once
// camera-check calib: checks a camera calibration from a few frames of a tag at a measured distance
// (docs/camera.md, "Checking a calibration"). Host tool code: allocates freely.
#include <cstdint>
#include <string>
#include <vector>

#include "dockcore/drivers/apriltag_detector.hpp"
#include "dockcore/drivers/v4l2_camera.hpp"

namespace camera_check {

struct CalibOptions {
  double distance_m = 0;      ///< Lens to tag along the optical axis, as measured (required, > 0).
  double lateral_m = 0;       ///< Tag centre to the right of the optical axis, as measured.
  std::uint32_t frames = 10;  ///< Frames with the tag to average (device); images: every image.
  int tag_id = -1;            ///< The tag to use; −1 = the strongest in each frame.
  double tolerance = 0.01;    ///< "ok" when depth and lateral agree within this fraction of the distance.
  double give_up_s = 10;      ///< Device: stop after this long without a frame holding the tag.
};

/// One frame's tag pose: position of the tag centre in the camera frame.
struct CalibSample {
  double x_m = 0;
  double z_m = 0;
};

/// What the frames say about the calibration.
struct CalibReport {
  std::uint32_t frames = 0;  ///< Samples used.
  double z_mean_m = 0, z_std_m = 0;
  double x_mean_m = 0, x_std_m = 0;
  /// distance_m / z_mean_m: the factor fx_px and fy_px (together) are off by — or, equally, the tag size's error.
  double focal_factor = 1;
  /// fx_px · (x_mean_m − lateral_m) / z_mean_m: how far the principal point is off to the left (add it to cx_px).
  double cx_offset_px = 0;
  bool depth_ok = false, lateral_ok = false;
  bool ok() const { return depth_ok && lateral_ok; }
};

/// The report of `samples` (at least one) for a calibration whose intrinsics are `k`. O(samples).
CalibReport calib_report(const std::vector<CalibSample>& samples, const CalibOptions& o,
                         const dockcore::drivers::CameraIntrinsics& k);

/// Prints the summary line (JSON) of `r` with the suggested values. O(1).
void print_calib_report(const CalibReport& r, const CalibOptions& o, const dockcore::drivers::CameraIntrinsics& k);

/// Exit statuses of calib (also docs/camera.md).
enum CalibExit : int { kCalibOk = 0, kCalibOff = 1, kCalibUsage = 2, kCalibDevice = 3, kCalibNoTag = 4 };

/// calib on JPEG images (one frame each): detects with `det` (its intrinsics and tag size are the calibration
/// checked), prints one `calib_frame` line per frame with the tag and the summary. `report` (optional) gets the
/// report. Returns a CalibExit.
int run_calib_images(const std::vector<std::string>& images, const CalibOptions& o,
                     const dockcore::drivers::TagDetectorOptions& det, CalibReport* report = nullptr);

/// calib on a V4L2 device: the first `o.frames` frames holding the tag. Returns a CalibExit.
int run_calib_device(const dockcore::drivers::V4l2CameraOptions& cam, const CalibOptions& o,
                     const dockcore::drivers::TagDetectorOptions& det);

}  // namespace camera_check
