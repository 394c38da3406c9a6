#pragma once
/// @file Seed 000's breakpoint detection as a dock-pose measurement: what Dockcore needs to run BreakpointDetector in
/// place of the estimator (DockDetector::kBreakpoint, dockcore.hpp) — which profiles it can find, the seed's
/// thresholds at the scan's resolution, and the detection as a dock pose with a covariance the filter can fuse.
///
/// The pose. Position: the seed's centre, i.e. the raw range of the beam halfway between the pattern's outer marks
/// at that beam's angle (BreakpointDetection::dock_position_lidar): on the breakpoint dock it hits the raised face
/// at the contacts' centre. Yaw, which the seed's text leaves out but its ROS node publishes the figures for: the
/// seed's left point (range and angle of mark m3, in the -y slot) and right point (mark m0 on the +y end block, its
/// range plus the 0.06 m step, i.e. on the slot plane) both lie on the slot plane x = -0.06 m, 0.26 m apart, so
/// the line from left to right is the dock's +y axis.
///
/// The covariance, from the detector's own figures (beam spacing Δθ, the ranges it read, the baseline b between its
/// left and right points) and the lidar's range noise σr (EstimatorParams::range_sigma_m):
///  - along the centre beam: σr² (one raw range);
///  - across it: r²·Δθ²/8 — each outer mark places its edge within one beam (uniform: Δθ²/12), the mean of the two
///    has Δθ²/24, and rounding the centre to a beam adds Δθ²/12;
///  - yaw: (σ⊥,left² + σ⊥,right²) / b², where σ⊥² is a point's error variance normal to the baseline: its range
///    noise along its beam and its one-beam quantisation (r·Δθ)²/12 across it, projected on the baseline's normal,
///    plus the slot's side wall: a beam at angle φ to the dock's normal that enters a slot within h·tan φ of its
///    wall (h = 0.06 m deep) meets the wall, not the bottom, so an outer mark lands there with probability
///    min(1, h·tan φ / (r·Δθ)) and reads short by up to h − min_jump_m (a shorter one is no mark): that probability
///    times (h − min_jump_m)²/12.
/// Position and yaw are taken as uncorrelated. This is the spread of a detection that found the dock; it says
/// nothing about the seed's false matches (the four-mark pattern locking onto range noise elsewhere in the scan,
/// docs/performance.md): those are left to the filter's jump gate.

#include <cstdint>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/breakpoint_detector.hpp"
#include "dockcore/perception/dock_profile.hpp"

namespace dockcore {

/// Whether `profile` is the built-in "breakpoint" outline (docs/docks.md), vertex for vertex within 1 mm, up to a
/// rigid move of the dock frame (a taught docking target moves the frame, not the shape). When it is and
/// `native_in_dock` is not null, sets it to the built-in's frame expressed in the profile's frame (identity for the
/// built-in itself). O(vertices).
bool breakpoint_outline_frame(const DockProfile& profile, Pose2* native_in_dock = nullptr);

/// The seed's thresholds (`seed`, default BreakpointParams{}) with its beam-count thresholds (neighbour_offset_idx
/// 5, max_pair_spacing_idx 7, tuned on a 1° lidar) scaled to the same angles on a scan of `angle_increment_rad`
/// (> 0; otherwise `seed` unchanged), at least 1 and 2 beams. O(1).
BreakpointParams breakpoint_params_for_scan(Real angle_increment_rad,
                                            const BreakpointParams& seed = BreakpointParams{});

/// The dock pose (built-in breakpoint frame) in the robot frame and its covariance (x, y, yaw; m², rad²) from
/// detection `d` of a scan with `angle_increment_rad`, a lidar at `lidar_mount` in the robot frame and range noise
/// `range_sigma_m`, for a detector whose smallest marked jump is `min_jump_m` (file comment). False (outputs
/// untouched) when !d.found, the centre beam has no valid return, the left/right points coincide, or an input is not
/// finite. O(1).
bool breakpoint_measurement(const BreakpointDetection& d, Real angle_increment_rad, const Pose2& lidar_mount,
                            Real range_sigma_m, Pose2* dock_in_robot, Mat3* covariance,
                            Real min_jump_m = BreakpointParams{}.min_jump_m);

}  // namespace dockcore
