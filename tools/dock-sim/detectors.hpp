#pragma once
// Runs dockcore's three dock detectors on one scan with uniform results; shared by `detect` and `scene`
// (implemented in detect.cpp).
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/breakpoint_detector.hpp"
#include "dockcore/perception/dock_pose_estimator.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "dockcore/perception/line_segments.hpp"
#include "dockcore/perception/vmarker_detector.hpp"

namespace docksim_cli {

enum class Detector { kEstimator, kBreakpoint, kVMarker };

/// "estimator", "breakpoint", "vmarker".
const char* detector_name(Detector d);

/// "all" -> every detector; otherwise one name. Throws std::invalid_argument for anything else.
std::vector<Detector> parse_detectors(const std::string& s);

/// "x,y,yaw" (metres, metres, radians) -> pose. Throws std::invalid_argument with a message.
dockcore::Pose2 parse_pose_csv(const std::string& s);

/// One detector's answer for one scan. Poses are in the robot frame (the lidar mount's parent frame).
struct DetectorResult {
  Detector detector = Detector::kEstimator;
  bool applicable = true;   ///< false: the detector cannot look for this profile (see reason).
  std::string reason;       ///< Why not applicable.
  bool found = false;
  std::string status;       ///< The detector's own status name.
  bool has_yaw = true;      ///< The breakpoint detector gives a position only.
  dockcore::Pose2 pose;     ///< Valid when found (yaw only when has_yaw).
  nlohmann::ordered_json quality = nlohmann::ordered_json::object();  ///< Detector-specific figures.
};

/// The detectors, configured once for a profile. Large (the estimator holds ~100 kB of buffers): keep one per run,
/// on the heap (it allocates its members itself).
class DetectorSet {
 public:
  /// `which`: the detectors to run, in output order. The breakpoint detector applies only to the built-in
  /// "breakpoint" outline, the V-marker detector only to 3-vertex concave V profiles; otherwise their results say
  /// not applicable. Throws std::runtime_error when the estimator refuses the profile.
  DetectorSet(const dockcore::DockProfile& profile, const dockcore::EstimatorParams& params,
              const std::vector<Detector>& which);
  ~DetectorSet();

  /// Runs every selected detector on `scan`; `mount` is the lidar's pose in the robot frame.
  std::vector<DetectorResult> run(const dockcore::ScanView& scan, const dockcore::Pose2& mount);

  const dockcore::DockProfile& profile() const { return profile_; }

 private:
  DetectorResult run_estimator(const dockcore::ScanView& scan, const dockcore::Pose2& mount);
  DetectorResult run_breakpoint(const dockcore::ScanView& scan, const dockcore::Pose2& mount);
  DetectorResult run_vmarker(const dockcore::ScanView& scan, const dockcore::Pose2& mount);

  dockcore::DockProfile profile_;
  dockcore::EstimatorParams params_;
  std::vector<Detector> which_;
  std::unique_ptr<dockcore::DockPoseEstimator> estimator_;
  std::unique_ptr<dockcore::BreakpointDetector> breakpoint_;
  bool breakpoint_applicable_ = false;
  dockcore::VMarkerDetector vmarker_;
  dockcore::VMarkerError vmarker_error_ = dockcore::VMarkerError::kOk;
  std::unique_ptr<dockcore::ScanPoints> points_;
  std::unique_ptr<dockcore::LineSegments> segments_;
};

/// Rounds to 6 decimals (µm / µrad) for printing.
double round6(double v);

/// Appends the result's JSON fields to `j` (an object, possibly with leading fields) and returns it: detector,
/// [applicable, reason,] found, x_m, y_m, yaw_rad (null when not found / no yaw), quality.
nlohmann::ordered_json result_json(const DetectorResult& r,
                                   nlohmann::ordered_json j = nlohmann::ordered_json::object());

}  // namespace docksim_cli
