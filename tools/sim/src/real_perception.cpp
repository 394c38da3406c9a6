// Dock-detector measurements on real recordings (see docksim/real_perception.hpp).
#include "docksim/real_perception.hpp"
#include "docksim/angles.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <vector>

#include "dockcore/perception/dock_pose_filter.hpp"
#include "dockcore/perception/line_segments.hpp"
#include "dockcore/perception/profile_geometry.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/scenes.hpp"
#include "docksim/sim_run.hpp"

namespace docksim {
namespace {

using dockcore::DockPoseEstimator;
using dockcore::LaserScan;
using dockcore::Pose2;
using dockcore::Real;
using dockcore::ScanView;
using dockcore::Vec2;

double wrap(double a) {
  return std::remainder(a, kTwoPiD);
}

bool agree(const Pose2& a, const Pose2& b, double max_m, double max_rad) {
  const double dx = static_cast<double>(a.x_m - b.x_m);
  const double dy = static_cast<double>(a.y_m - b.y_m);
  return std::hypot(dx, dy) <= max_m && std::fabs(wrap(static_cast<double>(a.yaw_rad - b.yaw_rad))) <= max_rad;
}

std::uint64_t fnv1a(std::uint64_t h, const char* s) {
  for (; s != nullptr && *s != '\0'; ++s) {
    h ^= static_cast<unsigned char>(*s);
    h *= 0x100000001B3ull;
  }
  return h * 0x100000001B3ull;  // separates "ab"+"c" from "a"+"bc"
}

bool wraps(const ScanView& scan) {
  return scan.wraps();
}

/// Beams of `scan` whose angles cover [lo, hi] (radians, any multiple of 2π) plus `margin` beams each side. False
/// when that interval leaves a partial scan's field of view. Indices are wrapped on full-turn scans.
bool beams_covering(const ScanView& scan, double lo, double hi, std::size_t margin, std::vector<std::size_t>* out) {
  out->clear();
  const double amin = static_cast<double>(scan.angle_min_rad);
  const double inc = static_cast<double>(scan.angle_increment_rad);
  const std::size_t n = scan.count;
  if (n < 2 || !(inc > 0)) return false;
  const double amax = amin + inc * static_cast<double>(n - 1);
  // Bring the interval to the turn nearest the field of view's centre.
  const double fov_c = 0.5 * (amin + amax);
  const double c = 0.5 * (lo + hi);
  const double shift = fov_c + wrap(c - fov_c) - c;
  lo += shift;
  hi += shift;
  const long first = static_cast<long>(std::ceil((lo - amin) / inc)) - static_cast<long>(margin);
  const long last = static_cast<long>(std::floor((hi - amin) / inc)) + static_cast<long>(margin);
  if (last < first) return false;
  const long nl = static_cast<long>(n);
  if (wraps(scan)) {
    if (last - first + 1 > nl) return false;
    for (long i = first; i <= last; ++i) out->push_back(static_cast<std::size_t>(((i % nl) + nl) % nl));
    return true;
  }
  if (first < 0 || last >= nl) return false;
  for (long i = first; i <= last; ++i) out->push_back(static_cast<std::size_t>(i));
  return true;
}

Vec2 beam_dir(const ScanView& scan, std::size_t i) {
  const Real a = scan.angle_rad(i);
  return Vec2(std::cos(a), std::sin(a));
}

double occluder_tolerance(double sigma_m, double resolution_m) {
  return std::max({4.0 * sigma_m, resolution_m, 0.02});
}

/// Working memory of the site search (ScanPoints alone is ~160 kB, too much for the stack).
struct SiteScratch {
  dockcore::ScanPoints points;
  dockcore::LineSegments segments;
  dockcore::PlacedProfile placed;
  std::vector<std::size_t> beams;
};

/// The dock at `pose` lies wholly in the field of view (with margin beams), and every beam it would catch sees
/// nothing nearer than the dock. `free_behind_m` > 0 additionally asks every beam of the span to see that far past
/// the dock's farthest vertex (or nothing).
bool site_clean(const ScanView& scan, const dockcore::DockProfile& profile, const Pose2& pose, double tol_m,
                std::size_t margin_beams, double free_behind_m, SiteScratch& s) {
  s.placed.place(profile, pose);
  Real lo = 0, hi = 0;
  s.placed.angular_span(&lo, &hi);
  if (!beams_covering(scan, static_cast<double>(lo), static_cast<double>(hi), margin_beams, &s.beams)) return false;
  double far_m = 0;
  for (std::size_t i = 0; i < profile.vertex_count; ++i)
    far_m = std::max(far_m, static_cast<double>(s.placed.v_m[i].norm()));
  for (const std::size_t i : s.beams) {
    const double bg = static_cast<double>(scan.ranges_m[i]);
    if (free_behind_m > 0 && bg > 0 && bg < far_m + free_behind_m) return false;
    Real r = 0;
    std::size_t seg = 0;
    if (s.placed.raycast(beam_dir(scan, i), &r, &seg) && bg > 0 && bg < static_cast<double>(r) - tol_m) return false;
  }
  return true;
}

double back_plane_x(const dockcore::DockProfile& p) {
  double x = static_cast<double>(p.vertices_m[0].x());
  for (std::size_t i = 1; i < p.vertex_count; ++i) x = std::min(x, static_cast<double>(p.vertices_m[i].x()));
  return x;
}

}  // namespace

dockcore::EstimatorParams real_estimator_params(const RealRecording& rec, const EstimatorOverrides& overrides) {
  return overrides.for_noise(rec.sigma_m);
}

const char* to_string(ConfirmFrame f) {
  switch (f) {
    case ConfirmFrame::kNone:
      return "none";
    case ConfirmFrame::kWorld:
      return "world";
    case ConfirmFrame::kSensor:
      return "sensor";
  }
  return "?";
}

const char* to_string(CompositeKind k) {
  switch (k) {
    case CompositeKind::kWallFlush:
      return "wall-flush";
    case CompositeKind::kWallGap:
      return "wall-gap";
    case CompositeKind::kFreeStanding:
      return "free-standing";
  }
  return "?";
}

// ---------------------------------------------------------------- false positives

namespace {

/// Loads scan `j` of the recording, as seen in the confirmation window that starts at scan `window` (the single-scan
/// pass loads scan i as window i's first), into `out`. False when the scan cannot be used.
using ScanLoader = std::function<bool(std::size_t window, std::size_t j, LaserScan* out)>;

/// The false-positive measurement of measure_real_false_positives over scans given by `load`, with the estimators'
/// intensity use set to `intensity_usable`.
RealFpResult measure_fp(const LoadedRecording& rec, const dockcore::DockProfile& profile, const ConfirmRule& rule,
                        const ScanLoader& load, bool intensity_usable, const EstimatorOverrides& overrides) {
  RealFpResult out;
  const std::size_t n = rec.scans.size();
  auto est = std::make_unique<DockPoseEstimator>();
  auto tracker = std::make_unique<DockPoseEstimator>();  // hinted estimates; keeps est's counters single-scan
  const dockcore::EstimatorParams params = real_estimator_params(*rec.info, overrides);
  if (!est->configure(profile, params) || !tracker->configure(profile, params)) return out;
  est->set_intensity_usable(intensity_usable);
  tracker->set_intensity_usable(intensity_usable);
  auto scan = std::make_unique<LaserScan>();
  const Pose2 mount = real_lidar_mount();
  std::vector<char> found(n, 0);
  std::vector<Pose2> pose(n);
  std::vector<double> evidence(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!load(i, i, scan.get())) continue;  // the reader already refuses > kMaxScanPoints
    ++out.scans;
    const dockcore::DockEstimate e = est->estimate(scan->view(), mount);
    if (!e.found) continue;
    found[i] = 1;
    pose[i] = e.pose;
    evidence[i] = static_cast<double>(e.evidence.total_nats);
    ++out.found;
    if (out.examples.size() < kMaxFalseDockExamples) out.examples.push_back(FalseDock{i, e.pose});
  }
  out.counters = est->counters();

