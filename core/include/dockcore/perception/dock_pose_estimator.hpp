#pragma once
/// @file DockPoseEstimator: the product's dock detector. Full dock pose (x, y, yaw) in the robot frame with a quality
/// report, for any DockProfile.
///
/// Pipeline per scan (all in the lidar frame, converted to the robot frame at the end):
///  1. Candidates. With a pose hint (the tracker's prediction, or a configured dock pose) the hint is tried first.
///     Otherwise (or when the hint fails) line segments of the scan are matched to the profile's long segments: each
///     pairing of a scan segment with a profile segment of similar length, facing the lidar, gives up to three pose
///     hypotheses (centres aligned, or either end aligned for a partly hidden segment). A dock with reflector stripes,
///     on a lidar whose intensity is usable, can also get hypotheses from the scan's bright runs, refined whatever
///     their prescore (stripe_hypotheses; at most kMaxStripeHypotheses).
///  2. Registration. Point-to-segment Gauss-Newton on (x, y, yaw) with Huber then Tukey weights, over the beams
///     inside the dock's angular span (plus a margin), associating each point with the nearest visible profile
///     segment.
///  3. Decision. The expected scan of the profile at the refined pose is compared beam by beam with the measured one,
///     and each candidate gets a log-likelihood ratio (nats): how much better "this dock at this pose" explains the
///     beams than "no dock here". It is a sum of cues (EvidenceCue), each reported: the fit of the beams that land on
///     the dock, beams that see through it, surfaces in the free space in front of it, the support of each feature,
///     surfaces that carry on past the dock's edges (a real dock stops where its outline stops), the wall behind it
///     (as the dock's mounting says: required, evidence when seen, or not looked for) and the pose prior (hint). A
///     candidate is accepted when the sum reaches min_evidence_nats. A few structural checks stay hard (too few
///     beams, out of range, seen edge-on, pose too uncertain, outside the hint radius).
///  4. Selection among accepted candidates: one whose evidence is far stronger (kSelectMarginNats) wins; otherwise
///     the nearest to the lidar, or the nearest to the hint.
///
/// Cost: tracking (a hint that holds) reads only the beams in the dock's span: O(I · W · S) with I <= max_iterations,
/// W beams in the span, S visible profile segments (most beams keep their segment between iterations). A global
/// search adds O(B) for the B beams (points, segmentation, hypotheses) and refines at most max_candidates
/// candidates (and at most kMaxStripeHypotheses more for a dock with stripes). The beam directions cost O(B) only when
/// the scan geometry changes. No heap: the working buffers are DockPoseEstimatorN's, sized by its beam capacity
/// (docs/architecture.md gives the sizes).

#include <cstddef>
#include <cstdint>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "dockcore/perception/line_segments.hpp"
#include "dockcore/perception/profile_geometry.hpp"

