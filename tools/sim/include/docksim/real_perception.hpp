#pragma once
// Dock-detector measurements on real recordings (docksim/realdata.hpp): false positives on the dock-less scans,
// single-scan and confirmed over consecutive scans, and composite scenes, a dock ray-cast into a real scan.
// Uses only the estimator's public API (configure, estimate, counters). Host-side; deterministic for a given seed.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/dock_pose_estimator.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "docksim/estimator_overrides.hpp"
#include "docksim/realdata.hpp"
#include "docksim/rng.hpp"

namespace docksim {

/// The estimator's parameters for a recording: estimator_params_for_noise(rec.sigma_m) with `overrides` applied.
/// O(1).
dockcore::EstimatorParams real_estimator_params(const RealRecording& rec, const EstimatorOverrides& overrides = {});

/// When consecutive single-scan detections count as one confirmed detection.
struct ConfirmRule {
  /// Consecutive scans of a window (a tracker's acquisition). The first is searched without a hint; each later one
  /// with the first detection, carried into that scan's sensor frame by the poses, as the hint (what a tracker
  /// does; it makes re-finding the same object likelier, so the rate is not flattered).
  int scans = 3;
  /// Every later detection lies within this distance and yaw of the first, both mapped into the world frame.
  double agree_m = 0.05;
  double agree_rad = 5.0 * dockcore::kPi / 180.0;
  /// PoseSource::kStatic: a window only spans scans whose stamps are at most this far apart (the sensor may have
  /// been moved between captures).
  double static_max_gap_s = 1.0;
};

/// In which frame detections of a window were compared.
enum class ConfirmFrame : std::uint8_t {
  kNone = 0,  ///< No poses: single-scan figures only.
  kWorld,     ///< Through the recording's robot poses.
  kSensor,    ///< Standing sensor (PoseSource::kStatic).
};

/// Name of a ConfirmFrame ("none", "world", "sensor"). Never null.
const char* to_string(ConfirmFrame f);

/// A false dock: where it was found.
struct FalseDock {
  std::size_t scan = 0;  ///< 0-based index of the scan in the recording (= line - 1 when no line was skipped).
  dockcore::Pose2 pose;  ///< In the sensor frame.
};

/// False positives of one profile on one dock-less recording.
struct RealFpResult {
  std::size_t scans = 0;  ///< Scans run.
  std::size_t found = 0;  ///< Scans where the estimator reported a dock (every one is false).
  ConfirmFrame frame = ConfirmFrame::kNone;
  std::size_t windows = 0;                    ///< Confirmation opportunities: windows of rule.scans consecutive scans.
  std::size_t attempts = 0;                   ///< Windows whose first scan found a dock (the others cannot confirm).
  std::size_t confirmed = 0;                  ///< Windows whose detections all agreed (each is a confirmed false dock).
  /// Of those, windows whose detections' evidence also adds up to DockFilterParams::confirm_evidence_nats: what the
  /// dock filter's sequential test (DockPoseFilter::confirmed) would confirm from those scans.
  std::size_t confirmed_sequential = 0;
  std::vector<FalseDock> examples;            ///< The first kMaxFalseDockExamples false docks.
  std::vector<std::size_t> confirmed_starts;  ///< First scan of the first kMaxFalseDockExamples confirmed windows.
  /// The estimator's counters after the single-scan pass (candidates, rejections by reason).
  dockcore::EstimatorCounters counters{};
};

constexpr std::size_t kMaxFalseDockExamples = 8;

/// Runs the estimator (real_estimator_params, lidar at the origin, no hint) on every scan of `rec`: single-scan
/// false positives, then, when the recording has poses, the confirmation windows of `rule` over scans i..i+scans-1.
/// Cost: one estimate per scan, plus rule.scans-1 hinted estimates per window whose first scan found a dock.
RealFpResult measure_real_false_positives(const LoadedRecording& rec, const dockcore::DockProfile& profile,
                                          const ConfirmRule& rule = ConfirmRule{},
                                          const EstimatorOverrides& overrides = {});

// ---------------------------------------------------------------- reflective clutter

/// Reflective things pasted into real dock-less scans, to measure what a reflector dock's intensity cue meets in a
/// real room. Per confirmation window (its first scan i), 1..objects_max objects are placed in scan i's free space
/// (the real return at their bearing lies at least 0.3 m beyond them, or there is none), min..max_range_m from the
/// lidar, each kind equally likely:
///  - a sign: a flat board 0.2-0.6 m long facing the lidar within ±40°, taped all over (one in three) or with 1-3
///    stripes 3-15 cm long;
///  - a safety vest: a torso, a 12-sided circle of radius 0.15-0.2 m whose band the scan plane crosses (all retro);
///  - chrome legs: four 8-sided legs of radius 1-1.5 cm at the corners of a 0.40-0.50 m square, retro within 12° of
///    their normal only (a mirror returns the beam only when met head on).
/// The objects stand in the world (the window's first sensor pose) and are ray-cast into every scan of the window;
/// pasted ranges get the recording's noise (RangeNoise).
/// Every real return gets an LD06 intensity, rounded to 0-255: 255·ρ·|cos i|/(1 + (r/4 m)²), incidence i from the
/// line through its neighbours (head on when they are not on one surface), reflectivity ρ uniform 0.1-1.0 per 0.5 m
/// cell of the world (a surface reads alike from scan to scan). So a white wall met head on within ~0.6 m reads
/// past the reflector threshold as tape would.
struct ReflectiveClutterOptions {
  std::uint64_t seed = 1;
  int objects_max = 3;  ///< 0: no objects, the real returns' intensities only.
  double min_range_m = 0.4;
  double max_range_m = 2.5;
  EstimatorOverrides overrides{};  ///< Applied to the estimators' parameters (stripe_hypotheses among them).
};

/// measure_real_false_positives for a profile with reflector stripes on a lidar whose intensity is usable
/// (set_intensity_usable(true)), the scans carrying intensities and reflective clutter as ReflectiveClutterOptions
/// says. Deterministic in (options.seed, recording, window). Cost: as measure_real_false_positives plus O(beams ·
/// pasted segments) per scan.
RealFpResult measure_real_reflector_false_positives(const LoadedRecording& rec, const dockcore::DockProfile& profile,
                                                    const ReflectiveClutterOptions& options,
                                                    const ConfirmRule& rule = ConfirmRule{});

// ---------------------------------------------------------------- composite scenes

/// Where a pasted dock stands.
enum class CompositeKind : std::uint8_t {
  kWallFlush = 0,  ///< Back plane (the profile's smallest x) on a straight wall stretch of the scan.
  kWallGap,        ///< Back plane a gap in front of the wall (CompositeSiteParams::gap_*).
  kFreeStanding,   ///< In open floor: the beams around it see far beyond it (or nothing).
};
constexpr int kCompositeKinds = 3;

/// Name of a CompositeKind ("wall-flush", "wall-gap", "free-standing"). Never null.
const char* to_string(CompositeKind k);

/// Range noise of a recording, for pasted beams: r -> round_to(r + N(0, sqrt(max(0, σ² - res²/12))), res). The
/// quantisation's own ±res/2 uniform error (res²/12 variance) is part of the σ measured on the real walls.
struct RangeNoise {
  double sigma_m = 0.01;
  double resolution_m = 0;  ///< 0: no quantisation.
  double apply(double range_m, Rng& rng) const;
};

/// How composite sites are chosen.
struct CompositeSiteParams {
  double min_range_m = 0.3;  ///< Wall returns used, and the dock's distance: 0.3-2.0 m from the lidar.
  double max_range_m = 2.0;
  double margin_m = 0.10;  ///< Wall kept beyond each end of the dock (what the estimator's wall check sees).
  double max_incidence_rad = 60.0 * dockcore::kPi / 180.0;  ///< Dock face seen at most this obliquely.
  double gap_min_m = 0.02;                                  ///< kWallGap: the gap is uniform in [gap_min_m, gap_max_m].
  double gap_max_m = 0.08;
  double free_min_m = 0.5;  ///< kFreeStanding: distance uniform in [free_min_m, free_max_m],
  double free_max_m = 1.8;
  double free_yaw_rad = 30.0 * dockcore::kPi / 180.0;  ///< ... yaw within ± this of facing the lidar,
  double free_behind_m = 1.0;  ///< ... and every beam of its span (± margin beams) sees this far past it (or nothing).
  std::size_t margin_beams = 3;  ///< Beams beyond each side of the dock's span that must be clear too.
  int attempts = 20;             ///< Random positions tried per scan.
};

/// A dock placement in a scan's sensor frame.
struct CompositeSite {
  CompositeKind kind = CompositeKind::kWallFlush;
  dockcore::Pose2 dock_in_sensor;
  double gap_m = 0;  ///< Back plane to wall (wall kinds).
};

/// Finds a clean site for `profile` in `scan`: for the wall kinds, a line segment (core extract_line_segments on
/// the returns min..max_range_m away, thresholds scaled to sigma_m) long enough for the dock plus margin_m each side
/// and fitted to ~2σ, a random position on it with the dock's x axis along the wall normal; for kFreeStanding, a
/// random distance / bearing / yaw whose beams see free_behind_m past the dock. A site counts only when the dock is
/// within range and incidence, wholly inside the scan's field of view, and no return lies in front of it (nothing
/// would occlude it). Returns false when none of `attempts` tries works. Cost O(beams) per try plus one segment
/// extraction.
bool find_composite_site(const dockcore::ScanView& scan, const dockcore::DockProfile& profile, CompositeKind kind,
                         double sigma_m, const CompositeSiteParams& params, Rng& rng, CompositeSite* out);

/// Copies `background` into `out` and pastes the dock: every beam the placed profile catches (core
/// PlacedProfile::raycast, nearer than the background return or where there was none) gets noise.apply(dock range)
/// and intensity 0, hiding what lay behind. Returns the beams replaced; *occluded (if given) counts beams the dock
/// would catch whose background return is nearer than the dock by more than max(4σ, res, 2 cm) (they keep it).
/// O(beams · profile segments).
std::size_t paste_dock(const dockcore::ScanView& background, const dockcore::DockProfile& profile,
                       const dockcore::Pose2& dock_in_sensor, const RangeNoise& noise, Rng& rng,
                       dockcore::LaserScan* out, std::size_t* occluded = nullptr);

/// The dock as installed for a composite kind: wall kinds get mounting kWall (gap 0-0.10 m) and the default
/// kFreeStanding gets mounting kFreeStanding. Params are
/// real_estimator_params(rec, overrides) otherwise. O(1).
void composite_installation(const RealRecording& rec, CompositeKind kind, dockcore::DockProfile* profile,
                            dockcore::EstimatorParams* params, const EstimatorOverrides& overrides = {});

struct CompositeOptions {
  std::size_t per_cell = 100;  ///< Composites per (recording, profile, kind), at most one per scan.
  std::uint64_t seed = 1;
  double match_m = 0.10;  ///< A detection within this distance and yaw of the truth is the pasted dock;
  double match_rad = 10.0 * dockcore::kPi / 180.0;  ///< farther it is a wrong dock.
  CompositeSiteParams site{};
  EstimatorOverrides overrides{};  ///< Applied to the estimator's parameters.
};

/// Composite results of one (recording, profile, kind).
/// Upper edges (degrees) of the view-angle bins of CompositeResult: 0-30° (the detection targets' envelope), 30-45°,
/// 45-60° (the wall sites' max_incidence_rad).
constexpr int kCompositeViewBins = 3;
constexpr double kCompositeViewBinDeg[kCompositeViewBins] = {30.0, 45.0, 60.0};

struct CompositeResult {
  std::size_t scans_tried = 0;             ///< Scans looked at for a site.
  std::size_t no_site = 0;                 ///< Of which had no clean site.
  std::size_t placed = 0;                  ///< Composites run.
  std::size_t detected = 0;                ///< Found within match_m / match_rad of the truth.
  std::size_t wrong = 0;                   ///< Found elsewhere.
  std::size_t missed = 0;                  ///< Not found.
  /// By how far the dock's face is turned from facing the lidar (kCompositeViewBinDeg): composites placed and
  /// detected. A dock seen further off its axis shows less of itself (a 90° notch beyond 45° shows one arm).
  std::size_t placed_by_view[kCompositeViewBins] = {};
  std::size_t detected_by_view[kCompositeViewBins] = {};
  std::vector<double> pos_err_m;           ///< Of the detected ones.
  std::vector<double> yaw_err_rad;         ///< Of the detected ones.
  std::vector<double> wrong_pos_err_m;     ///< Of the wrong ones: how far from the truth (near miss or elsewhere).
  dockcore::EstimatorCounters counters{};  ///< The estimator's, over this cell's composites.
};

/// Pastes `profile` into up to per_cell scans of `rec` (visited in a seeded random order, one site per scan) and runs
/// the estimator installed as composite_installation says, lidar at the origin, no hint. The seed is mixed with the
/// recording, profile and kind, so every cell is reproducible on its own. Cost: one segment extraction and one
/// estimate per composite, plus site searches.
CompositeResult measure_real_composites(const LoadedRecording& rec, const dockcore::DockProfile& profile,
                                        CompositeKind kind, const CompositeOptions& options = CompositeOptions{});

}  // namespace docksim