  if (!rec.has_poses() || rule.scans < 1) return out;
  const bool is_static = rec.info->poses == PoseSource::kStatic;
  out.frame = is_static ? ConfirmFrame::kSensor : ConfirmFrame::kWorld;
  const std::size_t w = static_cast<std::size_t>(rule.scans);
  const double max_gap_us = rule.static_max_gap_s * 1e6;
  for (std::size_t i = 0; i + w <= n; ++i) {
    if (is_static) {
      bool close = true;
      for (std::size_t k = 1; k < w && close; ++k) {
        const std::uint64_t a = rec.scans[i + k - 1].stamp_us, b = rec.scans[i + k].stamp_us;
        close = b > a && static_cast<double>(b - a) <= max_gap_us;
      }
      if (!close) continue;
    }
    ++out.windows;
    if (!found[i]) continue;
    ++out.attempts;
    // The lidar sits at the robot's origin (real_lidar_mount), so the robot frame is the sensor frame.
    const Pose2 first_world = rec.sensor_in_world[i].compose(pose[i]);
    bool confirmed = true;
    double evidence_nats = evidence[i];
    for (std::size_t k = 1; k < w && confirmed; ++k) {
      const std::size_t j = i + k;
      const Pose2 hint = rec.sensor_in_world[j].inverse().compose(first_world);
      confirmed = load(i, j, scan.get());
      if (!confirmed) break;
      const dockcore::DockEstimate e = tracker->estimate(scan->view(), mount, &hint);
      confirmed = e.found && agree(rec.sensor_in_world[j].compose(e.pose), first_world, rule.agree_m, rule.agree_rad);
      evidence_nats += static_cast<double>(e.evidence.total_nats);
    }
    if (confirmed) {
      ++out.confirmed;
      if (evidence_nats >= static_cast<double>(dockcore::DockFilterParams{}.confirm_evidence_nats)) {
        ++out.confirmed_sequential;
      }
      if (out.confirmed_starts.size() < kMaxFalseDockExamples) out.confirmed_starts.push_back(i);
    }
  }
  return out;
}

/// One pasted world per window: its objects, in the world frame of the window's first scan.
struct PastedClutter {
  World world;
  int objects = 0;
};

/// Draws the window's reflective clutter in the free space of `first` (its sensor frame = `sensor_in_world`).
PastedClutter draw_clutter(const ScanView& first, const Pose2& sensor_in_world, const ReflectiveClutterOptions& o,
                           Rng& rng) {
  PastedClutter c;
  const int wanted = o.objects_max > 0 ? 1 + static_cast<int>(rng.uniform() * o.objects_max) : 0;
  const double amin = static_cast<double>(first.angle_min_rad);
  const double inc = static_cast<double>(first.angle_increment_rad);
  const double span = inc * static_cast<double>(first.count > 0 ? first.count - 1 : 0);
  auto to_world = [&sensor_in_world](double x, double y) {
    return sensor_in_world.transform(Vec2(static_cast<Real>(x), static_cast<Real>(y)));
  };
  for (int k = 0; k < wanted; ++k) {
    for (int attempt = 0; attempt < 20; ++attempt) {
      const double d = rng.uniform(o.min_range_m, o.max_range_m);
      const double b = amin + rng.uniform() * span;
      // Free space: the real returns over the object's angular size lie well beyond it (or there are none).
      const double half_rad = std::atan2(0.35, d);
      bool free = true;
      for (long i = static_cast<long>(std::floor((b - half_rad - amin) / inc));
           free && i <= static_cast<long>(std::ceil((b + half_rad - amin) / inc)); ++i) {
        if (i < 0 || i >= static_cast<long>(first.count)) continue;
        const double r = static_cast<double>(first.ranges_m[i]);
        free = !(r > 0 && r < d + 0.3);
      }
      if (!free) continue;
      const double cx = d * std::cos(b), cy = d * std::sin(b);
      const int kind = static_cast<int>(rng.uniform() * 3);
      if (kind == 0) {  // a sign facing the lidar within ±40°
        const double len = rng.uniform(0.2, 0.6);
        const double face = b + kPiD + rng.uniform(-40.0, 40.0) * kPiD / 180.0;
        const double tx = -std::sin(face), ty = std::cos(face);  // along the board
        // Tape: all over, or 1-3 stripes of 3-15 cm at random places (overlaps merge).
        std::vector<std::pair<double, double>> tape;
        if (rng.uniform() < 1.0 / 3.0) {
          tape.emplace_back(0.0, len);
        } else {
          const int stripes = 1 + static_cast<int>(rng.uniform() * 3);
          for (int q = 0; q < stripes; ++q) {
            const double w = std::min(len, rng.uniform(0.03, 0.15));
            const double from = rng.uniform(0.0, len - w);
            tape.emplace_back(from, from + w);
          }
        }
        // Cut the board at every tape edge; each piece is taped when its middle lies in a stripe.
        std::vector<double> cuts{0.0, len};
        for (const auto& t : tape) {
          cuts.push_back(t.first);
          cuts.push_back(t.second);
        }
        std::sort(cuts.begin(), cuts.end());
        const double reflectivity = rng.uniform(0.1, 1.0);
        for (std::size_t q = 0; q + 1 < cuts.size(); ++q) {
          if (cuts[q + 1] - cuts[q] < 1e-6) continue;
          const double mid = 0.5 * (cuts[q] + cuts[q + 1]);
          bool taped = false;
          for (const auto& t : tape) taped = taped || (mid >= t.first && mid <= t.second);
          const double s0 = cuts[q] - 0.5 * len, s1 = cuts[q + 1] - 0.5 * len;
          Segment seg;
          seg.a = to_world(cx + s0 * tx, cy + s0 * ty);
          seg.b = to_world(cx + s1 * tx, cy + s1 * ty);
          seg.reflectivity = reflectivity;
          seg.retro = taped;
          c.world.segments.push_back(seg);
        }
      } else if (kind == 1) {  // a safety vest: the band all round the torso
        const std::size_t before = c.world.segments.size();
        c.world.add_circle(to_world(cx, cy), rng.uniform(0.15, 0.2), 12, 0.5);
        for (std::size_t q = before; q < c.world.segments.size(); ++q) c.world.segments[q].retro = true;
      } else {  // chrome legs
        const double side = rng.uniform(0.40, 0.50), radius = rng.uniform(0.01, 0.015);
        const double yaw = rng.uniform(-kPiD, kPiD);
        const std::size_t before = c.world.segments.size();
        for (int q = 0; q < 4; ++q) {
          const double lx = (q & 1 ? 0.5 : -0.5) * side, ly = (q & 2 ? 0.5 : -0.5) * side;
          c.world.add_circle(
              to_world(cx + lx * std::cos(yaw) - ly * std::sin(yaw), cy + lx * std::sin(yaw) + ly * std::cos(yaw)),
              radius, 8, 0.9);
        }
        for (std::size_t q = before; q < c.world.segments.size(); ++q) {
          c.world.segments[q].retro = true;
          c.world.segments[q].retro_cutoff_rad = 12.0 * kPiD / 180.0;
        }
      }
      ++c.objects;
      break;
    }
  }
  return c;
}

/// A reflectivity for the world cell around (x, y): uniform 0.1-1.0, the same for every scan that sees the cell.
double cell_reflectivity(std::uint64_t seed, double x, double y) {
  const auto cx = static_cast<std::int64_t>(std::floor(x / 0.5));
  const auto cy = static_cast<std::int64_t>(std::floor(y / 0.5));
  Rng r(seed ^ (static_cast<std::uint64_t>(cx) * 0x9E3779B97F4A7C15ull) ^
        (static_cast<std::uint64_t>(cy) * 0xC2B2AE3D27D4EB4Full));
  return r.uniform(0.1, 1.0);
}

}  // namespace