namespace dockcore {

/// How to pick one dock when several verify.
enum class DockSelect : std::uint8_t {
  kNearest = 0,  ///< Smallest distance from the lidar.
  kHint = 1,     ///< Closest to the pose hint (falls back to nearest when no hint is given).
};

/// Why an estimate was not produced (or kOk).
enum class EstimateStatus : std::uint8_t {
  kOk = 0,
  kNoProfile,         ///< configure() was not called with a valid profile.
  kNoPoints,          ///< No valid returns within range.
  kNoCandidates,      ///< No scan feature resembles the profile.
  kNotVerified,       ///< Candidates existed but none passed verification (too few inliers, violations, RMS).
  kBadScan,           ///< Scan geometry invalid (count 0 or > capacity, zero increment, non-finite angles).
};

/// Why verification refused a candidate (the rejection rules, in the order they are applied).
enum class RejectReason : std::uint8_t {
  kNone = 0,
  kNoConvergence,  ///< Registration found too few points or diverged.
  kTooFewInliers,  ///< Fewer than min_inliers.
  kMostlyHidden,   ///< Inliers / expected beams below min_visible_fraction.
  kOblique,        ///< Face seen beyond max_view_angle_rad.
  kOutOfRange,     ///< Farther than max_range_m.
  kUncertain,      ///< Position 1-σ from the covariance above max_sigma_m.
  kFarFromHint,    ///< Farther than hint_radius_m from the hint.
  kWeakEvidence,   ///< The cues' log-likelihood ratio is below min_evidence_nats (see the cues for why).
  /// A reflector dock whose stripe pattern reads otherwise than its profile's (another dock of this shape, or an
  /// untaped look-alike): a wrong dock id is worse than none. Only with usable intensity (docs/docks.md).
  kWrongCode,
  /// A reflector dock whose pattern was not read whole: a region with no beam well inside it (too far for the
  /// regions' width, too oblique, hidden), a gap read neither way, or no stripe read bright. A pattern known in part
  /// could be another dock's. Only with usable intensity.
  kCodeUnread,
  kCount,
};

/// The terms of the accept decision, each a log-likelihood ratio in nats (positive: evidence for the dock).
enum class EvidenceCue : std::uint8_t {
  kFit = 0,     ///< Beams landing on the dock, by how closely (Gaussian of range_sigma_m against a look-alike's).
  kSeeThrough,  ///< Beams that pass where the dock should stop them, or return nothing there.
  kFreeSpace,   ///< Surfaces just in front of the dock (free_space_m), where an approaching robot would be.
  kSupport,     ///< Long dock surfaces with too few of their beams (a surface of the dock that is not there).
  kEdges,       ///< Returns just past the dock's ends: a surface carrying on in line, or something right beside it.
  kWall,        ///< Beams past the ends meeting the wall where the mounting puts it (for), or not (against).
  kGeometry,    ///< How well the visible part of the dock fixes all three pose components (a flat face alone cannot).
  kPrior,       ///< Closeness to the pose hint when hint_radius_m is set (dock database, staging pose).
  /// The profile's reflector stripes read bright and its plain surfaces not (only for profiles with reflectors, on a
  /// lidar whose intensity is usable: set_intensity_usable()).
  kIntensity,
  kCount,
};

/// Number of evidence cues.
constexpr std::size_t kEvidenceCueCount = static_cast<std::size_t>(EvidenceCue::kCount);

/// Short name of a cue ("fit", "see_through", "free_space", "support", "edges", "wall", "geometry", "prior").
/// Never null.
const char* to_string(EvidenceCue c);

/// What the cues are computed from, per candidate. Beam counts are weighted by min(1, beam spacing at the dock /
/// 5 cm): beams closer than that on one surface are not independent evidence.
struct DecisionFeatures {
  Real hit = 0;          ///< Weighted beams within the inlier gate of the dock's surface.
  Real hit_sq = 0;       ///< Weighted sum of (residual / range_sigma_m)² over those beams.
  Real dropped = 0;      ///< Weighted dock beams with no return (not scored: dropouts say little).
  Real beyond = 0;       ///< Weighted dock beams returning from behind the dock's surface.
  Real front = 0;        ///< Weighted dock beams returning within free_space_m in front of it.
  Real missing = 0;      ///< Long dock surfaces (>= 3 expected beams) with fewer than half their beams on them.
  Real continues = 0;    ///< Weighted returns 4-12 cm past a long surface's end, on its line.
  Real stops = 0;        ///< Weighted returns there off its line but within 12 cm of it (beside the dock's end).
  Real wall_seen = 0;    ///< Weighted beams past the dock's ends meeting the mounting's wall.
  Real wall_missed = 0;  ///< Weighted beams past the ends that could have, and did not.
  /// Smallest eigenvalue of the fit's information matrix (yaw scaled by the dock's radius), weighted: the number of
  /// independent beams that fix the least constrained pose component.
  Real constraint = 0;
  /// The stripe pattern as read (profiles with reflectors on a lidar whose intensity is usable; else all 0): regions
  /// (each stripe, each gap between or beside stripes on a taped segment) with an inlier beam well inside them that
  /// read as the profile says or not, the inlier beams inside stripes, and the bright beams (>=
  /// reflector_min_intensity) inside any region.
  std::uint8_t regions_matched = 0;
  std::uint8_t regions_mismatched = 0;
  std::uint8_t stripes_matched = 0;  ///< Of regions_matched: stripes that read bright.
  /// Regions not read: no beam well inside them (too narrow for the range, or hidden), or a gap with one bright beam
  /// among fewer than four (a glint, or another dock's stripe seen by one beam). Any refuses the code (kCodeUnread).
  std::uint8_t regions_unread = 0;
  std::uint16_t stripe_beams = 0;
  std::uint16_t bright_beams = 0;
};

/// A candidate's evidence: each cue's log-likelihood ratio and their sum, nats, and the features behind them.
struct DockEvidence {
  Real cue_nats[kEvidenceCueCount] = {};
  Real total_nats = 0;
  DecisionFeatures features{};
  /// The cue with the most negative contribution (kCount when none is negative): the main reason against.
  EvidenceCue weakest() const;
};

/// Short name of a RejectReason ("weak_evidence", "wrong_code", ...; at most 15 characters: it goes into dockd's
/// one-datagram status as `det_reject`). Never null.
const char* to_string(RejectReason r);

/// Human-readable name of an EstimateStatus. Never null.
const char* to_string(EstimateStatus s);

/// Tuning of the estimator. Defaults suit LD06-class lidars (0.8°, σ 10 mm) and docks 0.2–0.5 m wide.
struct EstimatorParams {
  Real min_range_m = static_cast<Real>(0.05);     ///< Closer returns are ignored (lidar blind zone).
  Real max_range_m = static_cast<Real>(2.5);      ///< Farther returns are ignored; docks are sought within this
                                                  ///< (seed 000 uses 2.1 m; beyond ~2.5 m a 0.3 m dock is < 15 beams).
  Real range_sigma_m = static_cast<Real>(0.01);   ///< Expected 1-σ range noise; scales the gates and covariance.
  Real huber_k = static_cast<Real>(1.5);          ///< Huber threshold in units of range_sigma_m (first 3 iterations).
  Real tukey_c = static_cast<Real>(3.0);          ///< Tukey biweight cut-off in units of range_sigma_m (after).
  Real association_gate_m = static_cast<Real>(0.08);  ///< Points farther from every visible segment are ignored.
  Real inlier_gate_m = static_cast<Real>(0.03);   ///< |measured − expected| below this is an inlier.
  std::uint8_t max_iterations = 6;                ///< Gauss-Newton cap per candidate.
  std::uint8_t max_candidates = 12;               ///< Hypotheses refined per scan at most (best prescore first).
  Real min_feature_length_m = static_cast<Real>(0.08);  ///< Profile segments shorter than this seed no hypotheses.
  /// Returns this close in front of the expected surface count against the dock (free-space cue), not as
  /// occlusion: the space just in front of a dock is empty (a robot docks there), so a surface there means the
  /// hypothesis is wrong — e.g. a flat wall "explaining" a winged dock's face while hiding its wings.
  Real free_space_m = static_cast<Real>(0.15);
  std::uint16_t min_inliers = 10;  ///< Absolute floor on inliers (a 0.3 m dock 2 m away gives ~13 with LD06);
                                   ///< a profile's own DockProfile::min_inliers replaces it.
  /// Inliers / all beams expected on the dock (occluded included), at least: how much of the dock may be hidden.
  Real min_visible_fraction = static_cast<Real>(0.5);
  /// Distance from a segment's line within which a return 4-12 cm past its end counts as the surface carrying on.
  /// Narrower than the inlier gate: a wall meeting a 45° wing at its tip stays ~overhang away from the wing's line.
  Real extension_band_m = static_cast<Real>(0.02);
  /// Accept a candidate when its evidence (sum of the cues' log-likelihood ratios) reaches this, nats. Higher: fewer
  /// false detections, more misses of partly seen docks. docs/performance.md gives the rates per setting.
  Real min_evidence_nats = static_cast<Real>(3.4);
  Real max_sigma_m = static_cast<Real>(0.05);     ///< Reject when the position 1-σ (covariance) exceeds this.
  Real max_view_angle_rad = static_cast<Real>(1.2);     ///< Dock face seen more obliquely than this is rejected.
  Real hint_gate_m = static_cast<Real>(0.3);      ///< A verified pose farther than this from the hint ignores it.
  /// With a hint, only docks within this distance of it are accepted (0: anywhere). Set it when the dock's pose is
  /// known roughly (a dock database, a staging pose): clutter elsewhere can then never be taken for the dock.
  Real hint_radius_m = 0;
  /// How far the wall may lie outside the mounting's gap range (either way), on top of the noise gate, metres.
  Real wall_tolerance_m = static_cast<Real>(0.02);
  DockSelect select = DockSelect::kNearest;
  SegmentParams segments{};                       ///< Line extraction used for candidate generation.
  /// A return at least this bright (the lidar's own units: LD06 0–255) counts as retro-reflective tape for the
  /// intensity cue. Only used for profiles with reflectors.
  Real reflector_min_intensity = static_cast<Real>(235);
  /// A dock with reflector stripes, on a lidar whose intensity is usable: the global search also tries the scan's
  /// bright runs as the stripes (add_stripe_hypotheses), whatever their outline's rank. Finds more coded docks (their
  /// outline outranked by a nearer look-alike or a flat wall) and tries more taped things for them: more false
  /// docks and wrong ids (docs/performance.md, "Reflector docks").
  bool stripe_hypotheses = false;
};

/// Parameters for a lidar whose 1-σ range noise is `range_sigma_m`: the noise-dependent gates (inlier gate 3σ,
/// extension band 2σ, association gate 6σ, each with a floor for very clean lidars) scaled from
/// the defaults, which are this function's result for 10 mm. O(1).
EstimatorParams estimator_params_for_noise(Real range_sigma_m);

/// Result of one scan. Pose and covariance in the robot frame (the frame of the lidar mount pose).
struct DockEstimate {
  bool found = false;
  EstimateStatus status = EstimateStatus::kNoProfile;
  Pose2 pose{};                 ///< Dock frame (origin at the contacts, x out of the face) in the robot frame.
  Mat3 covariance = Mat3::Zero();  ///< Of (x_m, y_m, yaw_rad), m² / rad².
  Real rms_m = 0;               ///< RMS of inlier residuals.
  Real shape_rms_m = 0;         ///< RMS over all unoccluded dock beams, residuals clamped at the inlier gate.
  std::uint16_t inliers = 0;    ///< Beams within the inlier gate.
  std::uint16_t expected = 0;   ///< Beams predicted to hit the dock.
  std::uint16_t violations = 0; ///< Beams that see through where the dock should be.
  std::uint16_t occluded = 0;   ///< Beams blocked by something in front of the dock.
  std::uint16_t extensions = 0; ///< Returns continuing a long dock surface past its end (evidence against).
  std::uint16_t wall_seen = 0;  ///< Beams past the dock's ends that met the wall where the mounting puts it.
  std::uint16_t wall_looked = 0;///< Beams past the dock's ends that could have met such a wall.
  /// The decision's cues. When found: the accepted candidate's. When not: the best refused candidate's (the one
  /// with the highest total), so a caller can see why nothing was accepted; all zero when no candidate was refined.
  DockEvidence evidence{};
  RejectReason reject = RejectReason::kNone;  ///< When not found: why the best refused candidate was refused.
  /// When not found: the best refused candidate's pose (robot frame), for diagnostics; the counts above are then
  /// that candidate's too. Never use it to dock.
  Pose2 refused_pose{};
  std::uint8_t iterations = 0;  ///< Gauss-Newton iterations of the winning candidate.
  std::uint16_t candidates = 0; ///< Hypotheses refined this scan.
  std::uint16_t verified = 0;   ///< Of which were accepted (passed the hard checks and reached min_evidence_nats).
  bool from_hint = false;       ///< The winner came from the hint (tracking) rather than a global search.
};

/// Counters since configure(); never reset by estimate().
struct EstimatorCounters {
  std::uint32_t scans = 0;
  std::uint32_t found = 0;
  std::uint32_t bad_scans = 0;
  std::uint32_t candidates = 0;
  std::uint32_t rejected = 0;       ///< Candidates refused by verification.
  std::uint32_t rejected_by[static_cast<std::size_t>(RejectReason::kCount)] = {};  ///< Refusals by reason.
  std::uint32_t truncated_candidates = 0;  ///< Hypotheses skipped because max_candidates was reached.
  std::uint32_t truncated_segments = 0;    ///< Scans whose line extraction hit a cap.
};

/// The estimator over working buffers it does not own (DockPoseEstimatorN<N> gives them, for scans of up to N
/// beams). Everything that takes an estimator takes this, whatever its capacity. Not copyable.
class DockPoseEstimatorBase {
 public:
  DockPoseEstimatorBase(const DockPoseEstimatorBase&) = delete;
  DockPoseEstimatorBase& operator=(const DockPoseEstimatorBase&) = delete;

