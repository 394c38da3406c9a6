#pragma once
// Cramér–Rao lower bound for a single-scan dock pose estimate: the Fisher information of the range samples that hit
// the profile, under independent Gaussian range noise. An unbiased estimator cannot beat it; the benchmark prints it
// beside each measured error so the estimator's efficiency is visible.
#include <cstddef>

#include "dockcore/geometry.hpp"
#include "dockcore/perception/dock_profile.hpp"

namespace docksim {

struct Crlb {
  bool ok = false;           ///< False when the pose is unobservable (too few beams or a singular information).
  std::size_t beams = 0;     ///< Beams that hit the profile.
  dockcore::Mat3 cov;        ///< Bound on the covariance of (x, y, yaw) in the sensor frame.
  double sigma_longitudinal_m = 0;  ///< Along the dock's x axis (approach direction).
  double sigma_lateral_m = 0;       ///< Along the dock's y axis.
  double sigma_yaw_rad = 0;
};

/// Bound for a dock at `dock_in_sensor`, scanned by beams angle_min + i*increment (i < beams) with range noise
/// σ(r) = sigma_const_m + sigma_prop * r (1 σ).
Crlb dock_pose_crlb(const dockcore::DockProfile& profile, const dockcore::Pose2& dock_in_sensor, double angle_min_rad,
                    double angle_increment_rad, std::size_t beams, double sigma_const_m, double sigma_prop);

}  // namespace docksim