RealFpResult measure_real_false_positives(const LoadedRecording& rec, const dockcore::DockProfile& profile,
                                          const ConfirmRule& rule, const EstimatorOverrides& overrides) {
  const ScanLoader load = [&rec](std::size_t, std::size_t j, LaserScan* out) {
    return rec.scans[j].to_laser_scan(out);
  };
  return measure_fp(rec, profile, rule, load, false, overrides);
}

RealFpResult measure_real_reflector_false_positives(const LoadedRecording& rec, const dockcore::DockProfile& profile,
                                                    const ReflectiveClutterOptions& options, const ConfirmRule& rule) {
  LidarModel ld06;
  lidar_model("ld06", &ld06);
  const RangeNoise noise{rec.info->sigma_m, rec.info->resolution_m};
  const std::uint64_t rec_seed = fnv1a(options.seed * 0x100000001B3ull, rec.info->name);
  const bool posed = rec.has_poses();
  // The clutter of the window loaded last (the single-scan pass draws scan i's as window i's; the window pass then
  // draws each window's again, the same for the same seed).
  std::size_t clutter_window = static_cast<std::size_t>(-1);
  PastedClutter clutter;
  auto first = std::make_unique<LaserScan>();
  std::vector<Vec2> pts;
  const ScanLoader load = [&](std::size_t window, std::size_t j, LaserScan* out) {
    if (window != clutter_window) {
      if (!rec.scans[window].to_laser_scan(first.get())) return false;
      Rng rng(trial_seed(rec_seed, window));
      clutter = draw_clutter(first->view(), posed ? rec.sensor_in_world[window] : Pose2{}, options, rng);
      clutter_window = window;
    }
    if (!rec.scans[j].to_laser_scan(out)) return false;
    // Poses place the clutter in scan j; without them only the window's own first scan is used.
    const Pose2 sensor = posed ? rec.sensor_in_world[j] : Pose2{};
    Rng rng(trial_seed(rec_seed ^ 0x5045u, j * 7919u + window));
    const std::size_t n = out->count;
    const ScanView v = out->view();
    pts.assign(n, Vec2::Zero());
    for (std::size_t i = 0; i < n; ++i) {
      const Real a = v.angle_rad(i);
      pts[i] = out->ranges_m[i] * Vec2(std::cos(a), std::sin(a));
    }
    // Real returns: diffuse intensities, the incidence from the line through the neighbours.
    for (std::size_t i = 0; i < n; ++i) {
      const double r = static_cast<double>(out->ranges_m[i]);
      if (!(r > 0)) {
        out->intensities[i] = 0;
        continue;
      }
      double cos_i = 1.0;
      if (i > 0 && i + 1 < n && out->ranges_m[i - 1] > 0 && out->ranges_m[i + 1] > 0 &&
          (pts[i + 1] - pts[i - 1]).norm() < static_cast<Real>(0.1)) {
        const Vec2 t = (pts[i + 1] - pts[i - 1]).normalized();
        const Vec2 d = pts[i].normalized();
        cos_i = std::fabs(static_cast<double>(t.x() * d.y() - t.y() * d.x()));
      }
      const Vec2 w = sensor.transform(pts[i]);
      Segment diffuse;
      diffuse.reflectivity = cell_reflectivity(rec_seed, static_cast<double>(w.x()), static_cast<double>(w.y()));
      out->intensities[i] = static_cast<Real>(sensor_intensity(ld06, surface_intensity(ld06, diffuse, r, cos_i)));
    }
    if (clutter.objects == 0 || (!posed && j != window)) return true;
    // Pasted objects: a nearer hit replaces the real return, its intensity the footprint's mean as simulate_scan
    // takes it.
    const Vec2 origin(sensor.x_m, sensor.y_m);
    const double half_div = 0.5 * ld06.beam_divergence_rad;
    for (std::size_t i = 0; i < n; ++i) {
      const double theta = static_cast<double>(v.angle_rad(i) + sensor.yaw_rad);
      double t = 0, raw = 0;
      for (const double side : {0.0, -half_div, half_div}) {
        const Vec2 dir(static_cast<Real>(std::cos(theta + side)), static_cast<Real>(std::sin(theta + side)));
        double ts = 0;
        std::size_t k = 0;
        if (!clutter.world.raycast_segment(origin, dir, 12.0, &ts, &k)) continue;
        const Segment& sg = clutter.world.segments[k];
        const double ex = static_cast<double>(sg.b.x() - sg.a.x()), ey = static_cast<double>(sg.b.y() - sg.a.y());
        const double c =
            std::fabs(static_cast<double>(dir.x()) * ey - static_cast<double>(dir.y()) * ex) / std::hypot(ex, ey);
        raw += surface_intensity(ld06, sg, ts, c);
        if (side == 0.0) t = ts;
      }
      const double real_r = static_cast<double>(out->ranges_m[i]);
      if (!(t > 0) || (real_r > 0 && real_r < t)) continue;
      out->ranges_m[i] = static_cast<Real>(noise.apply(t, rng));
      out->intensities[i] = static_cast<Real>(sensor_intensity(ld06, raw / 3.0));
    }
    return true;
  };
  return measure_fp(rec, profile, rule, load, true, options.overrides);
}