  /// Sets the profile and parameters; returns false (estimator unusable until a good call) for a profile with no
  /// segments. O(vertices).
  bool configure(const DockProfile& profile, const EstimatorParams& params);

  /// Estimates the dock pose in one scan. `lidar_mount` is the lidar's pose in the robot frame. `hint`, if not null,
  /// is an expected dock pose in the robot frame (tracker prediction or configured pose). Cost: see file comment.
  DockEstimate estimate(const ScanView& scan, const Pose2& lidar_mount, const Pose2* hint = nullptr);

  /// Whether the scans' intensities may be read (the lidar's IntensityCheck verdict): without it, the intensity cue
  /// is 0 and detection is geometric. Default false. O(1).
  void set_intensity_usable(bool usable) { intensity_usable_ = usable; }
  bool intensity_usable() const { return intensity_usable_; }

  const EstimatorCounters& counters() const { return counters_; }
  const EstimatorParams& params() const { return params_; }
  const DockProfile& profile() const { return profile_; }
  /// The configured profile's largest vertex distance from the dock origin, m (0 before configure()). O(1).
  Real profile_radius_m() const { return profile_radius_m_; }
  /// Most beams a scan may have (larger scans are refused as kBadScan).
  std::size_t capacity() const { return capacity_; }

 protected:
  /// The per-beam working buffers, each of `capacity` elements.
  struct Buffers {
    Vec2* dir;
    std::uint16_t* assoc_beam;
    std::uint8_t* assoc_seg;
    ScanPointBuffer* points;
    LineSegmentBuffer* segments;
    std::size_t capacity;
  };
  explicit DockPoseEstimatorBase(const Buffers& b)
      : dir_(b.dir), assoc_beam_(b.assoc_beam), assoc_seg_(b.assoc_seg), points_(*b.points), segs_(*b.segments),
        capacity_(b.capacity) {}
  ~DockPoseEstimatorBase() = default;

