#include "dockcore/perception/line_segments.hpp"

namespace dockcore {
namespace {

/// Centred second moments of a point set: enough to get the TLS line and its residual, and to combine two sets
/// exactly (parallel-axis theorem) without revisiting their points.
struct Moments {
  Vec2 c = Vec2::Zero();  // centroid
  Real sxx = 0;           // Σ (x - cx)²
  Real sxy = 0;
  Real syy = 0;
  std::uint32_t n = 0;

  void add_point(const Vec2& p) {
    // Welford-style single-point update: stable, and the same formula the parallel-axis merge uses for n_b = 1.
    const Real n_old = static_cast<Real>(n);
    ++n;
    const Vec2 d = p - c;
    const Real w = n_old / static_cast<Real>(n);
    c += d / static_cast<Real>(n);
    sxx += d.x() * d.x() * w;
    sxy += d.x() * d.y() * w;
    syy += d.y() * d.y() * w;
  }
  /// Inverse of add_point for a point known to be in the set (n >= 2).
  void remove_point(const Vec2& p) {
    const Real n_new = static_cast<Real>(n - 1);
    const Vec2 c_new = (c * static_cast<Real>(n) - p) / n_new;
    const Vec2 d = p - c_new;
    const Real w = n_new / static_cast<Real>(n);
    sxx -= d.x() * d.x() * w;
    sxy -= d.x() * d.y() * w;
    syy -= d.y() * d.y() * w;
    c = c_new;
    --n;
  }
};

Moments combine(const Moments& a, const Moments& b) {
  if (a.n == 0) return b;
  if (b.n == 0) return a;
  Moments m;
  m.n = a.n + b.n;
  const Real na = static_cast<Real>(a.n);
  const Real nb = static_cast<Real>(b.n);
  const Real nt = static_cast<Real>(m.n);
  const Vec2 d = b.c - a.c;
  m.c = a.c + d * (nb / nt);
  const Real w = na * nb / nt;
  m.sxx = a.sxx + b.sxx + d.x() * d.x() * w;
  m.sxy = a.sxy + b.sxy + d.x() * d.y() * w;
  m.syy = a.syy + b.syy + d.y() * d.y() * w;
  return m;
}

/// Major-axis direction (the TLS line) and the mean squared orthogonal residual (smallest eigenvalue / n).
void principal_axis(const Moments& m, Vec2& dir, Real& mean_sq_residual) {
  const Real half_diff = (m.sxx - m.syy) * static_cast<Real>(0.5);
  const Real half_tr = (m.sxx + m.syy) * static_cast<Real>(0.5);
  const Real disc = std::sqrt(half_diff * half_diff + m.sxy * m.sxy);
  const Real lambda_min = half_tr - disc;
  mean_sq_residual = m.n > 0 && lambda_min > 0 ? lambda_min / static_cast<Real>(m.n) : static_cast<Real>(0);
  const Real theta = static_cast<Real>(0.5) * std::atan2(static_cast<Real>(2) * m.sxy, m.sxx - m.syy);
  dir = Vec2(std::cos(theta), std::sin(theta));
}

Real rms_of(const Moments& m) {
  Vec2 dir;
  Real msr = 0;
  principal_axis(m, dir, msr);
  return std::sqrt(msr);
}

/// Points in processing order: position `pos` maps to point index (start + pos) mod n, which rotates a wrapping scan
/// so that a cluster straddling index 0 is contiguous.
struct RotatedPoints {
  const ScanPointBuffer& pts;
  std::size_t start;
  std::size_t n;
  std::size_t index(std::size_t pos) const {
    const std::size_t i = start + pos;
    return i >= n ? i - n : i;
  }
  const Vec2& at(std::size_t pos) const { return pts[index(pos)].p_m; }
};

/// Centred moments over positions [lo, hi], two passes (centroid first) for accuracy far from the origin.
Moments moments_over(const RotatedPoints& rp, std::size_t lo, std::size_t hi) {
  Moments m;
  if (hi < lo) return m;
  Vec2 sum = Vec2::Zero();
  for (std::size_t pos = lo; pos <= hi; ++pos) sum += rp.at(pos);
  m.n = static_cast<std::uint32_t>(hi - lo + 1);
  m.c = sum / static_cast<Real>(m.n);
  for (std::size_t pos = lo; pos <= hi; ++pos) {
    const Vec2 d = rp.at(pos) - m.c;
    m.sxx += d.x() * d.x();
    m.sxy += d.x() * d.y();
    m.syy += d.y() * d.y();
  }
  return m;
}

/// A run of positions [lo, hi] with the moments of the points that its fit uses.
struct Piece {
  std::size_t lo = 0;
  std::size_t hi = 0;
  std::size_t contig_lo = 0;  // [contig_lo, hi] are all in m (merges across skipped points break contiguity)
  Moments m;
};

class Extractor {
 public:
  Extractor(const RotatedPoints& rp, Real angle_increment_rad, const SegmentParams& params, LineSegmentBuffer& out,
            SegmentStats& stats)
      : rp_(rp), inc_(angle_increment_rad), params_(params), out_(out), stats_(stats) {}

