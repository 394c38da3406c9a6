#include "dockcore/perception/reflector_read.hpp"

#include <cmath>

#include "dockcore/perception/profile_geometry.hpp"

namespace dockcore {

namespace {

constexpr Real kHalf = static_cast<Real>(0.5);

/// The bright runs of one scan, beam by beam: the inlier beams of one segment in scan order form a sequence, and each
/// run of bright beams within it becomes a stripe when it closes.
class RunCollector {
 public:
  explicit RunCollector(const PlacedProfile& placed) : placed_(placed) {}

  /// An inlier beam on segment `seg`, its expected hit `s_m` along it. A new segment starts a new sequence.
  void beam(std::size_t seg, Real s_m, bool bright) {
    if (!in_seq_ || seg != seg_) {
      end_sequence();
      in_seq_ = true;
      seg_ = seg;
    }
    if (bright) {
      if (run_n_ == 0) {
        run_first_m_ = s_m;
        run_start_known_ = have_prev_;
        run_start_m_ = have_prev_ ? kHalf * (prev_m_ + s_m) : s_m;
      } else if (run_n_ == 1) {
        run_second_m_ = s_m;
      }
      if (run_n_ > 0) run_before_last_m_ = run_last_m_;
      run_last_m_ = s_m;
      if (run_n_ < 0xFFFF) ++run_n_;
    } else if (run_n_ > 0) {
      close_run(kHalf * (run_last_m_ + s_m), true);
    }
    prev_m_ = s_m;
    have_prev_ = true;
  }

  /// The sequence ends (a beam off the dock, another segment, the span's end): an open run closes at its last beam
  /// plus half the beam spacing.
  void end_sequence() {
    if (run_n_ > 0) {
      close_run(run_n_ >= 2 ? run_last_m_ + kHalf * (run_last_m_ - run_before_last_m_) : run_last_m_, false);
    }
    in_seq_ = false;
    have_prev_ = false;
  }

  std::size_t found() const { return found_; }
  std::size_t stored() const { return found_ < kMaxReflectors ? found_ : kMaxReflectors; }
  const ReflectorStripe* stripes() const { return stripes_; }

 private:
  /// Closes the open run with its end edge at `end_m`: half-way to a dark beam (`end_known`) or extrapolated past
  /// the run's last beam. Keeps it as a stripe when it has two beams or more and is at least kMinStripeM long after
  /// clamping to its segment.
  void close_run(Real end_m, bool end_known) {
    const std::uint16_t n = run_n_;
    run_n_ = 0;
    if (n < 2) return;
    const Real len = placed_.len_m[seg_];
    const Real spacing_start = std::fabs(run_second_m_ - run_first_m_);
    const Real spacing_end = std::fabs(run_last_m_ - run_before_last_m_);
    Real start_m = run_start_m_;
    if (!run_start_known_) {
      // Extend away from the run by half a spacing; to the segment's end when that lies within a spacing.
      start_m = run_first_m_ - kHalf * (run_second_m_ - run_first_m_);
      start_m = snap(run_first_m_, start_m < run_first_m_, spacing_start, len, start_m);
    }
    if (!end_known) end_m = snap(run_last_m_, end_m < run_last_m_, spacing_end, len, end_m);
    Real lo = start_m < end_m ? start_m : end_m;
    Real hi = start_m < end_m ? end_m : start_m;
    lo = lo < 0 ? 0 : (lo > len ? len : lo);
    hi = hi < 0 ? 0 : (hi > len ? len : hi);
    if (!(hi - lo >= kMinStripeM)) return;
    if (found_ < kMaxReflectors) {
      ReflectorStripe& st = stripes_[found_];
      st.segment = static_cast<std::uint8_t>(seg_);
      st.from_m = lo;
      st.to_m = hi;
    }
    ++found_;
  }

  /// An edge extrapolated from the beam at `last_m` towards smaller (`towards_start`) or larger distances along the
  /// segment: the segment's end on that side when it lies within `spacing_m` of the beam, else `edge_m`.
  static Real snap(Real last_m, bool towards_start, Real spacing_m, Real len_m, Real edge_m) {
    if (towards_start) return last_m <= spacing_m ? 0 : edge_m;
    return len_m - last_m <= spacing_m ? len_m : edge_m;
  }

