#pragma once
// camera-check tag-pose: the dock pose derived from a tag on rendered frames (docs/camera.md, "Fusion").
#include <cstdint>
#include <string>
#include <vector>

#include "dockcore/drivers/apriltag_detector.hpp"
#include "dockcore/perception/tag_measurement.hpp"
#include "docksim/tag_render.hpp"

namespace camera_check {

struct TagPoseOptions {
  std::uint32_t frames = 300;  ///< Rendered frames.
  double distance_m = 1.0;     ///< Camera to tag, along the dock's axis.
  double lateral_m = 0.10;     ///< Robot offset from the dock's axis: uniform in ±this.
  double yaw_deg = 15;         ///< Dock turned against the robot: uniform in ±this.
  double noise_grey = 4;       ///< Gaussian pixel noise, grey levels (σ).
  double blur_px = 0.8;        ///< Gaussian blur σ, px (0: none).
  /// The covariance model's corner noise, for the model's σ printed beside (default: the core's default).
  double sigma_px = static_cast<double>(dockcore::TagFusionParams{}.sigma_px);
  bool corner_fit = true;  ///< Hand the corners to the core (the dock pose fitted to them), or the pose alone.
  std::uint64_t seed = 1;
  std::uint32_t width_px = 640, height_px = 480;
};

/// Renders, detects and prints one JSON summary line (percentiles of the errors of the dock pose in the robot frame,
/// the model's σ). Returns the exit status: 0, 1 when no frame had the tag, 2 for bad options.
int run_tag_pose(const TagPoseOptions& o, dockcore::drivers::TagDetectorOptions det, double fx_px);

}  // namespace camera_check