// ---------------------------------------------------------------- composites

double RangeNoise::apply(double range_m, Rng& rng) const {
  const double quant_var = resolution_m > 0 ? resolution_m * resolution_m / 12.0 : 0.0;
  const double extra = std::sqrt(std::max(0.0, sigma_m * sigma_m - quant_var));
  double r = range_m + (extra > 0 ? rng.normal(0.0, extra) : 0.0);
  if (resolution_m > 0) r = std::round(r / resolution_m) * resolution_m;
  return r;
}

bool find_composite_site(const ScanView& scan, const dockcore::DockProfile& profile, CompositeKind kind, double sigma_m,
                         const CompositeSiteParams& p, Rng& rng, CompositeSite* out) {
  const auto scratch = std::make_unique<SiteScratch>();
  SiteScratch& s = *scratch;
  const double tol = occluder_tolerance(sigma_m, 0);
  const double back_x = back_plane_x(profile);
  if (kind == CompositeKind::kFreeStanding) {
    const bool full = scan.wraps();
    const double amin = static_cast<double>(scan.angle_min_rad);
    const double amax = amin + static_cast<double>(scan.angle_increment_rad) * static_cast<double>(scan.count - 1);
    for (int a = 0; a < p.attempts; ++a) {
      const double d = rng.uniform(p.free_min_m, p.free_max_m);
      const double b = full ? rng.uniform(-kPiD, kPiD) : rng.uniform(amin, amax);
      const double y = rng.uniform(-p.free_yaw_rad, p.free_yaw_rad);
      const Pose2 pose = dock_pose_from_lidar(d, b, y);
      if (!site_clean(scan, profile, pose, tol, p.margin_beams, p.free_behind_m, s)) continue;
      *out = CompositeSite{kind, pose, 0};
      return true;
    }
    return false;
  }
  // Wall kinds: long, straight segments of the returns in range.
  dockcore::scan_to_points(scan, Pose2{}, static_cast<Real>(p.min_range_m), static_cast<Real>(p.max_range_m), s.points);
  dockcore::SegmentParams sp;
  sp.split_threshold_m = static_cast<Real>(std::max(4.0 * sigma_m, 0.015));
  sp.merge_max_rms_m = static_cast<Real>(std::max(2.0 * sigma_m, 0.006));
  dockcore::extract_line_segments(s.points, scan, sp, s.segments);
  const double width = static_cast<double>(profile.width_m());
  const double need = width + 2.0 * p.margin_m;
  const double max_rms = std::max(2.0 * sigma_m, 0.005);
  std::vector<std::size_t> walls;
  for (std::size_t k = 0; k < s.segments.size(); ++k) {
    const dockcore::LineSegment& g = s.segments[k];
    if (static_cast<double>(g.length_m()) >= need && static_cast<double>(g.rms_m) <= max_rms) walls.push_back(k);
  }
  if (walls.empty()) return false;
  for (int a = 0; a < p.attempts; ++a) {
    const dockcore::LineSegment& g = s.segments[walls[rng.next_u64() % walls.size()]];
    const double len = static_cast<double>(g.length_m());
    const double along = rng.uniform(p.margin_m + 0.5 * width, len - p.margin_m - 0.5 * width);
    const Vec2 on_wall = g.start_m + g.direction() * static_cast<Real>(along);
    const Vec2 n = g.normal;  // towards the lidar
    const double gap = kind == CompositeKind::kWallGap ? rng.uniform(p.gap_min_m, p.gap_max_m) : 0.0;
    const Vec2 origin = on_wall + n * static_cast<Real>(gap - back_x);
    const double dist = static_cast<double>(origin.norm());
    if (dist < p.min_range_m || dist > p.max_range_m) continue;
    const double cos_inc = static_cast<double>(n.dot(-origin)) / dist;
    if (cos_inc < std::cos(p.max_incidence_rad)) continue;
    const Pose2 pose{origin.x(), origin.y(), std::atan2(n.y(), n.x())};
    if (!site_clean(scan, profile, pose, tol, p.margin_beams, 0, s)) continue;
    *out = CompositeSite{kind, pose, gap};
    return true;
  }
  return false;
}