 private:
  struct Refined {
    Pose2 pose;      // dock in lidar frame
    Mat3 h;          // Gauss-Newton normal matrix at the solution
    Real rms_m;
    Real shape_rms_m;
    std::uint16_t inliers, expected, violations, occluded, extensions, wall_seen, wall_looked;
    std::uint8_t iterations;
    DockEvidence evidence;
    bool ok;
    bool duplicate;  // dropped by refine(): converging onto a verified pose
    RejectReason reject;
  };
  /// Copies a candidate's beam counts and evidence into an estimate (accepted or best refused). O(1).
  static void report(const Refined& r, DockEstimate* est);
  /// Checks the scan's geometry and takes its ranges (by pointer, valid until estimate() returns); recomputes the
  /// beam directions only when the geometry differs from the last scan's. O(1), or O(B) on a new geometry.
  bool load_scan(const ScanView& scan);
  /// `r` when it is a return within [min_m, max_m], else 0: the test range_at() applies, for loops that keep the
  /// limits in locals. O(1).
  static Real usable_range(Real r, Real min_m, Real max_m) {
    return is_valid_range(r) && r >= min_m && r <= max_m ? r : 0;
  }
  /// Range of beam i when it is a return within [min_range_m, max_range_m], else 0. O(1).
  Real range_at(std::size_t i) const { return usable_range(ranges_m_[i], params_.min_range_m, params_.max_range_m); }
  /// Fills points_ from the loaded beams (global search only): one per beam with range_at() != 0. O(B).
  void build_points();
  /// Gauss-Newton registration from `initial` (dock in lidar frame). `rough`: the start may be centimetres off (a
  /// global-search hypothesis), so large steps fit a sample of a dense span; a hint refines on every beam from the
  /// start. O(I · W · S) for I iterations over the W beams of the dock's span and S profile segments. A fit that
  /// comes close to one of the `n_verified` poses in `verified` after a few iterations is abandoned (duplicate set).
  /// When the fit leaves a direction almost unfixed, up to kEdgeSteps more steps with edge_terms() (O(kEdgeSteps · V ·
  /// S)).
  Refined refine(const Pose2& initial, bool rough, const Pose2* verified = nullptr, std::size_t n_verified = 0);
  /// Fills the association list (assoc_beam_, no segment yet) with the returns in placed_'s angular span plus the
  /// margin that `gate_m` (the iteration's association gate) subtends at the dock, leaving out wall points beside a
  /// mounted dock. `t`, `nd`: the dock's position and x axis in the lidar frame, `dist_m` = |t|. Returns how many.
  /// O(beams in the span).
  std::size_t span_beams(Real dist_m, const Vec2& t, const Vec2& nd, Real gate_m);
  /// Scores a refined candidate (its evidence and counts) and decides. `hint` is the hint in the lidar frame or null.
  void verify(Refined& r, const Pose2* hint);
  /// Where the scan shows the ends of the placed dock's visible surfaces. A silhouette vertex is the end of a visible
  /// surface whose neighbour along the profile is hidden or absent: rays past it miss that surface. When the last
  /// beam on the surface and the first beam beyond its line lie within kEdgeSearchBeams of where the pose puts the
  /// vertex, with at most one beam between them, the vertex's bearing lies between those two beams: a measurement
  /// whose error is uniform over that interval (standard deviation width/√12). Adds its Gauss-Newton terms, in the
  /// range units of refine() (weighted by range_sigma_m² over that variance), to `h` and `g`. refine() takes them
  /// when its fit leaves a direction almost unfixed (kEdgeWeakShare): a dock along a face that every visible surface
  /// is parallel to, which the point-to-surface residuals cannot place. Returns the edges used. Requires placed_ at
  /// `pose` and a loaded scan. O(V·S): a raycast per silhouette vertex, and 2·kEdgeSearchBeams + 1 beams each.
  std::size_t edge_terms(const Pose2& pose, Mat3* h, Vec3* g) const;
  /// A fit's information (refine()'s normal matrix) with yaw expressed as arc length at the dock's radius, so that all
  /// three components are in metres: what the `geometry` cue and refine()'s test for an almost unfixed direction read.
  /// O(1).
  Mat3 arc_scaled(const Mat3& h) const;
  /// verify(), then the hint radius: the whole accept decision for one candidate, no counters touched.
  void decide(Refined& r, const Pose2* hint);
  /// Signed index of the beam nearest angle_rad (may lie outside [0, beams) for a partial scan).
  long first_beam(Real angle_rad) const;
  /// Index of beam first+k, wrapped on full-turn scans; false when outside a partial scan.
  bool beam_at(long first, std::size_t k, std::size_t* index) const {
    long i = first + static_cast<long>(k);
    const long n = static_cast<long>(beams_);
    if (wraps_) {
      // Spans start within a turn of the scan's ends: one add or subtract, the division only beyond that.
      if (i < 0) i += n;
      if (i >= n) i -= n;
      if (i < 0 || i >= n) {
        i %= n;
        if (i < 0) i += n;
      }
    } else if (i < 0 || i >= n) {
      return false;
    }
    *index = static_cast<std::size_t>(i);
    return true;
  }
  /// Fills hyps_ with ranked pose hypotheses from scan line segments and sliding-window line fits (points_ already
  /// built), the best max_candidates first, then the stripe hypotheses; returns how many to refine in all.
  std::size_t generate_candidates();
  /// Appends the hypothesis that puts profile segment `profile_segment` (normal facing the lidar along n_scan) with
  /// its point anchor_dock (dock frame) onto anchor_scan (lidar frame). Counts truncation at kMaxHypotheses.
  void push_hypothesis(const Vec2& n_scan, const Vec2& anchor_scan, const Vec2& anchor_dock, std::size_t profile_segment,
                       std::size_t* n);
  /// The pose that puts profile segment `profile_segment` (normal facing the lidar along n_scan) with its point
  /// anchor_dock (dock frame) onto anchor_scan (lidar frame). O(1), one arctangent.
  Pose2 hypothesis_pose(const Vec2& n_scan, const Vec2& anchor_scan, const Vec2& anchor_dock,
                        std::size_t profile_segment) const;
  /// Reflector docks with usable intensity: hypotheses from the scan's bright runs, written to hyps_ from index `at`
  /// (past the ranked ones, so they are refined whatever their prescore). A run on a scan line segment puts the
  /// centre of each piece of tape (tape_piece) no shorter than the run at the run's centre, the line giving the
  /// face's direction: the stripes pin a flat face along itself where its outline does not. At most
  /// kMaxStripeHypotheses; returns how many. O(points + runs · (line segments + stripes)).
  std::size_t add_stripe_hypotheses(std::size_t at);
  /// The piece of tape that starts at stripe q (q < reflector_count): the stripes meeting it end to end (within
  /// kStripeEdgeMarginM) on its segment. Writes the piece's end along the segment to *to_m; returns the index past its
  /// last stripe. O(stripes in the piece).
  std::size_t tape_piece(std::size_t q, Real* to_m) const;
  /// Whether consecutive points a, b lie apart by more than five beam spacings at a's range (at least 5 cm): one
  /// surface does not continue across that. O(1).
  bool depth_gap(const ScanPoint& a, const ScanPoint& b) const;
  /// Hypotheses from windows of each long profile segment's length slid along contiguous runs of points: a window
  /// that is flat to the noise level, spans the segment's length and ends (a bend or a gap) on one side at least.
  /// Robust where split-and-merge merges a short wing into the face. O(points · long profile segments).
  void add_window_hypotheses(std::size_t* n);
  /// Rough support of a hypothesis: +1 per matching beam, -2 per beam seeing through the dock (every other beam).
  /// Stops early, returning a bound below `floor`, once the score can no longer reach `floor`: a hypothesis that
  /// ranks below the best max_candidates needs no exact score.
  Real prescore(const Pose2& pose, Real floor);
  /// The wall cue's counts: of the beams just outside [k_first_hit, k_last_hit] (offsets from `first`, up to 3 per
  /// side) that could meet a wall behind the dock, how many do where the mounting's gap range puts it.
  /// Precondition: placed_ holds the profile placed at `pose`.
  void wall_behind(const Pose2& pose, long first, std::size_t k_first_hit, std::size_t k_last_hit,
                   std::uint16_t* seen, std::uint16_t* looked) const;
  /// For a return p: 0 when it is not 4-12 cm past the end of a long visible segment of placed_ (or lies on the
  /// dock), 1 when it is off that segment's line by at most 12 cm, 2 when it continues the line. [box_lo, box_hi]:
  /// placed_'s bounding box grown by the inlier gate (p outside it is off the dock).
  int continues_past_end(const Vec2& p, const Vec2& box_lo, const Vec2& box_hi) const;