  const PlacedProfile& placed_;
  bool in_seq_ = false;
  std::size_t seg_ = 0;
  bool have_prev_ = false;
  Real prev_m_ = 0;
  std::uint16_t run_n_ = 0;
  bool run_start_known_ = false;
  Real run_start_m_ = 0;
  Real run_first_m_ = 0;
  Real run_second_m_ = 0;
  Real run_before_last_m_ = 0;
  Real run_last_m_ = 0;
  ReflectorStripe stripes_[kMaxReflectors] = {};
  std::size_t found_ = 0;
};

}  // namespace

const char* to_string(StripeReadStatus s) {
  switch (s) {
    case StripeReadStatus::kOk:
      return "ok";
    case StripeReadStatus::kNoIntensity:
      return "no_intensity";
    case StripeReadStatus::kTooFewBeams:
      return "too_few_beams";
    case StripeReadStatus::kTooManyStripes:
      return "too_many_stripes";
  }
  return "?";
}

StripeRead read_reflector_stripes(const ScanView& scan, const Pose2& lidar_mount, const DockProfile& profile,
                                  const Pose2& dock_in_robot, const StripeReadParams& params) {
  StripeRead out;
  if (scan.count == 0 || scan.ranges_m == nullptr || !(scan.angle_increment_rad > 0) ||
      !std::isfinite(scan.angle_min_rad) ||
      static_cast<Real>(scan.count) * scan.angle_increment_rad > kTwoPi + scan.angle_increment_rad ||
      profile.segment_count() == 0 || !finite_pose(dock_in_robot) || !finite_pose(lidar_mount)) {
    out.status = StripeReadStatus::kTooFewBeams;
    return out;
  }
  if (scan.intensities == nullptr) {
    out.status = StripeReadStatus::kNoIntensity;
    return out;
  }
  PlacedProfile placed;
  placed.place(profile, lidar_mount.inverse().compose(dock_in_robot));
  Real lo = 0;
  Real hi = 0;
  placed.angular_span(&lo, &hi);
  // A beam of slack either side for rounding.
  const long first = nearest_beam_index(scan.angle_min_rad, scan.angle_increment_rad, scan.count, lo) - 1;
  const std::size_t n_beams = static_cast<std::size_t>((hi - lo) / scan.angle_increment_rad) + 3;
  const long count = static_cast<long>(scan.count);
  const bool wraps = scan.wraps();
  RunCollector runs(placed);
  Real min_i = 0;
  Real max_i = 0;
  for (std::size_t k = 0; k < n_beams && k < scan.count; ++k) {
    long i = first + static_cast<long>(k);
    if (wraps) {
      i %= count;
      if (i < 0) i += count;
    } else if (i < 0 || i >= count) {
      runs.end_sequence();
      continue;
    }
    const std::size_t b = static_cast<std::size_t>(i);
    const Real a = scan.angle_rad(b);
    const Vec2 dir(std::cos(a), std::sin(a));
    Real expected_m = 0;
    std::size_t seg = 0;
    if (!placed.raycast(dir, &expected_m, &seg)) {
      runs.end_sequence();
      continue;
    }
    const Real m = scan.ranges_m[b];
    if (!is_valid_range(m) || m < params.min_range_m || std::fabs(m - expected_m) > params.inlier_gate_m) continue;
    const Real v = scan.intensities[b];
    if (out.inlier_beams == 0) {
      min_i = max_i = v;
    } else {
      min_i = v < min_i ? v : min_i;
      max_i = v > max_i ? v : max_i;
    }
    if (out.inlier_beams < 0xFFFF) ++out.inlier_beams;
    const bool bright = v >= params.min_intensity;
    if (bright && out.bright_beams < 0xFFFF) ++out.bright_beams;
    runs.beam(seg, placed.along_m(seg, expected_m * dir), bright);
  }
  runs.end_sequence();
  if (out.inlier_beams < params.min_inlier_beams) {
    out.status = StripeReadStatus::kTooFewBeams;
    return out;
  }
  if (!(max_i > min_i)) {
    out.status = StripeReadStatus::kNoIntensity;
    return out;
  }
  if (runs.found() > kMaxReflectors) {
    out.status = StripeReadStatus::kTooManyStripes;
    return out;
  }
  // In order along the outline; runs of one segment seen in two sequences may overlap after extension: merged.
  std::size_t n = 0;
  for (std::size_t q = 0; q < runs.stored(); ++q) {
    ReflectorStripe st = runs.stripes()[q];
    std::size_t j = n;
    while (j > 0 && (out.stripes[j - 1].segment > st.segment ||
                     (out.stripes[j - 1].segment == st.segment && out.stripes[j - 1].from_m > st.from_m))) {
      out.stripes[j] = out.stripes[j - 1];
      --j;
    }
    out.stripes[j] = st;
    ++n;
  }
  std::size_t merged = 0;
  for (std::size_t q = 0; q < n; ++q) {
    if (merged > 0 && out.stripes[merged - 1].segment == out.stripes[q].segment &&
        out.stripes[q].from_m <= out.stripes[merged - 1].to_m) {
      if (out.stripes[q].to_m > out.stripes[merged - 1].to_m) out.stripes[merged - 1].to_m = out.stripes[q].to_m;
    } else {
      out.stripes[merged++] = out.stripes[q];
    }
  }
  out.count = merged;
  out.status = StripeReadStatus::kOk;
  return out;
}

bool same_stripes(const ReflectorStripe* a, std::size_t a_count, const ReflectorStripe* b, std::size_t b_count,
                  Real tolerance_m) {
  if (a_count != b_count) return false;
  for (std::size_t q = 0; q < a_count; ++q) {
    if (a[q].segment != b[q].segment || std::fabs(a[q].from_m - b[q].from_m) > tolerance_m ||
        std::fabs(a[q].to_m - b[q].to_m) > tolerance_m) {
      return false;
    }
  }
  return true;
}

}  // namespace dockcore