  /// Splits, fits and merges the cluster at positions [lo, hi].
  void process_cluster(std::size_t lo, std::size_t hi, std::uint32_t cluster_id) {
    cluster_id_ = cluster_id;
    has_pending_ = false;
    struct Range {
      std::uint32_t lo;
      std::uint32_t hi;
    };
    FixedVector<Range, kSegmentSplitStackDepth> stack;
    stack.push_back(Range{static_cast<std::uint32_t>(lo), static_cast<std::uint32_t>(hi)});
    while (!stack.empty()) {
      const Range r = stack.back();
      stack.pop_back();
      const std::size_t count = static_cast<std::size_t>(r.hi - r.lo) + 1;
      if (count >= 3) {
        if (stats_.split_iterations >= params_.max_split_iterations) {
          ++stats_.unsplit_ranges;
        } else {
          ++stats_.split_iterations;
          const std::size_t k = farthest_from_chord(r.lo, r.hi);
          if (k != 0) {
            if (stack.size() + 2 <= stack.capacity()) {
              // Right half first so the left half is popped next: leaves come out in scan order. The split point
              // belongs to both halves, so a corner's point anchors both sides' chords.
              stack.push_back(Range{static_cast<std::uint32_t>(k), r.hi});
              stack.push_back(Range{r.lo, static_cast<std::uint32_t>(k)});
              continue;
            }
            ++stats_.unsplit_ranges;
          }
        }
      }
      leaf(r.lo, r.hi);
    }
    flush();
  }

 private:
  /// Position strictly inside (lo, hi) farthest from the chord, or 0 when none exceeds the split threshold.
  std::size_t farthest_from_chord(std::size_t lo, std::size_t hi) const {
    const Vec2 a = rp_.at(lo);
    const Vec2 ab = rp_.at(hi) - a;
    const Real len = ab.norm();
    // Degenerate chord (closed loop or repeated point): fall back to distance from the first point.
    const bool use_chord = len > static_cast<Real>(1e-6);
    const Vec2 nrm = use_chord ? Vec2(Vec2(-ab.y(), ab.x()) / len) : Vec2(Vec2::Zero());
    Real best = params_.split_threshold_m;
    std::size_t best_pos = 0;
    for (std::size_t pos = lo + 1; pos < hi; ++pos) {
      const Vec2 d = rp_.at(pos) - a;
      const Real dist = use_chord ? std::fabs(nrm.dot(d)) : d.norm();
      if (dist > best) {
        best = dist;
        best_pos = pos;
      }
    }
    return best_pos;
  }

  void leaf(std::size_t lo, std::size_t hi) {
    const std::size_t count = hi - lo + 1;
    if (count < params_.min_points) {
      ++stats_.rejected_short;
      return;
    }
    // A piece that starts on the previous piece's last point (a split corner) shares it. Merging uses the piece's
    // exclusive moments so the point is not counted twice; otherwise place_corner decides where the boundary goes.
    const bool shared = has_pending_ && lo == pending_.hi;
    const Moments excl = moments_over(rp_, shared ? lo + 1 : lo, hi);

    if (has_pending_ && lo <= pending_.hi + params_.merge_max_skipped_points + 1) {
      // Collinear = the combined fit explains both pieces as well as noise allows. No angle test: pieces that
      // IEPF cuts out of a noisy wall (3-5 points between two spikes) zig-zag by up to ~70°, yet belong to it.
      const Moments merged = combine(pending_.m, excl);
      if (rms_of(merged) <= params_.merge_max_rms_m) {
        // Points strictly between the pieces (skipped crumbs) are not in the moments, so only the new piece's
        // part is a contiguous tail that corner refinement may later move.
        if (lo > pending_.hi + 1) pending_.contig_lo = lo;
        pending_.m = merged;
        pending_.hi = hi;
        return;
      }
    }
    Piece p;
    p.lo = lo;
    p.hi = hi;
    p.m = excl;
    p.contig_lo = shared ? lo + 1 : lo;
    if (shared) place_corner(lo, p);
    flush();
    if (p.contig_lo > p.lo) p.contig_lo = p.lo;
    pending_ = p;
    has_pending_ = true;
  }

