#include "dockcore/perception/breakpoint_detector.hpp"

namespace dockcore {
namespace {

// Window bounds that land within this fraction of a beam of an exact beam angle count as hitting it, so a bound
// of exactly -90° on a 1° scan includes the -90° beam despite rounding in angle_min + k * increment.
constexpr Real kWindowTolBeams = static_cast<Real>(1e-3);

Real abs_r(Real v) { return v < 0 ? -v : v; }

}  // namespace

const char* to_string(BreakpointStatus s) {
  switch (s) {
    case BreakpointStatus::kFound: return "found";
    case BreakpointStatus::kBadScan: return "scan has no samples, non-finite geometry or a non-positive increment";
    case BreakpointStatus::kBadWindow: return "window bounds are not finite or min > max";
    case BreakpointStatus::kEmptyWindow: return "window holds fewer than 2 beams of the scan";
    case BreakpointStatus::kTooFewMutations: return "too few mutation points in the window";
    case BreakpointStatus::kNoPattern: return "no group of mutation points matches the dock pattern";
  }
  return "unknown breakpoint status";
}

bool BreakpointDetection::dock_position_lidar(Vec2& out_m) const {
  if (!found || !is_valid_range(centre_range_m)) return false;
  out_m = Vec2(centre_range_m * std::cos(centre_angle_rad), centre_range_m * std::sin(centre_angle_rad));
  return true;
}

std::uint32_t BreakpointDetector::scan_index_of(std::size_t j) const {
  std::int32_t k = first_k_ + static_cast<std::int32_t>(j);
  if (index_modulus_ > 0) {
    const std::int32_t m = static_cast<std::int32_t>(index_modulus_);
    k %= m;
    if (k < 0) k += m;
  }
  return static_cast<std::uint32_t>(k);
}

Real BreakpointDetector::angle_of(std::size_t pos) const {
  const std::int32_t k = first_k_ + static_cast<std::int32_t>(pos);
  return wrap_angle(scan_angle_min_rad_ + static_cast<Real>(k) * scan_increment_rad_);
}

BreakpointDetection BreakpointDetector::detect(const ScanView& scan) {
  BreakpointDetection none;
  work_count_ = 0;
  const Real inc = scan.angle_increment_rad;
  const Real amin = scan.angle_min_rad;
  if (scan.ranges_m == nullptr || scan.count == 0 || !std::isfinite(inc) || !std::isfinite(amin) || !(inc > 0)) {
    none.status = BreakpointStatus::kBadScan;
    return none;
  }
  Real wmin = params_.window_min_rad;
  Real wmax = params_.window_max_rad;
  if (!std::isfinite(wmin) || !std::isfinite(wmax) || wmin > wmax) {
    none.status = BreakpointStatus::kBadWindow;
    return none;
  }

  // Bring the window to the turn the scan covers: shift it by whole turns so that its middle lies within half a
  // turn of the scan's middle. Lets callers write the window as [-90°, 90°] whatever angle_min the lidar uses.
  const Real count_r = static_cast<Real>(scan.count);
  const Real scan_mid = amin + static_cast<Real>(0.5) * (count_r - 1) * inc;
  const Real off = static_cast<Real>(0.5) * (wmin + wmax) - scan_mid;
  const Real shift = wrap_angle(off) - off;
  wmin += shift;
  wmax += shift;

  const bool wraps = scan.wraps();
  Real x_lo = (wmin - amin) / inc;
  Real x_hi = (wmax - amin) / inc;
  std::size_t modulus = 0;
  if (wraps) {
    // Beams per turn; a scan may repeat its first angle at the end (361 beams of 1°), so the count is not used.
    const Real per_turn = std::floor(kTwoPi / inc + static_cast<Real>(0.5));
    modulus = per_turn < count_r ? static_cast<std::size_t>(per_turn) : scan.count;
    // After the shift the window lies within about 1.5 turns of angle_min; the clamp only guards the int conversion.
    const Real lim = static_cast<Real>(3) * count_r;
    x_lo = x_lo < -lim ? -lim : x_lo;
    x_hi = x_hi > lim ? lim : x_hi;
  } else {
    x_lo = x_lo < 0 ? 0 : x_lo;
    x_hi = x_hi > count_r - 1 ? count_r - 1 : x_hi;
  }
  const Real k_lo_r = std::ceil(x_lo - kWindowTolBeams);
  const Real k_hi_r = std::floor(x_hi + kWindowTolBeams);
  if (!(k_hi_r >= k_lo_r + 1)) {
    none.status = BreakpointStatus::kEmptyWindow;
    return none;
  }
  std::size_t w = static_cast<std::size_t>(k_hi_r - k_lo_r) + 1;
  if (wraps && w > modulus) w = modulus;
  if (w > kMaxScanPoints) w = kMaxScanPoints;

  first_k_ = static_cast<std::int32_t>(k_lo_r);
  index_modulus_ = modulus;
  scan_angle_min_rad_ = amin;
  scan_increment_rad_ = inc;
  work_count_ = w;
  ++counters_.scans_processed;

  // Step 1: filter (seed eq. 5-2; the code's isinf test widened to every non-return, since NaN would otherwise
  // poison every comparison below).
  for (std::size_t j = 0; j < w; ++j) {
    const Real r = scan.ranges_m[scan_index_of(j)];
    work_m_[j] = (is_valid_range(r) && r <= params_.max_range_m) ? r : 0;
  }

  // Step 2: gap completion, in place and in the seed's loop order (i in [1, n-2)), so a value completed at i is the
  // left neighbour seen at i+1. The seed's first branch would also "complete" a 0 between two 0s (with 0); requiring
  // valid neighbours changes no range and keeps the counter honest.
  const Real gap_thr = params_.gap_fill_max_diff_m;
  if (gap_thr > 0 && w >= 4) {
    for (std::size_t i = 1; i + 2 < w; ++i) {
      if (work_m_[i] > 0) continue;
      const Real a = work_m_[i - 1];
      if (!(a > 0)) continue;
      const Real b = work_m_[i + 1];
      if (b > 0) {
        if (abs_r(b - a) < gap_thr) {
          work_m_[i] = static_cast<Real>(0.5) * (a + b);
          ++counters_.gap_filled_points;
        }
      } else {
        const Real c = work_m_[i + 2];
        if (c > 0 && abs_r(c - a) < gap_thr) {
          work_m_[i] = work_m_[i + 1] = static_cast<Real>(0.5) * (a + c);
          counters_.gap_filled_points += 2;
        }
      }
    }
  }

  BreakpointDetection d = params_.variant == BreakpointVariant::kPaperSigned ? detect_paper_signed(scan)
                                                                               : detect_seed_code(scan);
  counters_.mutations_found += d.mutation_count;
  if (d.found) ++counters_.detections;
  return d;
}

void BreakpointDetector::fill_geometry(const ScanView& scan, std::size_t right_pos, std::size_t left_pos,
                                       BreakpointDetection& d) const {
  // The seed's (int)(0.5 + (left + right) / 2.0) on non-negative integers.
  const std::size_t centre_pos = (right_pos + left_pos + 1) / 2;
  d.right_index = scan_index_of(right_pos);
  d.left_index = scan_index_of(left_pos);
  d.centre_index = scan_index_of(centre_pos);
  d.right_angle_rad = angle_of(right_pos);
  d.left_angle_rad = angle_of(left_pos);
  d.centre_angle_rad = angle_of(centre_pos);
  d.centre_range_m = scan.ranges_m[d.centre_index];
}

BreakpointDetection BreakpointDetector::detect_seed_code(const ScanView& scan) {
  BreakpointDetection d;
  const std::size_t n = work_count_;
  const Real* r = work_m_;

  // Step 3: mark i when the jump to i+1 lies strictly inside the band. The seed's loop stops at n-2, so the last
  // pair (n-2, n-1) is never examined; kept, it only matters at the window edge where the guard below rejects anyway.
  std::uint16_t marks = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::int8_t m = 0;
    if (i + 2 < n) {
      const Real jump = abs_r(r[i] - r[i + 1]);
      if (jump > params_.min_jump_m && jump < params_.max_jump_m) m = 1;
    }
    marks_[i] = m;
    if (m != 0) ++marks;
  }
  d.mutation_count = marks;

