#include "dockcore/params/param_table.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <type_traits>

namespace dockcore::params {

namespace {

constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;
constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;

}  // namespace

// One entry per parameter. T is the ParamTargets member, M the field within that struct.
#define DC_REAL(TBL, KEY, UNIT, LO, HI, USE, T, M, MEANING)                    \
  ParamSpec {                                                                  \
    TBL, KEY, UNIT, ParamType::kReal, LO, HI, USE, MEANING,                    \
        [](const ParamTargets& t) { return static_cast<double>(t.T->M); },     \
        [](const ParamTargets& t, double v) { t.T->M = static_cast<Real>(v); } \
  }
#define DC_DEG(TBL, KEY, LO, HI, USE, T, M, MEANING)                                        \
  ParamSpec {                                                                               \
    TBL, KEY, "°", ParamType::kDegrees, LO, HI, USE, MEANING,                               \
        [](const ParamTargets& t) { return static_cast<double>(t.T->M) * kDegPerRad; },     \
        [](const ParamTargets& t, double v) { t.T->M = static_cast<Real>(v * kRadPerDeg); } \
  }
#define DC_INT(TBL, KEY, UNIT, LO, HI, USE, T, M, MEANING)                                                       \
  ParamSpec {                                                                                                    \
    TBL, KEY, UNIT, ParamType::kInteger, LO, HI, USE, MEANING,                                                   \
        [](const ParamTargets& t) { return static_cast<double>(t.T->M); }, [](const ParamTargets& t, double v) { \
          t.T->M = static_cast<std::remove_reference_t<decltype(t.T->M)>>(static_cast<std::int64_t>(v));         \
        }                                                                                                        \
  }
#define DC_BOOL(TBL, KEY, USE, T, M, MEANING)                                                                      \
  ParamSpec {                                                                                                      \
    TBL, KEY, "–", ParamType::kBool, 0, 1, USE, MEANING, [](const ParamTargets& t) { return t.T->M ? 1.0 : 0.0; }, \
        [](const ParamTargets& t, double v) { t.T->M = v != 0; }                                                   \
  }
// A setting every controller shares, written into all four controllers' DockingCommonParams.
#define DC_COMMON(KEY, UNIT, LO, HI, USE, M, MEANING)                                  \
  ParamSpec {                                                                          \
    "controller", KEY, UNIT, ParamType::kReal, LO, HI, USE, MEANING,                   \
        [](const ParamTargets& t) { return static_cast<double>(t.smooth->common.M); }, \
        [](const ParamTargets& t, double v) {                                          \
          const Real r = static_cast<Real>(v);                                         \
          t.seed000->common.M = t.seed004->common.M = r;                               \
          t.seed003->common.M = t.smooth->common.M = r;                                \
        }                                                                              \
  }
// The shared settings given for one controller only (dock-sim's per-controller tables), with the shared keys' bounds.
#define DC_COMMON_OF(TBL, T)                                                                   \
  [] {                                                                                         \
    ParamSpec s = DC_REAL(TBL, "pad_reach_m", "m", 0.01, 3, kScenario, T, common.pad_reach_m,  \
                          "This controller only: robot centre to the pads' centre.");          \
    s.default_text = "from the footprint";                                                     \
    return s;                                                                                  \
  }(),                                                                                         \
      DC_REAL(TBL, "creep_speed_mps", "m/s", 0.001, 1, kScenario, T, common.creep_speed_mps,   \
              "This controller only: slowest approach speed."),                                \
      DC_REAL(TBL, "stall_press_m", "m", -0.1, 0.1, kScenario, T, common.stall_press_m,        \
              "This controller only: pads this far past the contact plane count as pressed."), \
      DC_REAL(TBL, "stall_timeout_s", "s", 0.1, 60, kScenario, T, common.stall_timeout_s,      \
              "This controller only: pressed without contact this long: retry.")

namespace {

const ParamSpec kTable[] = {
    // [robot]: the drive geometry dockd converts wheel speeds with (a scenario's chassis takes the same bounds
    // under its own names: wheel_radius_m, wheel_base_m, lx_m, ly_m).
    DC_REAL("robot", "wheel_radius_m", "m", 0.005, 1, kDockd, drive, wheel_radius_m, "Rolling radius."),
    DC_REAL("robot", "track_m", "m", 0.02, 5, kDockd, drive, wheel_base_m, "Differential: left–right wheel distance."),
    DC_REAL("robot", "half_wheelbase_m", "m", 0.01, 5, kDockd, drive, lx_m, "Mecanum: half front–rear distance (lx)."),
    DC_REAL("robot", "half_track_m", "m", 0.01, 5, kDockd, drive, ly_m, "Mecanum: half left–right distance (ly)."),

    // [robot.limits]: dockcore's drive limits (saturate_twist keeps the curvature, then limit_acceleration).
    [] {
      ParamSpec s = DC_REAL("robot.limits", "max_vx_mps", "m/s", 0, 5, kBoth, limits, max_vx_mps,
                            "Forward speed limit (also the task manager's final clamp; 0: none).");
      s.scenario_default = 0.4;
      return s;
    }(),
    DC_REAL("robot.limits", "max_vy_mps", "m/s", 0, 5, kBoth, limits, max_vy_mps, "Sideways speed limit (mecanum)."),
    DC_REAL("robot.limits", "max_wz_radps", "rad/s", 0, 10, kBoth, limits, max_wz_radps, "Yaw rate limit."),
    DC_REAL("robot.limits", "max_wheel_radps", "rad/s", 0, 500, kBoth, limits, max_wheel_radps,
            "Any wheel's angular velocity."),
    DC_REAL("robot.limits", "max_linear_accel_mps2", "m/s²", 0, 20, kBoth, limits, max_linear_accel_mps2,
            "Rate limit of vx, vy between ticks."),
    DC_REAL("robot.limits", "max_angular_accel_radps2", "rad/s²", 0, 50, kBoth, limits, max_angular_accel_radps2,
            "Rate limit of wz."),

    // [robot.footprint]: the obstacle check (dockcore FootprintParams). A scenario derives the body's outline from
    // its chassis (length_m, width_m, radius_m, centre_x_m); dockd gives it directly.
    [] {
      ParamSpec s{"robot.footprint",
                  "shape",
                  "–",
                  ParamType::kChoice,
                  0,
                  1,
                  kBoth,
                  "Body outline.",
                  [](const ParamTargets& t) { return t.footprint->shape == FootprintShape::kCircular ? 1.0 : 0.0; },
                  [](const ParamTargets& t, double v) {
                    t.footprint->shape = v != 0 ? FootprintShape::kCircular : FootprintShape::kSquare;
                  }};
      s.choices = "square|circle";
      return s;
    }(),
    DC_REAL("robot.footprint", "half_length_m", "m", 0.01, 5, kDockd, footprint, half_length_m,
            "Square: centre to front/rear edge."),
    DC_REAL("robot.footprint", "half_width_m", "m", 0.01, 5, kDockd, footprint, half_width_m,
            "Square: centre to each side."),
    DC_REAL("robot.footprint", "radius_m", "m", 0.01, 5, kDockd, footprint, radius_m,
            "Circle radius (a scenario's `radius_m` is its chassis circle, with these bounds)."),
    DC_REAL("robot.footprint", "check_length_m", "m", 0, 5, kBoth, footprint, check_length_m,
            "Obstacle area depth beyond the body edge."),
    DC_REAL("robot.footprint", "check_width_m", "m", 0, 5, kBoth, footprint, check_width_m, "Obstacle area width."),
    DC_REAL("robot.footprint", "circumscribed_radius_m", "m", 0.01, 10, kDockd, footprint, circumscribed_radius_m,
            "Rotation check radius."),
    DC_REAL("robot.footprint", "self_margin_m", "m", 0, 1, kBoth, footprint, self_margin_m,
            "Within the self sectors (`self_sectors_deg`) returns inside the body grown by this are the robot; "
            "elsewhere every return, even inside the body, is an obstacle (docs/task-manager.md, Obstacles)."),
    DC_REAL("robot.footprint", "dock_margin_m", "m", 0, 1, kBoth, footprint, dock_margin_m,
            "Returns this close to the dock outline are the dock."),
    DC_INT("robot.footprint", "min_points", "–", 1, 1000, kBoth, footprint, min_points,
           "Returns in an area that block it."),

    // The dock's detector (DockcoreConfig::detector): a scenario's [dock], each of dockd's [[docks]] entries.
    [] {
      ParamSpec s{"dock",
                  "detector",
                  "–",
                  ParamType::kChoice,
                  0,
                  1,
                  kBoth,
                  "Which detector finds this dock in each scan: `estimator` (any profile) or `breakpoint` (seed 000's "
                  "range-jump detector; only the `breakpoint` profile, against a wall; a pose covariance from its beam "
                  "spacing and `range_sigma_m`). docs/docks.md, \"Which detector works with which dock\".",
                  [](const ParamTargets& t) { return *t.detector == DockDetector::kBreakpoint ? 1.0 : 0.0; },
                  [](const ParamTargets& t, double v) {
                    *t.detector = v != 0 ? DockDetector::kBreakpoint : DockDetector::kEstimator;
                  }};
      s.choices = "estimator|breakpoint";
      s.dockd_table = "docks";
      return s;
    }(),

    // [estimator]: EstimatorParams. The range keys sit in dockd's [lidar].
    [] {
      ParamSpec s = DC_REAL("estimator", "min_range_m", "m", 0, 10, kBoth, estimator, min_range_m,
                            "Estimator ignores closer returns (< `max_range_m`).");
      s.dockd_table = "lidar";
      return s;
    }(),
    [] {
      ParamSpec s = DC_REAL("estimator", "max_range_m", "m", 0.1, 100, kBoth, estimator, max_range_m,
                            "Estimator ignores farther returns.");
      s.dockd_table = "lidar";
      return s;
    }(),
    [] {
      ParamSpec s = DC_REAL("estimator", "range_sigma_m", "m", 0.0001, 1, kBoth, estimator, range_sigma_m,
                            "Expected range noise (gates, covariance).");
      s.dockd_table = "lidar";
      return s;
    }(),
    DC_REAL("estimator", "huber_k", "σ", 0.1, 10, kBoth, estimator, huber_k,
            "Huber threshold of the first 3 Gauss-Newton iterations, in units of `range_sigma_m`."),
    DC_REAL("estimator", "tukey_c", "σ", 0.5, 20, kBoth, estimator, tukey_c,
            "Tukey cut-off after them, in units of `range_sigma_m`."),
    DC_REAL("estimator", "association_gate_m", "m", 0.005, 1, kBoth, estimator, association_gate_m,
            "Points farther than this from every visible dock surface are left out of the fit."),
    DC_REAL("estimator", "inlier_gate_m", "m", 0.001, 0.5, kBoth, estimator, inlier_gate_m,
            "A beam within this of the expected range is an inlier."),
    DC_INT("estimator", "max_iterations", "–", 1, 50, kBoth, estimator, max_iterations,
           "Gauss-Newton iterations per candidate, at most."),
    DC_INT("estimator", "max_candidates", "–", 1, 64, kBoth, estimator, max_candidates,
           "Pose hypotheses refined per scan, at most (best first)."),
    DC_REAL("estimator", "min_feature_length_m", "m", 0.01, 2, kBoth, estimator, min_feature_length_m,
            "Profile segments shorter than this seed no hypotheses."),
    DC_REAL("estimator", "free_space_m", "m", 0, 1, kBoth, estimator, free_space_m,
            "Returns this close in front of the expected surface count against the dock (free-space cue: the space "
            "before a dock is empty), not as occlusion."),
    DC_INT("estimator", "min_inliers", "–", 1, 1000, kBoth, estimator, min_inliers,
           "Inliers, at least; the built-in docks (plate-v, v-marker, breakpoint) bring their own floor of 6."),
    DC_REAL("estimator", "min_visible_fraction", "–", 0, 1, kBoth, estimator, min_visible_fraction,
            "Inliers / all beams expected on the dock, at least (how much may be hidden)."),
    DC_REAL("estimator", "extension_band_m", "m", 0.001, 0.5, kBoth, estimator, extension_band_m,
            "How near a long dock surface's line a return 4–12 cm past its end must lie to count as the surface "
            "carrying on (edges cue)."),
    DC_REAL("estimator", "min_evidence_nats", "nats", -20, 100, kBoth, estimator, min_evidence_nats,
            "A candidate is accepted when its evidence (the sum of its cues' log-likelihood ratios, "
            "[docks.md](docks.md#how-the-detector-decides)) reaches this. Higher: fewer false docks, more misses."),
    DC_REAL("estimator", "reflector_min_intensity", "sensor units", 0, 65535, kBoth, estimator, reflector_min_intensity,
            "A return at least this bright counts as reflector tape (intensity cue; docks with `[[reflectors]]` on a "
            "lidar whose intensity is usable). LD06: 0–255."),
    DC_BOOL("estimator", "stripe_hypotheses", kBoth, estimator, stripe_hypotheses,
            "Docks with `[[reflectors]]` on a lidar whose intensity is usable: the search also tries the scan's bright "
            "runs as the dock's stripes. Finds more coded docks, and takes more taped things for them "
            "([performance.md](performance.md#reflector-docks))."),
    DC_REAL("estimator", "wall_tolerance_m", "m", 0, 0.2, kBoth, estimator, wall_tolerance_m,
            "How far outside the mounting's gap range a wall still counts as the dock's wall."),
    DC_REAL("estimator", "max_sigma_m", "m", 0.001, 1, kBoth, estimator, max_sigma_m,
            "Position 1-σ from the covariance, at most."),
    DC_DEG("estimator", "max_view_angle_deg", 1, 90, kBoth, estimator, max_view_angle_rad,
           "Dock face seen more obliquely than this is refused (default 1.2 rad)."),
    DC_REAL("estimator", "hint_gate_m", "m", 0, 5, kBoth, estimator, hint_gate_m,
            "A verified pose farther than this from the hint ignores the hint."),
    DC_REAL("estimator", "hint_radius_m", "m", 0, 10, kBoth, estimator, hint_radius_m,
            "With a hint, only docks within this distance of it are accepted; 0: anywhere."),
    [] {
      ParamSpec s{"estimator",
                  "select",
                  "–",
                  ParamType::kChoice,
                  0,
                  1,
                  kBoth,
                  "Which verified dock wins: the nearest, or the one nearest the hint.",
                  [](const ParamTargets& t) { return t.estimator->select == DockSelect::kHint ? 1.0 : 0.0; },
                  [](const ParamTargets& t, double v) {
                    t.estimator->select = v != 0 ? DockSelect::kHint : DockSelect::kNearest;
                  }};
      s.choices = "nearest|hint";
      return s;
    }(),
    // [estimator.segments]: SegmentParams, the line extraction.
    DC_REAL("estimator.segments", "cluster_abs_gap_m", "m", 0.005, 1, kBoth, estimator, segments.cluster_abs_gap_m,
            "Floor of the cluster-break distance."),
    DC_REAL("estimator.segments", "cluster_gap_k", "–", 0, 50, kBoth, estimator, segments.cluster_gap_k,
            "Range-proportional cluster-break term (× range × beam spacing)."),
    DC_REAL("estimator.segments", "cluster_noise_margin_m", "m", 0, 0.5, kBoth, estimator,
            segments.cluster_noise_margin_m, "Added to that term."),
    DC_INT("estimator.segments", "cluster_max_missing_beams", "–", 0, 20, kBoth, estimator,
           segments.cluster_max_missing_beams, "Missing samples tolerated inside a cluster."),
    DC_REAL("estimator.segments", "split_threshold_m", "m", 0.001, 0.5, kBoth, estimator, segments.split_threshold_m,
            "Split while a point is farther than this from its chord."),
    DC_INT("estimator.segments", "corner_refine_points", "–", 0, 10, kBoth, estimator, segments.corner_refine_points,
           "Samples a split's corner may move to the best fit."),
    DC_INT("estimator.segments", "min_points", "–", 2, 100, kBoth, estimator, segments.min_points,
           "Fewest points of a segment."),
    DC_REAL("estimator.segments", "min_length_m", "m", 0, 2, kBoth, estimator, segments.min_length_m,
            "Shortest segment kept."),
    DC_REAL("estimator.segments", "merge_max_rms_m", "m", 0.001, 0.5, kBoth, estimator, segments.merge_max_rms_m,
            "Merge neighbouring pieces one line fits with at most this RMS."),
    DC_INT("estimator.segments", "merge_max_skipped_points", "–", 0, 20, kBoth, estimator,
           segments.merge_max_skipped_points, "Points a merge may skip."),
    DC_INT("estimator.segments", "max_clusters", "–", 1, 100000, kBoth, estimator, segments.max_clusters,
           "Clusters processed per scan (later ones are counted and dropped)."),
    // [camera.fusion] (dockd, and scenarios with a rendered camera): TagFusionParams, the tag pose as a dock-pose
    // measurement (docs/camera.md, "Fusion").
    DC_REAL("camera.fusion", "sigma_px", "px", 0.01, 20, kBoth, tag_fusion, sigma_px,
            "Effective corner noise of the tag detector: the covariance model's free parameter (measure it with "
            "`camera-check tag-pose`)."),
    DC_REAL("camera.fusion", "sigma_scale", "–", 0.1, 100, kBoth, tag_fusion, sigma_scale,
            "Multiplies every σ of the tag's covariance model."),
    DC_REAL("camera.fusion", "min_decision_margin", "–", 0, 1000, kBoth, tag_fusion, min_decision_margin,
            "Tag detections with a smaller decision margin are not fused (`weak`)."),
    DC_REAL("camera.fusion", "max_range_m", "m", 0.1, 20, kBoth, tag_fusion, max_range_m,
            "Tags deeper than this along the optical axis are not fused (`far`)."),
    DC_REAL("camera.fusion", "max_lag_s", "s", 0.001, 1, kBoth, tag_fusion, max_lag_s,
            "A tag frame older than the newest scan by more than this is not fused (`stale`)."),
    DC_INT("estimator.segments", "max_split_iterations", "–", 1, 1000000, kBoth, estimator,
           segments.max_split_iterations, "Split-step evaluations per scan."),

    // [watchdog]: WatchdogParams, the core's input watch (docs/dockd.md, "Watchdogs").
    DC_INT("watchdog", "lidar_stale_ms", "ms", 40, 10000, kBoth, watchdog, lidar_stale_ms,
           "The newest scan's turn ended longer ago: the drive is held at zero; a scan this late is not used."),
    DC_INT("watchdog", "chassis_stale_ms", "ms", 40, 10000, kBoth, watchdog, chassis_stale_ms,
           "No chassis feedback for longer: the drive is held at zero."),
    DC_INT("watchdog", "fault_after_ms", "ms", 0, 60000, kBoth, watchdog, fault_after_ms,
           "Stale this long after the hold began: fault 185 (lidar) or 184 (chassis)."),
    DC_INT("watchdog", "resume_after_ms", "ms", 0, 60000, kBoth, watchdog, resume_after_ms,
           "A dock or undock such a fault interrupted is issued again once both inputs are fresh this long."),
    DC_INT("watchdog", "max_resumes", "–", 0, 20, kBoth, watchdog, max_resumes,
           "Resumes per task; then the fault stays."),

    // [intensity]: IntensityCheckParams, whether the lidar's intensity is usable (docs/lidars.md, "Intensity check").
    DC_REAL("intensity", "flat_share", "–", 0.51, 1, kBoth, intensity, flat_share,
            "A scan is flat when at least this share of its returns read within ±`flat_band` of one value."),
    DC_REAL("intensity", "flat_band", "sensor units", 0, 1000, kBoth, intensity, flat_band,
            "Half-width of \"one value\" (LD06: 0–255, RPLIDAR quality: 0–63)."),
    DC_INT("intensity", "min_returns", "–", 1, 256, kBoth, intensity, min_returns,
           "Scans with fewer returns (of at most 256 sampled) are not judged."),
    DC_INT("intensity", "window_scans", "–", 1, 32, kBoth, intensity, window_scans,
           "Judged scans the verdict looks back on."),
    DC_REAL("intensity", "decide_share", "–", 0.51, 1, kBoth, intensity, decide_share,
            "The verdict (usable, flat, absent) changes when at least this share of the window agrees."),

    // [robot.deadband]: WheelDeadbandParams, the output shaping's wheel deadband (docs/architecture.md).
    DC_REAL("robot.deadband", "known_radps", "rad/s", 0, 20, kBoth, deadband, known_radps,
            "Wheel deadband the drive is known to have: slower commands are scaled up to it (0: none known)."),
    DC_BOOL("robot.deadband", "adapt", kBoth, deadband, adapt,
            "Learn a larger deadband per wheel and direction from commanded versus measured wheel speeds."),
    DC_REAL("robot.deadband", "max_radps", "rad/s", 0, 20, kBoth, deadband, max_radps,
            "Largest deadband learned: bounds how fast the slowest creep can become."),
    DC_INT("robot.deadband", "stall_ms", "ms", 50, 10000, kBoth, deadband, stall_ms,
           "A wheel turning at under a quarter of its command, or under nine tenths and slowing down, and not speeding "
           "up, this long in all (short stands add up) has stalled: its deadband grows by 25 %."),

    // [task]: TaskParams (docs/task-manager.md).
    DC_REAL("task", "detect_wait_s", "s", 0, 60, kBoth, task, detect_wait_s,
            "Stand still this long for a detection before swinging."),
    DC_DEG("task", "swing_amplitude_deg", 0, 180, kBoth, task, swing_amplitude_rad,
           "Swing to ±this about the start heading."),
    DC_REAL("task", "swing_speed_radps", "rad/s", 0.01, 3, kBoth, task, swing_speed_radps,
            "Swing rate (above the drive deadband)."),
    DC_INT("task", "max_swings", "–", 0, 20, kBoth, task, max_swings,
           "Full swings without a detection before fault 177."),
    DC_REAL("task", "target_lost_after_s", "s", 0.05, 60, kBoth, task, target_lost_after_s,
            "Estimate older than this: stop and wait."),
    DC_REAL("task", "target_lost_timeout_s", "s", 0.1, 600, kBoth, task, target_lost_timeout_s,
            "Lost this long: fault 181."),
    DC_REAL("task", "blind_finish_m", "m", 0, 1, kBoth, task, blind_finish_m,
            "The robot's edge this close to the dock's face: a confirmed estimate carried by odometry stays current."),
    DC_REAL("task", "blind_finish_max_s", "s", 0, 120, kBoth, task, blind_finish_max_s,
            "Longest the last stretch runs on odometry alone."),
    DC_REAL("task", "blind_approach_m", "m", 0.1, 10, kBoth, task, blind_approach_m,
            "The dock at least this far from the robot's edge: the estimate carried by odometry stays current for up "
            "to blind_approach_max_s."),
    DC_REAL("task", "blind_approach_max_s", "s", 0, 60, kBoth, task, blind_approach_max_s,
            "Longest the approach from afar runs on odometry alone; 0: off."),
    DC_DEG("task", "blind_off_axis_deg", 0, 180, kBoth, task, blind_off_axis_rad,
           "The robot this far off the dock's axis (bearing from its face): the estimate carried by odometry also "
           "stays current for up to blind_approach_max_s, however near; 180: off."),
    DC_REAL("task", "push_zone_m", "m", 0.01, 1, kBoth, task, push_zone_m,
            "The final push starts when the robot, lined up with the dock, has its edge this close to the face."),
    DC_REAL("task", "max_push_m", "m", 0.01, 5, kBoth, task, max_push_m,
            "Odometry distance the final push may travel without the contacts closing: retry, then fault 190."),
    DC_REAL("task", "max_push_s", "s", 0.5, 600, kBoth, task, max_push_s,
            "Time the final push may last without the contacts closing: retry, then fault 190."),
    DC_REAL("task", "retry_lateral_step_m", "m", 0, 0.1, kBoth, task, retry_lateral_step_m,
            "After two attempts that missed the contacts (188, 190), the next aim this much to one side, then the "
            "other, then twice as far; 0: off."),
    DC_BOOL("task", "remember_aim", kBoth, task, remember_aim,
            "The aim that closed the contacts is the next docking's first aim at that dock (the search runs around "
            "it); a docking that misses them to the end forgets it."),
    DC_BOOL("task", "calibrate_mount", kBoth, task, calibrate_mount,
            "After the first attempt of a docking that reached the dock without the contacts closing, turn on the "
            "spot at the staging distance, measure where the lidar sits sideways and move the mount in use by it."),
    DC_DEG("task", "calibration_swing_deg", 5, 90, kBoth, task, calibration_swing_rad,
           "The calibration swing turns to +this, to -this and back about the heading it starts from."),
    DC_REAL("task", "max_mount_correction_m", "m", 0.001, 0.1, kBoth, task, max_mount_correction_m,
            "Largest sideways move of the lidar mount a calibration swing may make; a larger measure changes nothing."),
    DC_REAL("task", "obstacle_timeout_s", "s", 0.1, 600, kBoth, task, obstacle_timeout_s,
            "Blocked this long: fault 180."),
    DC_BOOL("task", "turn_when_blocked", kBoth, task, turn_when_blocked,
            "A command whose translation an obstacle blocks keeps its turn when turning in place is free; the "
            "blocked time runs until a whole command passes again."),
    DC_REAL("task", "charge_current_threshold_a", "A", 0, 200, kBoth, task, charge_current_threshold_a,
            "Charging = contact and current at least this."),
    DC_REAL("task", "charge_confirm_hold_s", "s", 0, 60, kBoth, task, charge_confirm_hold_s,
            "Contact and current held this long confirm charging."),
    DC_REAL("task", "charge_confirm_timeout_s", "s", 0.1, 600, kBoth, task, charge_confirm_timeout_s,
            "No confirmation within this: retry."),
    DC_REAL("task", "contact_lost_debounce_s", "s", 0, 60, kBoth, task, contact_lost_debounce_s,
            "Contacts open this long while charging: fault 183."),
    DC_INT("task", "max_retries", "–", 0, 20, kBoth, task, max_retries,
           "Attempts after the first; then fault 182/188/190 with the robot backed off."),
    DC_REAL("task", "staging_distance_m", "m", 0.1, 10, kBoth, task, staging_distance_m,
            "Back off until the robot centre is this far from the dock."),
    DC_REAL("task", "fallback_backoff_m", "m", 0, 5, kBoth, task, fallback_backoff_m,
            "Without a dock estimate: back off this far on odometry."),
    DC_REAL("task", "backoff_speed_mps", "m/s", 0.01, 1, kBoth, task, backoff_speed_mps,
            "Backing speed (above the drive deadband)."),
    DC_REAL("task", "backoff_timeout_s", "s", 1, 600, kBoth, task, backoff_timeout_s,
            "Back-off not done in this time: fault (186 undocking)."),
    DC_REAL("task", "charge_off_timeout_s", "s", 0.1, 60, kBoth, task, charge_off_timeout_s,
            "Undock: current must stop within this, else fault 186."),
    DC_REAL("task", "task_timeout_s", "s", 1, 3600, kBoth, task, task_timeout_s,
            "Docking (GET_TASKING_CMD..WAIT_FOR_CHARGE) longer: fault 189."),
    DC_REAL("task", "check_distance_error_tolerance_m", "m", 0, 100, kBoth, task,
            deviation.check_distance_error_tolerance_m,
            "The robot may be at most this far from the dock during alignment (fault 178)."),
    DC_REAL("task", "push_distance_tolerance_m", "m", 0, 100, kBoth, task, deviation.push_distance_tolerance_m,
            "The dock seen by the lidar may lie at most this far from where odometry expects it (a push moves it: "
            "fault 178)."),
    DC_DEG("task", "check_angle_error_tolerance_deg", 0, 180, kBoth, task, deviation.check_angle_error_tolerance_rad,
           "The dock's yaw seen by the lidar may differ at most this much from where odometry expects it (fault 179)."),

    // [controller]: the settings every controller shares, then each controller's own table.
    [] {
      ParamSpec s = DC_COMMON("pad_reach_m", "m", 0.01, 3, kBoth, pad_reach_m, "Robot centre to the pads' centre.");
      s.dockd_table = "robot";
      s.default_text = "from the footprint";
      return s;
    }(),
    DC_COMMON("creep_speed_mps", "m/s", 0.001, 1, kBoth, creep_speed_mps, "Slowest approach speed (all controllers)."),
    DC_COMMON("stall_timeout_s", "s", 0.1, 60, kBoth, stall_timeout_s, "Pressed without contact this long: retry."),

    DC_COMMON_OF("controller.seed000", seed000),
    DC_REAL("controller.seed000", "angle_threshold_rad", "rad", 0, 3.2, kScenario, seed000, angle_threshold_rad,
            "Centre angle (absolute) below this ends the correction."),
    DC_REAL("controller.seed000", "rotate_exit_rad", "rad", 0, 3.2, kScenario, seed000, rotate_exit_rad,
            "In-place turn ends within this."),
    DC_REAL("controller.seed000", "rotate_kp", "1/s", 0, 100, kScenario, seed000, rotate_kp,
            "Yaw rate per rad of bearing."),
    DC_REAL("controller.seed000", "rotate_max_radps", "rad/s", 0, 20, kScenario, seed000, rotate_max_radps,
            "Fastest in-place turn."),
    DC_REAL("controller.seed000", "rotate_min_radps", "rad/s", 0, 20, kScenario, seed000, rotate_min_radps,
            "Slowest in-place turn (above the deadband)."),
    DC_REAL("controller.seed000", "forward_speed_mps", "m/s", 0.01, 2, kBoth, seed000, forward_speed_mps,
            "Seed 000 cruise."),
    DC_REAL("controller.seed000", "slowdown_distance_m", "m", 0, 10, kScenario, seed000, slowdown_distance_m,
            "Pad-to-contact distance where the speed starts to fall."),

    DC_COMMON_OF("controller.seed004", seed004),
    DC_REAL("controller.seed004", "angle_tolerance_rad", "rad", 0, 3.2, kScenario, seed004, angle_tolerance_rad,
            "Table 3 angle_tolerance."),
    DC_REAL("controller.seed004", "distance_tolerance_m", "m", 0, 10, kScenario, seed004, distance_tolerance_m,
            "Table 3 distance_tolerance."),
    DC_REAL("controller.seed004", "relative_distance_m", "m", 0, 10, kScenario, seed004, relative_distance_m,
            "Table 3 relative_distance_tolerance (centre to marker)."),
    DC_REAL("controller.seed004", "robot_distance_tolerance_m", "m", -10, 10, kScenario, seed004,
            robot_distance_tolerance_m, "Lateral correction skipped below; < 0: never."),
    DC_REAL("controller.seed004", "angle_kp", "1/s", 0, 100, kScenario, seed004, angle_kp,
            "Yaw rate per rad of heading error."),
    DC_REAL("controller.seed004", "distance_kp", "1/s", 0, 100, kScenario, seed004, distance_kp,
            "Speed per m of distance error."),
    DC_REAL("controller.seed004", "max_wz_radps", "rad/s", 0, 20, kScenario, seed004, max_wz_radps,
            "Fastest in-place turn."),
    DC_REAL("controller.seed004", "min_wz_radps", "rad/s", 0, 20, kScenario, seed004, min_wz_radps,
            "Slowest in-place turn."),
    DC_REAL("controller.seed004", "max_speed_mps", "m/s", 0.01, 2, kBoth, seed004, max_speed_mps,
            "Seed 004 top speed."),
    DC_REAL("controller.seed004", "min_speed_mps", "m/s", 0, 5, kScenario, seed004, min_speed_mps,
            "Slowest straight motion."),
    DC_REAL("controller.seed004", "final_speed_mps", "m/s", 0, 5, kScenario, seed004, final_speed_mps,
            "Fastest FINAL_APPROACH speed."),
    DC_REAL("controller.seed004", "final_heading_kp", "1/s", 0, 100, kScenario, seed004, final_heading_kp,
            "FINAL_APPROACH heading hold."),

    DC_COMMON_OF("controller.seed003", seed003),
    DC_REAL("controller.seed003", "fx_px", "px", 1, 10000, kDockd, seed003, camera.fx_px,
            "Camera focal length (a scenario's camera is `[robot.camera]`)."),
    DC_REAL("controller.seed003", "cx_px", "px", 0, 10000, kDockd, seed003, camera.cx_px, "Camera principal point."),
    DC_REAL("controller.seed003", "image_width_px", "px", 1, 20000, kDockd, seed003, camera.image_width_px,
            "Camera image width."),
    DC_REAL("controller.seed003", "mount_x_m", "m", -2, 2, kDockd, seed003, camera.mount.x_m, "Camera mount x."),
    DC_REAL("controller.seed003", "mount_y_m", "m", -2, 2, kDockd, seed003, camera.mount.y_m, "Camera mount y."),
    DC_DEG("controller.seed003", "mount_yaw_deg", -180, 180, kDockd, seed003, camera.mount.yaw_rad,
           "Camera mount yaw."),
    [] {
      ParamSpec s = DC_BOOL("controller.seed003", "holonomic", kScenario, seed003, holonomic,
                            "Mecanum: the X loop drives vy; otherwise it is folded into wz.");
      s.default_text = "kinematics = \"mecanum\"";
      return s;
    }(),
    DC_INT("controller.seed003", "window", "samples", 1, static_cast<double>(kSeed003MaxWindow), kScenario, seed003,
           window, "Sliding window length."),
    DC_REAL("controller.seed003", "ema_alpha", "–", 0, 1e4, kScenario, seed003, ema_alpha,
            "Filter weight of the raw sample."),
    DC_REAL("controller.seed003", "stage_switch_m", "m", 0, 1e4, kScenario, seed003, stage_switch_m,
            "Stage 1 while the filtered depth exceeds this."),
    DC_REAL("controller.seed003", "stage1_kw", "rad/s/px", 0, 1e4, kScenario, seed003, stage1_kw, "Stage 1 yaw gain."),
    DC_REAL("controller.seed003", "stage1_max_wz_radps", "rad/s", 0, 1e4, kScenario, seed003, stage1_max_wz_radps,
            "Stage 1 yaw-rate cap."),
    DC_REAL("controller.seed003", "stage1_kv", "1/s", 0, 1e4, kScenario, seed003, stage1_kv, "Stage 1 speed gain."),
    DC_REAL("controller.seed003", "stage1_target_m", "m", 0, 1e4, kScenario, seed003, stage1_target_m,
            "Stage 1 depth target."),
    DC_REAL("controller.seed003", "stage1_max_vx_mps", "m/s", 0, 1e4, kScenario, seed003, stage1_max_vx_mps,
            "Stage 1 speed cap."),
    DC_REAL("controller.seed003", "goal_z_m", "m", 0, 1e4, kScenario, seed003, goal_z_m, "Stage 2 depth goal."),
    DC_REAL("controller.seed003", "z_kp", "1/s", 0, 1e4, kScenario, seed003, z_kp, "Depth PD: P."),
    DC_REAL("controller.seed003", "z_kd", "–", 0, 1e4, kScenario, seed003, z_kd, "Depth PD: D (per seed_period_s)."),
    DC_REAL("controller.seed003", "z_max_mps", "m/s", 0, 1e4, kScenario, seed003, z_max_mps, "Depth PD: cap."),
    DC_REAL("controller.seed003", "x_kp", "1/s", 0, 1e4, kScenario, seed003, x_kp, "Lateral PD: P."),
    DC_REAL("controller.seed003", "x_kd", "–", 0, 1e4, kScenario, seed003, x_kd, "Lateral PD: D (per seed_period_s)."),
    DC_REAL("controller.seed003", "x_max_mps", "m/s", 0, 1e4, kScenario, seed003, x_max_mps, "Lateral PD: cap."),
    DC_REAL("controller.seed003", "u_kp", "rad/s/px", 0, 1e4, kScenario, seed003, u_kp, "Image-column PD: P."),
    DC_REAL("controller.seed003", "u_kd", "rad/s/px", 0, 1e4, kScenario, seed003, u_kd,
            "Image-column PD: D (per seed_period_s)."),
    DC_REAL("controller.seed003", "u_max_radps", "rad/s", 0, 1e4, kScenario, seed003, u_max_radps,
            "Image-column PD: cap."),
    DC_REAL("controller.seed003", "seed_period_s", "s", 0, 1e4, kScenario, seed003, seed_period_s,
            "The seed's loop period the kd gains refer to."),
    DC_REAL("controller.seed003", "success_z_m", "m", 0, 1e4, kScenario, seed003, success_z_m,
            "Seed success: depth error below this ..."),
    DC_REAL("controller.seed003", "success_x_m", "m", 0, 1e4, kScenario, seed003, success_x_m,
            "... lateral error below this ..."),
    DC_REAL("controller.seed003", "success_u_px", "px", 0, 1e4, kScenario, seed003, success_u_px,
            "... column error below this ..."),
    DC_REAL("controller.seed003", "success_hold_s", "s", 0, 1e4, kScenario, seed003, success_hold_s,
            "... held this long."),
    DC_REAL("controller.seed003", "blind_zone_m", "m", 0, 1e4, kScenario, seed003, blind_zone_m,
            "Filtered depth below this disables the depth PD."),
    DC_REAL("controller.seed003", "target_timeout_s", "s", 0, 1e4, kScenario, seed003, target_timeout_s,
            "Camera target older than this counts as lost."),
    DC_REAL("controller.seed003", "final_speed_mps", "m/s", 0, 1e4, kScenario, seed003, final_speed_mps,
            "FINAL_APPROACH creep (≥ creep_speed_mps)."),
    DC_REAL("controller.seed003", "final_max_travel_m", "m", 0, 1e4, kScenario, seed003, final_max_travel_m,
            "FINAL_APPROACH gives up after this much travel without contact."),

    DC_COMMON_OF("controller.smooth", smooth),
    [] {
      ParamSpec s =
          DC_BOOL("controller.smooth", "backwards", kScenario, smooth, backwards, "Dock backwards (rear pads).");
      s.default_text = "pads = \"rear\"";
      return s;
    }(),
    DC_REAL("controller.smooth", "k_phi", "–", 0, 1e4, kScenario, smooth, k_phi, "Graceful law: heading gain."),
    DC_REAL("controller.smooth", "k_delta", "–", 0, 1e4, kScenario, smooth, k_delta, "Graceful law: steering gain."),
    DC_REAL("controller.smooth", "beta", "–", 0, 1e4, kScenario, smooth, beta, "Curvature slow-down: scale."),
    DC_REAL("controller.smooth", "lambda", "–", 0, 1e4, kScenario, smooth, lambda, "Curvature slow-down: exponent."),
    DC_REAL("controller.smooth", "v_max_mps", "m/s", 0.01, 2, kBoth, smooth, v_max_mps, "Cruise speed."),
    DC_REAL("controller.smooth", "w_max_radps", "rad/s", 0.05, 5, kBoth, smooth, w_max_radps, "Yaw-rate cap."),
    DC_REAL("controller.smooth", "slowdown_radius_m", "m", 0, 3, kBoth, smooth, slowdown_radius_m, "Slow-down radius."),
    DC_REAL("controller.smooth", "max_decel_mps2", "m/s²", 0, 1e4, kScenario, smooth, max_decel_mps2,
            "Braking profile towards the contact plane."),
    DC_REAL("controller.smooth", "goal_projection_m", "m", 0, 1, kBoth, smooth, goal_projection_m,
            "Goal behind the docked pose."),
    DC_REAL("controller.smooth", "min_turn_speed_mps", "m/s", 0, 1e4, kScenario, smooth, min_turn_speed_mps,
            "Smallest forward speed when ω saturates."),
    DC_REAL("controller.smooth", "min_turn_rate_radps", "rad/s", 0, 5, kBoth, smooth, min_turn_rate_radps,
            "Slowest turn along a tight curve, towards a confirmed estimate outside the line-up zone (0: off)."),
    DC_REAL("controller.smooth", "lineup_distance_m", "m", 0, 2, kBoth, smooth, lineup_distance_m,
            "Axis tracker range (0 disables)."),
    DC_REAL("controller.smooth", "lineup_engage_lateral_m", "m", 0, 1e4, kScenario, smooth, lineup_engage_lateral_m,
            "Axis tracker engages with the centre this near the axis ..."),
    DC_REAL("controller.smooth", "lineup_engage_heading_rad", "rad", 0, 1e4, kScenario, smooth,
            lineup_engage_heading_rad, "... and the heading this near the docked heading."),
    DC_REAL("controller.smooth", "lineup_hysteresis_m", "m", 0, 1e4, kScenario, smooth, lineup_hysteresis_m,
            "Axis tracker left only beyond lineup_distance_m + this."),
    DC_REAL("controller.smooth", "lineup_margin_m", "m", 0, 1e4, kScenario, smooth, lineup_margin_m,
            "Path meets the axis this far before the contact plane."),
    DC_REAL("controller.smooth", "lineup_horizon_min_m", "m", 0, 1e4, kScenario, smooth, lineup_horizon_min_m,
            "Shortest planning horizon."),
    DC_REAL("controller.smooth", "lineup_lateral_horizon_min_m", "m", 0, 1e4, kScenario, smooth,
            lineup_lateral_horizon_min_m, "Shortest horizon of the lateral term."),
    DC_REAL("controller.smooth", "lineup_max_curvature_inv_m", "1/m", 0, 1e4, kScenario, smooth,
            lineup_max_curvature_inv_m, "Largest path curvature."),
};

#undef DC_REAL
#undef DC_DEG
#undef DC_INT
#undef DC_BOOL
#undef DC_COMMON
#undef DC_COMMON_OF

/// `v` as the docs write it: an integer in full, otherwise at most 6 significant digits.
std::string number_text(double v) {
  std::ostringstream s;
  if (v == std::floor(v) && std::fabs(v) < 1e15) {
    s << static_cast<long long>(v);  // bounds such as 1000000 in full
  } else {
    s.precision(6);
    s << v;
  }
  return s.str();
}

/// A range bound for the docs: −20 with a proper minus sign.
std::string bound_text(double v) {
  std::string s = number_text(v);
  if (!s.empty() && s[0] == '-') s = "−" + s.substr(1);
  return s;
}

}  // namespace

const ParamSpec* param_table(std::size_t& count) {
  count = sizeof(kTable) / sizeof(kTable[0]);
  return kTable;
}

const char* table_of(const ParamSpec& s, ParamUse use) {
  return use == kDockd && s.dockd_table != nullptr ? s.dockd_table : s.table;
}

const ParamSpec* find_param(const std::string& table, const std::string& key, ParamUse use) {
  for (const ParamSpec& s : kTable) {
    if ((s.use & use) != 0 && table == table_of(s, use) && key == s.key) return &s;
  }
  return nullptr;
}

std::string choice_word(const ParamSpec& s, std::size_t index) {
  if (s.choices == nullptr) return {};
  const char* p = s.choices;
  for (std::size_t i = 0; i < index; ++i) {
    p = std::strchr(p, '|');
    if (p == nullptr) return {};
    ++p;
  }
  const char* end = std::strchr(p, '|');
  return end == nullptr ? std::string(p) : std::string(p, static_cast<std::size_t>(end - p));
}

std::size_t choice_count(const ParamSpec& s) {
  if (s.choices == nullptr) return 0;
  std::size_t n = 1;
  for (const char* p = s.choices; *p != '\0'; ++p) n += *p == '|' ? 1 : 0;
  return n;
}

void apply_defaults(const ParamTargets& t, ParamUse use) {
  if (use != kScenario) return;
  for (const ParamSpec& s : kTable) {
    if ((s.use & kScenario) != 0 && !std::isnan(s.scenario_default)) s.set(t, s.scenario_default);
  }
}

std::string markdown_table(const std::string& table, ParamUse use) {
  DriveGeometry drive;
  DriveLimits limits;
  FootprintParams footprint;
  TaskParams task;
  EstimatorParams estimator;
  Seed000Params seed000;
  Seed004Params seed004;
  Seed003Params seed003;
  SmoothParams smooth;
  TagFusionParams tag_fusion;
  WatchdogParams watchdog;
  WheelDeadbandParams deadband;
  DockDetector detector = DockDetector::kEstimator;
  IntensityCheckParams intensity;
  const ParamTargets defaults{&drive,   &limits, &footprint,  &task,     &estimator, &seed000,  &seed004,
                              &seed003, &smooth, &tag_fusion, &watchdog, &deadband,  &detector, &intensity};
  apply_defaults(defaults, use);
  std::ostringstream out;
  bool any = false;
  for (const ParamSpec& s : kTable) {
    if ((s.use & use) == 0 || table != table_of(s, use)) continue;
    if (!any) out << "| key | unit | default | range / values | meaning |\n|---|---|---|---|---|\n";
    any = true;
    std::string def, range;
    switch (s.type) {
      case ParamType::kBool:
        def = s.get(defaults) != 0 ? "true" : "false";
        range = "`true`, `false`";
        break;
      case ParamType::kChoice: {
        def = "`\"" + choice_word(s, static_cast<std::size_t>(s.get(defaults))) + "\"`";
        for (std::size_t i = 0; i < choice_count(s); ++i) range += (i == 0 ? "`" : ", `") + choice_word(s, i) + "`";
        break;
      }
      default:
        def = number_text(s.get(defaults));
        range = bound_text(s.min) + "–" + bound_text(s.max);
        break;
    }
    if (s.default_text != nullptr) def = s.default_text;
    out << "| `" << s.key << "` | " << s.unit << " | " << def << " | " << range << " | " << s.meaning << " |\n";
  }
  return out.str();
}

std::string update_param_blocks(const std::string& text, std::string& error) {
  const std::string kOpen = "<!-- params ", kClose = "<!-- /params -->";
  std::string out;
  std::size_t pos = 0;
  error.clear();
  while (true) {
    const std::size_t open = text.find(kOpen, pos);
    if (open == std::string::npos) break;
    const std::size_t open_end = text.find("-->", open);
    const std::size_t line_end = text.find('\n', open);
    if (open_end == std::string::npos || line_end == std::string::npos || open_end > line_end) {
      error = "unterminated '<!-- params' marker";
      return text;
    }
    std::istringstream words(text.substr(open + kOpen.size(), open_end - open - kOpen.size()));
    std::string who, table, extra;
    words >> who >> table >> extra;
    const ParamUse use = who == "dockd" ? kDockd : kScenario;
    if ((who != "dockd" && who != "scenario") || table.empty() || !extra.empty()) {
      error = "marker '" + text.substr(open, open_end + 3 - open) + "': expected <!-- params dockd|scenario TABLE -->";
      return text;
    }
    const std::string body = markdown_table(table, use);
    if (body.empty()) {
      error = "marker names table '" + table + "', which has no " + who + " parameters";
      return text;
    }
    const std::size_t close = text.find(kClose, line_end);
    if (close == std::string::npos) {
      error = "marker for '" + table + "' without '" + kClose + "'";
      return text;
    }
    out += text.substr(pos, line_end + 1 - pos);
    out += body;
    pos = close;
  }
  out += text.substr(pos);
  return out;
}

void derive_from_robot(const RobotFacts& r, const ParamTargets& t) {
  if (r.pad_reach_m >= 0) {
    const Real reach = static_cast<Real>(r.pad_reach_m);
    t.seed000->common.pad_reach_m = t.seed004->common.pad_reach_m = reach;
    t.seed003->common.pad_reach_m = t.smooth->common.pad_reach_m = reach;
  }
  if (!r.holonomic_given) t.seed003->holonomic = r.mecanum;
  if (!r.backwards_given) t.smooth->backwards = r.pads_rear;
  t.task->pads_rear = r.pads_rear;
  t.task->charger_switched = r.charger_switched;
  const DriveLimits& l = *t.limits;
  if (l.max_vx_mps > 0) t.task->max_vx_mps = l.max_vx_mps;
  if (l.max_vy_mps > 0) t.task->max_vy_mps = l.max_vy_mps;
  if (l.max_wz_radps > 0) t.task->max_wz_radps = l.max_wz_radps;
}

}  // namespace dockcore::params