  /// Places the boundary between the pending piece (which ends on split point k) and the new piece `p` (holding
  /// k+1..hi). The split point is only the sample farthest from a chord; with noise it is often a neighbour of the
  /// true corner, and a sample of one side left in the other's fit tilts it by ~(spacing·lever)/(n·L²/12) — degrees
  /// for a 0.2 m side. So try every boundary within corner_refine_points of k and keep the one with the smallest
  /// total squared residual; moments are moved one point at a time, O(1) each. Both sides must keep min_points; if
  /// no boundary allows that, k is shared by both (a side seen with min_points returns at grazing incidence).
  void place_corner(std::size_t k, Piece& p) {
    const std::size_t min_n = params_.min_points > 2 ? params_.min_points : 2;
    const std::size_t reach = params_.corner_refine_points;
    const auto cost = [](const Moments& a, const Moments& b) {
      Vec2 dir;
      Real msr_a = 0;
      Real msr_b = 0;
      principal_axis(a, dir, msr_a);
      principal_axis(b, dir, msr_b);
      return msr_a * static_cast<Real>(a.n) + msr_b * static_cast<Real>(b.n);
    };
    bool have = false;
    Real best_cost = 0;
    std::size_t best_e = k;  // last position of the pending piece
    // Boundary at k and further left: pending gives up its tail to p.
    Moments a = pending_.m;
    Moments b = p.m;
    for (std::size_t e = k;; --e) {
      if (a.n >= min_n && b.n >= min_n) {
        const Real c = cost(a, b);
        if (!have || c < best_cost) {
          have = true;
          best_cost = c;
          best_e = e;
        }
      }
      if (k - e >= reach || e <= pending_.contig_lo || e <= pending_.lo || a.n <= min_n) break;
      a.remove_point(rp_.at(e));
      b.add_point(rp_.at(e));
    }
    // Boundary right of k: p gives up its head to pending.
    a = pending_.m;
    b = p.m;
    for (std::size_t e = k + 1; e - k <= reach && e < p.hi && b.n > min_n; ++e) {
      b.remove_point(rp_.at(e));
      a.add_point(rp_.at(e));
      const Real c = cost(a, b);
      if (!have || c < best_cost) {
        have = true;
        best_cost = c;
        best_e = e;
      }
    }
    if (!have) {
      p.m.add_point(rp_.at(k));  // k shared by both
      p.lo = k;
      return;
    }
    for (std::size_t e = k; e > best_e; --e) {
      pending_.m.remove_point(rp_.at(e));
      p.m.add_point(rp_.at(e));
    }
    for (std::size_t e = k + 1; e <= best_e; ++e) {
      p.m.remove_point(rp_.at(e));
      pending_.m.add_point(rp_.at(e));
    }
    pending_.hi = best_e;
    p.lo = best_e + 1;
  }

  /// Emits the pending piece as a segment if it is long enough.
  void flush() {
    if (!has_pending_) return;
    has_pending_ = false;
    const Piece& p = pending_;
    Vec2 dir;
    Real msr = 0;
    principal_axis(p.m, dir, msr);
    const Vec2 first_p = rp_.at(p.lo);
    const Vec2 last_p = rp_.at(p.hi);
    if (dir.dot(last_p - first_p) < 0) dir = -dir;
    // Scan order runs counter-clockwise about the sensor for a positive increment, so the sensor lies to the left.
    const Vec2 normal = inc_ >= 0 ? Vec2(-dir.y(), dir.x()) : Vec2(dir.y(), -dir.x());
    LineSegment s;
    s.start_m = p.m.c + dir * dir.dot(first_p - p.m.c);
    s.end_m = p.m.c + dir * dir.dot(last_p - p.m.c);
    s.normal = normal;
    s.offset_m = normal.dot(p.m.c);
    s.rms_m = std::sqrt(msr);
    s.first = static_cast<std::uint32_t>(rp_.index(p.lo));
    s.last = static_cast<std::uint32_t>(rp_.index(p.hi));
    s.point_count = p.m.n;
    s.cluster = cluster_id_;
    if (s.length_m() < params_.min_length_m) {
      ++stats_.rejected_short;
      return;
    }
    if (!out_.push_back(s)) ++stats_.segments_dropped;
  }