  auto next_mark = [&](std::size_t from) {
    while (from < n && marks_[from] == 0) ++from;
    return from;
  };

  // Step 4: the first four marks, then slide by one mark at a time, as the seed's loop does.
  std::size_t m[4];
  std::size_t from = 0;
  for (std::size_t& mk : m) {
    mk = next_mark(from);
    if (mk >= n) {
      d.status = BreakpointStatus::kTooFewMutations;
      return d;
    }
    from = mk + 1;
  }

  const std::size_t off = params_.neighbour_offset_idx;
  const std::size_t spacing = params_.max_pair_spacing_idx;
  const Real pair_diff = params_.max_pair_range_diff_m;
  for (;;) {
    // Rule 1: the dock's raised part is nearer than its slot on each side.
    const bool order_ok = r[m[0]] < r[m[1]] && r[m[2]] < r[m[3]];
    // Rule 2: the dock stands out from what lies beyond it. Out-of-window neighbours (the seed reads outside its
    // array there) reject the candidate.
    const bool inside = m[0] >= off && m[3] + off < n;
    const bool neighbour_ok = inside && r[m[0]] < r[m[0] - off] && r[m[3]] < r[m[3] + off];
    // Rule 3: the slots are narrow (in beams).
    const bool spacing_ok = m[1] - m[0] < spacing && m[3] - m[2] < spacing;
    // Rule 4: the steps are not too tall.
    const bool diff_ok = abs_r(r[m[0]] - r[m[1]]) < pair_diff && abs_r(r[m[2]] - r[m[3]]) < pair_diff;
    if (order_ok && neighbour_ok && spacing_ok && diff_ok) break;
    // The seed leaves m3 unchanged when no further mark exists; the window then holds m3 twice and rule 1
    // (r[m2] < r[m3]) can never pass again, so stopping here gives the same answer in fewer steps.
    const std::size_t next = next_mark(m[3] + 1);
    if (next >= n) {
      d.status = BreakpointStatus::kNoPattern;
      return d;
    }
    m[0] = m[1];
    m[1] = m[2];
    m[2] = m[3];
    m[3] = next;
  }