  /// Hypotheses collected per scan before ranking; beyond this they are counted as truncated.
  static constexpr std::size_t kMaxHypotheses = 128;
  /// Stripe hypotheses (add_stripe_hypotheses) refined per scan at most, besides the ranked ones.
  static constexpr std::size_t kMaxStripeHypotheses = 6;
  /// Most prescores ranked_ holds: with more candidates than this, every prescore is exact.
  static constexpr std::size_t kMaxRanked = 16;
  struct Hypothesis {
    Pose2 pose{};       // dock in lidar frame
    Real prescore = 0;
  };

  /// The floor on inliers for this dock: its profile's own, else the parameters'. A dock with reflector stripes keeps
  /// the parameters': its code is read from the beams on each stripe and gap, and a lower floor let a look-alike's
  /// code be read from too few (confident wrong ids). O(1).
  std::uint16_t min_inliers() const {
    return profile_.min_inliers > 0 && profile_.reflector_count == 0 ? profile_.min_inliers : params_.min_inliers;
  }

  DockProfile profile_{};
  EstimatorParams params_{};
  bool configured_ = false;
  Real profile_radius_m_ = 0;  // largest vertex distance from the dock origin
  Real back_x_m_ = 0;          // the profile's back plane: its smallest x
  Real half_width_m_ = 0;      // largest |y| of the profile
  Real wall_gap_max_m_ = 0;    // farthest the wall may lie behind the back plane (the mounting's, or the default)
  // Per segment: the largest line distance at which registration keeps a beam on it unsearched (0: never).
  Real shortcut_max_m_[kMaxProfileVertices] = {};
  bool seg_taped_[kMaxProfileVertices] = {};  // Per segment: whether it carries a reflector stripe.
  EstimatorCounters counters_{};