std::size_t paste_dock(const ScanView& background, const dockcore::DockProfile& profile, const Pose2& dock_in_sensor,
                       const RangeNoise& noise, Rng& rng, LaserScan* out, std::size_t* occluded) {
  std::size_t replaced = 0, hidden = 0;
  if (!out->reset(background.count, background.angle_min_rad, background.angle_increment_rad, background.stamp_us)) {
    return 0;
  }
  for (std::size_t i = 0; i < background.count; ++i) {
    out->ranges_m[i] = background.ranges_m[i];
    out->intensities[i] = background.intensities != nullptr ? background.intensities[i] : 0;
  }
  dockcore::PlacedProfile placed;
  placed.place(profile, dock_in_sensor);
  Real lo = 0, hi = 0;
  placed.angular_span(&lo, &hi);
  std::vector<std::size_t> beams;
  if (beams_covering(background, static_cast<double>(lo), static_cast<double>(hi), 1, &beams)) {
    const double tol = occluder_tolerance(noise.sigma_m, noise.resolution_m);
    for (const std::size_t i : beams) {
      Real r = 0;
      std::size_t seg = 0;
      if (!placed.raycast(beam_dir(background, i), &r, &seg)) continue;
      const double bg = static_cast<double>(background.ranges_m[i]);
      if (bg > 0 && bg < static_cast<double>(r) - tol) {
        ++hidden;
        continue;
      }
      out->ranges_m[i] = static_cast<Real>(noise.apply(static_cast<double>(r), rng));
      out->intensities[i] = 0;
      ++replaced;
    }
  }
  if (occluded != nullptr) *occluded = hidden;
  return replaced;
}