  const RotatedPoints& rp_;
  Real inc_;
  const SegmentParams& params_;
  LineSegmentBuffer& out_;
  SegmentStats& stats_;
  Piece pending_;
  bool has_pending_ = false;
  std::uint32_t cluster_id_ = 0;
};

/// True when consecutive points a -> b do not belong to one cluster.
bool is_break(const ScanPoint& a, const ScanPoint& b, Real inc_abs, const SegmentParams& params) {
  const Real dtheta = std::fabs(wrap_angle(b.angle_rad - a.angle_rad));
  if (inc_abs > 0 &&
      dtheta > inc_abs * (static_cast<Real>(params.cluster_max_missing_beams) + static_cast<Real>(1.5))) {
    return true;
  }
  const Real r = a.range_m < b.range_m ? a.range_m : b.range_m;
  const Real range_term = params.cluster_gap_k * r * dtheta + params.cluster_noise_margin_m;
  const Real thr = range_term > params.cluster_abs_gap_m ? range_term : params.cluster_abs_gap_m;
  return (b.p_m - a.p_m).squaredNorm() > thr * thr;
}

/// Clusters the points in rotated order from `start` and extracts each cluster's segments into `out`.
void run_clusters(const ScanPointBuffer& points, std::size_t start, Real angle_increment_rad, const SegmentParams& params,
                  LineSegmentBuffer& out, SegmentStats& stats) {
  const std::size_t n = points.size();
  const Real inc_abs = std::fabs(angle_increment_rad);
  const RotatedPoints rp{points, start, n};
  Extractor ex(rp, angle_increment_rad, params, out, stats);
  std::size_t cluster_lo = 0;
  for (std::size_t pos = 1; pos <= n; ++pos) {
    const bool end_here = pos == n || is_break(points[rp.index(pos - 1)], points[rp.index(pos)], inc_abs, params);
    if (!end_here) continue;
    if (stats.clusters >= params.max_clusters) {
      ++stats.clusters_dropped;
    } else {
      const std::uint32_t id = stats.clusters++;
      if (pos - cluster_lo >= params.min_points) {
        ex.process_cluster(cluster_lo, pos - 1, id);
      } else {
        ++stats.rejected_short;
      }
    }
    cluster_lo = pos;
  }
}

}  // namespace

bool fit_line_tls(const Vec2* points_m, std::size_t count, LineFit& fit) {
  if (points_m == nullptr || count < 2) return false;
  Vec2 sum = Vec2::Zero();
  for (std::size_t i = 0; i < count; ++i) sum += points_m[i];
  Moments m;
  m.n = static_cast<std::uint32_t>(count);
  m.c = sum / static_cast<Real>(count);
  for (std::size_t i = 0; i < count; ++i) {
    const Vec2 d = points_m[i] - m.c;
    m.sxx += d.x() * d.x();
    m.sxy += d.x() * d.y();
    m.syy += d.y() * d.y();
  }
  if (m.sxx + m.syy <= 0) return false;
  Vec2 dir;
  Real msr = 0;
  principal_axis(m, dir, msr);
  fit.centroid_m = m.c;
  fit.direction = dir;
  fit.rms_m = std::sqrt(msr);
  fit.count = m.n;
  return true;
}

SegmentStats extract_line_segments(const ScanPointBuffer& points, Real angle_increment_rad, bool wraps,
                                   const SegmentParams& params, LineSegmentBuffer& out) {
  SegmentStats stats;
  out.clear();
  const std::size_t n = points.size();
  if (n < 2) return stats;
  const Real inc_abs = std::fabs(angle_increment_rad);

  // Choose the processing start. Without a wrap, position 0 is index 0. With a wrap joining the last and first
  // points, start right after some gap so that no cluster is cut at index 0; a contour with no gap at all (a closed
  // room) is cut at its widest step.
  std::size_t start = 0;
  bool closed = false;
  if (wraps && !is_break(points[n - 1], points[0], inc_abs, params)) {
    stats.wrapped = true;
    bool found_gap = false;
    for (std::size_t i = 0; i + 1 < n; ++i) {
      if (is_break(points[i], points[i + 1], inc_abs, params)) {
        start = i + 1;
        found_gap = true;
        break;
      }
    }
    closed = !found_gap;
    if (!found_gap) {
      Real widest = -1;
      for (std::size_t i = 0; i < n; ++i) {
        const std::size_t j = i + 1 == n ? 0 : i + 1;
        const Real d = (points[j].p_m - points[i].p_m).squaredNorm();
        if (d > widest) {
          widest = d;
          start = j;
        }
      }
    }
  }

  run_clusters(points, start, angle_increment_rad, params, out, stats);
  if (closed && out.size() >= 2) {
    // A closed contour (no gap anywhere) was cut at its widest step, which may fall inside a wall and leave that wall
    // in two pieces at the ends of the list. The first piece ends at a split point — a corner — so cut just after it instead.
    const std::size_t corner = out[0].last + 1 == n ? 0 : out[0].last + 1;
    out.clear();
    const bool wrapped = stats.wrapped;
    stats = SegmentStats{};
    stats.wrapped = wrapped;
    run_clusters(points, corner, angle_increment_rad, params, out, stats);
  }
  return stats;
}

}  // namespace dockcore