  // Working buffers (the owner's).
  Vec2* dir_;                  // beam i's unit direction, kept for the geometry it was computed for
  std::uint16_t* assoc_beam_;  // registration's beams ...
  std::uint8_t* assoc_seg_;    // ... and the profile segment each was nearest to in the last iteration
  ScanPointBuffer& points_;
  LineSegmentBuffer& segs_;
  std::size_t capacity_;
  // The current scan, in the lidar frame: its ranges (the caller's).
  const Real* ranges_m_ = nullptr;
  const Real* intensities_ = nullptr;  // the caller's, or null
  bool intensity_usable_ = false;
  std::size_t dir_beams_ = 0;
  Real dir_angle_min_rad_ = 0;
  Real dir_angle_inc_rad_ = 0;
  std::size_t beams_ = 0;
  Real angle_min_rad_ = 0;
  Real angle_inc_rad_ = 0;
  bool wraps_ = false;
  PlacedProfile placed_{};
  Hypothesis hyps_[kMaxHypotheses];
  // This scan's best max_candidates prescores so far, best first: the last one is the floor a new hypothesis must
  // reach to be refined.
  Real ranked_[kMaxRanked] = {};
  std::size_t n_ranked_ = 0;
  static_assert(kMaxProfileVertices < 255, "association segments are 8 bits with 0xFF for none");
};

/// Line segments the estimator's global search holds for a scan of up to N beams: a segment takes at least four
/// beams, and never more than kMaxLineSegments.
constexpr std::size_t estimator_segment_capacity(std::size_t beams) {
  return beams / 4 < 16 ? 16 : (beams / 4 > kMaxLineSegments ? kMaxLineSegments : beams / 4);
}

/// The estimator with its buffers, for scans of up to N beams. Size: about N · (16 + 48) bytes with double (half
/// with float) plus the segments, the hypotheses and the placed profile; keep it static or a member, not on a stack.
template <std::size_t N>
class DockPoseEstimatorN : public DockPoseEstimatorBase {
 public:
  static_assert(N >= 16 && N <= 65536, "beam indices are 16 bits");
  static constexpr std::size_t kCapacity = N;
  DockPoseEstimatorN() : DockPoseEstimatorBase(Buffers{dir_, assoc_beam_, assoc_seg_, &points_, &segs_, N}) {}

 private:
  Vec2 dir_[N];
  std::uint16_t assoc_beam_[N] = {};
  std::uint8_t assoc_seg_[N] = {};
  ScanPointsN<N> points_{};
  FixedVector<LineSegment, estimator_segment_capacity(N)> segs_{};
};

/// The estimator for scans of any lidar core supports (kMaxScanPoints beams).
using DockPoseEstimator = DockPoseEstimatorN<kMaxScanPoints>;

}  // namespace dockcore