void composite_installation(const RealRecording& rec, CompositeKind kind, dockcore::DockProfile* profile,
                            dockcore::EstimatorParams* params, const EstimatorOverrides& overrides) {
  *params = real_estimator_params(rec, overrides);
  if (kind == CompositeKind::kFreeStanding) {
    profile->mounting = dockcore::DockMounting{dockcore::DockMountKind::kFreeStanding, 0, static_cast<Real>(0.10)};
  } else {
    profile->mounting = dockcore::DockMounting{dockcore::DockMountKind::kWall, 0, static_cast<Real>(0.10)};
  }
}

CompositeResult measure_real_composites(const LoadedRecording& rec, const dockcore::DockProfile& profile,
                                        CompositeKind kind, const CompositeOptions& o) {
  CompositeResult out;
  dockcore::DockProfile installed = profile;
  dockcore::EstimatorParams params;
  composite_installation(*rec.info, kind, &installed, &params, o.overrides);
  auto est = std::make_unique<DockPoseEstimator>();
  if (!est->configure(installed, params)) return out;
  std::uint64_t h = fnv1a(0xCBF29CE484222325ull, rec.info->name);
  h = fnv1a(h, profile.name);
  h = fnv1a(h, to_string(kind));
  Rng rng(o.seed ^ h);
  std::vector<std::size_t> order(rec.scans.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng.next_u64() % i]);
  const RangeNoise noise{rec.info->sigma_m, rec.info->resolution_m};
  auto background = std::make_unique<LaserScan>();
  auto composite = std::make_unique<LaserScan>();
  for (const std::size_t idx : order) {
    if (out.placed >= o.per_cell) break;
    if (!rec.scans[idx].to_laser_scan(background.get())) continue;
    ++out.scans_tried;
    CompositeSite site;
    if (!find_composite_site(background->view(), installed, kind, rec.info->sigma_m, o.site, rng, &site)) {
      ++out.no_site;
      continue;
    }
    paste_dock(background->view(), installed, site.dock_in_sensor, noise, rng, composite.get());
    ++out.placed;
    const dockcore::DockEstimate e = est->estimate(composite->view(), real_lidar_mount());
    // The face's turn from facing the lidar: its x axis against the direction from the dock to the lidar.
    const Pose2& truth = site.dock_in_sensor;
    const double to_lidar = std::atan2(-static_cast<double>(truth.y_m), -static_cast<double>(truth.x_m));
    const double view_deg = std::fabs(wrap(static_cast<double>(truth.yaw_rad) - to_lidar)) / kDegD;
    int view_bin = 0;
    while (view_bin + 1 < kCompositeViewBins && view_deg > kCompositeViewBinDeg[view_bin]) ++view_bin;
    ++out.placed_by_view[view_bin];
    if (!e.found) {
      ++out.missed;
      continue;
    }
    const double pos = std::hypot(static_cast<double>(e.pose.x_m - site.dock_in_sensor.x_m),
                                  static_cast<double>(e.pose.y_m - site.dock_in_sensor.y_m));
    const double yaw = std::fabs(wrap(static_cast<double>(e.pose.yaw_rad - site.dock_in_sensor.yaw_rad)));
    if (pos <= o.match_m && yaw <= o.match_rad) {
      ++out.detected;
      ++out.detected_by_view[view_bin];
      out.pos_err_m.push_back(pos);
      out.yaw_err_rad.push_back(yaw);
    } else {
      ++out.wrong;
      out.wrong_pos_err_m.push_back(pos);
    }
  }
  out.counters = est->counters();
  return out;
}

}  // namespace docksim