  d.found = true;
  d.status = BreakpointStatus::kFound;
  for (std::size_t k = 0; k < 4; ++k) d.mutation_index[k] = scan_index_of(m[k]);
  d.left_range_m = r[m[3]];
  d.right_range_m = r[m[0]] + params_.right_range_compensation_m;
  fill_geometry(scan, m[0], m[3], d);
  return d;
}

BreakpointDetection BreakpointDetector::detect_paper_signed(const ScanView& scan) {
  BreakpointDetection d;
  const std::size_t n = work_count_;
  const Real* r = work_m_;
  const Real lo = params_.signed_min_jump_m;
  const Real hi = params_.signed_max_jump_m;

  // Eq. 5-6 on the backward difference; rd_0 has no predecessor and stays 0 (eq. 5-5).
  std::uint16_t marks = 0;
  marks_[0] = 0;
  for (std::size_t i = 1; i < n; ++i) {
    const Real diff = r[i] - r[i - 1];
    std::int8_t m = 0;
    if (diff >= lo && diff <= hi) {
      m = 1;
    } else if (diff >= -hi && diff <= -lo) {
      m = -1;
    }
    marks_[i] = m;
    if (m != 0) ++marks;
  }
  d.mutation_count = marks;
  if (marks < params_.signed_min_count || marks == 0) {
    d.status = BreakpointStatus::kTooFewMutations;
    return d;
  }

  // Eq. 5-7/5-8: clusters of non-zero marks (consecutive marks at most signed_max_gap_idx apart), first one whose
  // count lies in [min, max]. Each mark is visited once.
  std::size_t i = 0;
  while (i < n) {
    while (i < n && marks_[i] == 0) ++i;
    if (i >= n) break;
    const std::size_t first = i;
    std::size_t last = i;
    std::size_t second = i;
    std::size_t before_last = i;
    std::size_t count = 1;
    std::size_t j = i + 1;
    while (j < n && j - last <= params_.signed_max_gap_idx) {
      if (marks_[j] != 0) {
        before_last = last;
        last = j;
        if (count == 1) second = j;
        ++count;
      }
      ++j;
    }
    if (count >= params_.signed_min_count && count <= params_.signed_max_count) {
      d.found = true;
      d.status = BreakpointStatus::kFound;
      d.mutation_index[0] = scan_index_of(first);
      d.mutation_index[1] = scan_index_of(second);
      d.mutation_index[2] = scan_index_of(before_last);
      d.mutation_index[3] = scan_index_of(last);
      d.left_range_m = r[last];
      d.right_range_m = r[first];
      fill_geometry(scan, first, last, d);
      // Eq. 5-9: target = (m + n) / 2, kept unrounded; the range is still read at the rounded beam.
      d.centre_angle_rad = wrap_angle(d.right_angle_rad +
                                      static_cast<Real>(0.5) * static_cast<Real>(last - first) * scan_increment_rad_);
      return d;
    }
    i = last + 1;
  }
  d.status = BreakpointStatus::kNoPattern;
  return d;
}

}  // namespace dockcore
