// 2D lidar simulator: segment world, ray casting and the lidar error models (see docksim/lidar_sim.hpp).
#include "docksim/lidar_sim.hpp"
#include "docksim/angles.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace docksim {
namespace {

// Hits closer than this along the ray are ignored so a ray starting on a surface does not hit that surface.
constexpr double kMinHitT = 1e-9;

Vec2 v2(double x, double y) { return Vec2(static_cast<Real>(x), static_cast<Real>(y)); }

// A segment with its endpoints relative to the ray origin, in double regardless of Real.
struct RelSeg {
  double ax, ay, bx, by;
  double inv_len;  // 1/|b-a|, for the incidence angle.
  double reflectivity;
  bool one_sided;
  bool retro;
  std::uint32_t index;  // Into World::segments.
};

RelSeg make_rel(const Segment& s, double ox, double oy, std::uint32_t index) {
  RelSeg r;
  r.ax = static_cast<double>(s.a.x()) - ox;
  r.ay = static_cast<double>(s.a.y()) - oy;
  r.bx = static_cast<double>(s.b.x()) - ox;
  r.by = static_cast<double>(s.b.y()) - oy;
  const double len = std::hypot(r.bx - r.ax, r.by - r.ay);
  r.inv_len = len > 0 ? 1.0 / len : 0.0;
  r.reflectivity = s.reflectivity;
  r.one_sided = s.one_sided;
  r.retro = s.retro;
  r.index = index;
  return r;
}

// Ray from the origin along unit (dx, dy). The sign test on the endpoints' cross products rejects most segments
// with two multiplications each; the hit point then follows from the same cross products without a division by a
// near-zero determinant (parallel rays give ca == cb and are treated as a miss: a grazing ray has no return).
inline bool hit_rel(const RelSeg& s, double dx, double dy, double* t_out) {
  const double ca = dx * s.ay - dy * s.ax;
  const double cb = dx * s.by - dy * s.bx;
  if ((ca > 0 && cb > 0) || (ca < 0 && cb < 0)) return false;
  const double den = ca - cb;
  if (den == 0) return false;
  const double ex = s.bx - s.ax;
  const double ey = s.by - s.ay;
  if (s.one_sided && dx * ey - dy * ex >= 0) return false;  // dot(dir, (ey, -ex)) >= 0: met from behind.
  const double u = ca / den;
  const double t = (s.ax + u * ex) * dx + (s.ay + u * ey) * dy;
  if (!(t > kMinHitT)) return false;
  *t_out = t;
  return true;
}

// |cos| of the angle between the ray and the segment's normal.
inline double cos_incidence(const RelSeg& s, double dx, double dy) {
  const double ex = s.bx - s.ax;
  const double ey = s.by - s.ay;
  return std::fabs(dx * ey - dy * ex) * s.inv_len;
}

// Per-scan acceleration structure: segments near enough to matter, relative to the lidar, bucketed by the world
// bearing interval they subtend. A ray at any angle looks only at its own bucket, so the buckets need no margin for
// jitter or beam divergence: every segment is listed in every bucket its bearing interval touches.
class ScanCaster {
 public:
  static constexpr int kBins = 1024;

  void prepare(const World& world, double ox, double oy, double max_range) {
    segs_.clear();
    for (std::size_t i = 0; i < world.segments.size(); ++i) {
      const RelSeg r = make_rel(world.segments[i], ox, oy, static_cast<std::uint32_t>(i));
      if (r.inv_len == 0) continue;
      if (dist_to_origin(r) > max_range) continue;
      if (r.one_sided) {
        // Seen only from the side its normal faces; an origin behind (or on) the line can never see it.
        const double ex = r.bx - r.ax, ey = r.by - r.ay;
        if (-r.ax * ey + r.ay * ex <= 0) continue;  // dot(origin - a, (ey, -ex)) <= 0
      }
      segs_.push_back(r);
    }
    // Two passes: count per bin, then fill a flat array (no per-bin vectors).
    start_.assign(kBins + 1, 0);
    spans_.resize(segs_.size());
    for (std::size_t k = 0; k < segs_.size(); ++k) {
      spans_[k] = bin_span(segs_[k]);
      for_each_bin(spans_[k], [&](int b) { ++start_[static_cast<std::size_t>(b) + 1]; });
    }
    for (int b = 0; b < kBins; ++b) start_[static_cast<std::size_t>(b) + 1] += start_[static_cast<std::size_t>(b)];
    items_.resize(start_[kBins]);
    fill_.assign(start_.begin(), start_.end() - 1);
    for (std::size_t k = 0; k < segs_.size(); ++k) {
      for_each_bin(spans_[k], [&](int b) { items_[fill_[static_cast<std::size_t>(b)]++] = static_cast<std::uint32_t>(k); });
    }
  }

  // Nearest hit along world bearing `theta` within max_range. Returns the index into segs_ or -1.
  long cast(double theta, double max_range, double* t_out, double* dx_out, double* dy_out) const {
    const double dx = std::cos(theta);
    const double dy = std::sin(theta);
    *dx_out = dx;
    *dy_out = dy;
    const int b = bin_of(theta);
    double best = max_range;
    long best_k = -1;
    for (std::uint32_t j = start_[static_cast<std::size_t>(b)]; j < start_[static_cast<std::size_t>(b) + 1]; ++j) {
      const std::uint32_t k = items_[j];
      double t;
      if (hit_rel(segs_[k], dx, dy, &t) && t <= best) {
        best = t;
        best_k = static_cast<long>(k);
      }
    }
    if (best_k >= 0) *t_out = best;
    return best_k;
  }
  const RelSeg& seg(long k) const { return segs_[static_cast<std::size_t>(k)]; }
  // True when two hit segments form one continuous surface: the same segment or sharing an endpoint.
  bool continuous(long i, long j) const {
    if (i == j) return true;
    const RelSeg& a = seg(i);
    const RelSeg& b = seg(j);
    auto same = [](double x0, double y0, double x1, double y1) {
      return std::fabs(x0 - x1) <= 1e-9 && std::fabs(y0 - y1) <= 1e-9;
    };
    return same(a.ax, a.ay, b.ax, b.ay) || same(a.ax, a.ay, b.bx, b.by) || same(a.bx, a.by, b.ax, b.ay) ||
           same(a.bx, a.by, b.bx, b.by);
  }

 private:
  struct Span {
    int lo, hi;  // Inclusive bin indices, walked upwards modulo kBins; lo = -1 means every bin.
  };

  static double dist_to_origin(const RelSeg& s) {
    const double ex = s.bx - s.ax, ey = s.by - s.ay;
    double u = -(s.ax * ex + s.ay * ey) * s.inv_len * s.inv_len;
    u = std::min(1.0, std::max(0.0, u));
    return std::hypot(s.ax + u * ex, s.ay + u * ey);
  }
  static int bin_of(double theta) {
    double a = std::remainder(theta, kTwoPiD);  // [-pi, pi]
    int b = static_cast<int>(std::floor((a + kPiD) * (kBins / kTwoPiD)));
    if (b < 0) b = 0;
    if (b >= kBins) b = kBins - 1;
    return b;
  }
  static Span bin_span(const RelSeg& s) {
    const double na = std::hypot(s.ax, s.ay), nb = std::hypot(s.bx, s.by);
    const double cr = s.ax * s.by - s.ay * s.bx;
    const double dt = s.ax * s.bx + s.ay * s.by;
    // Origin on (or numerically at) the segment: it may be hit at any bearing.
    if (na < 1e-9 || nb < 1e-9 || (std::fabs(cr) <= 1e-12 * na * nb && dt < 0)) return Span{-1, -1};
    const double ta = std::atan2(s.ay, s.ax);
    const double d = std::atan2(cr, dt);  // Signed angle a -> b, |d| < pi.
    const double pad = 1e-9;              // Rounding at bin borders.
    const double lo = ta + std::min(0.0, d) - pad;
    const double hi = ta + std::max(0.0, d) + pad;
    const int blo = bin_of(lo);
    const int bhi = bin_of(hi);
    return Span{blo, bhi};
  }
  template <typename F>
  static void for_each_bin(const Span& sp, F f) {
    if (sp.lo < 0) {
      for (int b = 0; b < kBins; ++b) f(b);
      return;
    }
    for (int b = sp.lo;; b = (b + 1) % kBins) {
      f(b);
      if (b == sp.hi) break;
    }
  }

  std::vector<RelSeg> segs_;
  std::vector<Span> spans_;
  std::vector<std::uint32_t> start_;
  std::vector<std::uint32_t> fill_;
  std::vector<std::uint32_t> items_;
};

}  // namespace

void World::add_dock(const dockcore::DockProfile& profile, const Pose2& dock_pose, double reflectivity) {
  for (std::size_t i = 0; i + 1 < profile.vertex_count; ++i) {
    const Vec2 a = dock_pose.transform(profile.vertices_m[i]);
    const Vec2 b = dock_pose.transform(profile.vertices_m[i + 1]);
    const Real len = (b - a).norm();
    // Pieces between the stripes' ends (in order along the segment), each boundary point computed once so that
    // neighbouring pieces share it exactly.
    Vec2 from = a;
    Real at_m = 0;
    auto piece = [&](Real to_m, bool retro) {
      const Vec2 to = to_m >= len ? b : Vec2(a + (b - a) * (to_m / len));
      if (to_m > at_m) {
        Segment s;
        s.a = from;
        s.b = to;
        s.reflectivity = reflectivity;
        s.retro = retro;
        segments.push_back(s);
      }
      from = to;
      at_m = to_m;
    };
    for (std::size_t k = 0; k < profile.reflector_count; ++k) {
      const dockcore::ReflectorStripe& st = profile.reflectors[k];
      if (st.segment != i) continue;
      piece(st.from_m, false);
      piece(st.to_m, true);
    }
    piece(len, false);
  }
}

bool World::has_retro() const {
  for (const Segment& s : segments)
    if (s.retro) return true;
  return false;
}

void World::add_polyline(const std::vector<Vec2>& pts, bool closed, double reflectivity) {
  if (pts.size() < 2) return;
  const std::size_t n = closed ? pts.size() : pts.size() - 1;
  for (std::size_t i = 0; i < n; ++i) {
    Segment s;
    s.a = pts[i];
    s.b = pts[(i + 1) % pts.size()];
    s.reflectivity = reflectivity;
    segments.push_back(s);
  }
}

void World::add_box(const Vec2& centre, double size_x, double size_y, double yaw_rad, double reflectivity) {
  const Pose2 p{centre.x(), centre.y(), static_cast<Real>(yaw_rad)};
  const double hx = 0.5 * size_x, hy = 0.5 * size_y;
  // Clockwise, so each side's (dy, -dx) normal points outwards should anyone make them one-sided.
  const std::vector<Vec2> pts = {p.transform(v2(-hx, -hy)), p.transform(v2(-hx, hy)), p.transform(v2(hx, hy)),
                                 p.transform(v2(hx, -hy))};
  add_polyline(pts, true, reflectivity);
}

void World::add_circle(const Vec2& centre, double radius, int sides, double reflectivity) {
  if (sides < 3) sides = 3;
  std::vector<Vec2> pts;
  pts.reserve(static_cast<std::size_t>(sides));
  for (int i = 0; i < sides; ++i) {
    const double a = -kTwoPiD * i / sides;  // Clockwise, as add_box.
    pts.push_back(v2(static_cast<double>(centre.x()) + radius * std::cos(a),
                     static_cast<double>(centre.y()) + radius * std::sin(a)));
  }
  add_polyline(pts, true, reflectivity);
}

bool World::raycast_segment(const Vec2& origin, const Vec2& dir, double max_range, double* range_out,
                            std::size_t* segment_out) const {
  const double ox = static_cast<double>(origin.x()), oy = static_cast<double>(origin.y());
  double dx = static_cast<double>(dir.x()), dy = static_cast<double>(dir.y());
  const double n = std::hypot(dx, dy);
  if (!(n > 0)) return false;
  dx /= n;
  dy /= n;
  double best = max_range;
  std::size_t best_i = segments.size();
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const RelSeg r = make_rel(segments[i], ox, oy, 0);
    double t;
    if (hit_rel(r, dx, dy, &t) && t <= best) {
      best = t;
      best_i = i;
    }
  }
  if (best_i == segments.size()) return false;
  if (range_out) *range_out = best;
  if (segment_out) *segment_out = best_i;
  return true;
}

bool World::raycast(const Vec2& origin, const Vec2& dir, double max_range, double* range_out,
                    double* reflectivity_out) const {
  std::size_t i = 0;
  if (!raycast_segment(origin, dir, max_range, range_out, &i)) return false;
  if (reflectivity_out) *reflectivity_out = segments[i].reflectivity;
  return true;
}

const char* to_string(IntensityOutput o) {
  switch (o) {
    case IntensityOutput::kRaw:
      return "raw";
    case IntensityOutput::kLd06:
      return "ld06";
    case IntensityOutput::kRplidarQuality:
      return "rplidar-quality";
    case IntensityOutput::kConstant:
      return "constant";
    case IntensityOutput::kNone:
      return "none";
  }
  return "raw";
}

namespace {
constexpr IntensityOutput kIntensityOutputs[] = {IntensityOutput::kRaw, IntensityOutput::kLd06,
                                                 IntensityOutput::kRplidarQuality, IntensityOutput::kConstant,
                                                 IntensityOutput::kNone};
}  // namespace

std::vector<std::string> intensity_output_names() {
  std::vector<std::string> names;
  for (IntensityOutput o : kIntensityOutputs) names.emplace_back(to_string(o));
  return names;
}

bool intensity_output(const std::string& name, IntensityOutput* out) {
  for (IntensityOutput o : kIntensityOutputs) {
    if (name == to_string(o)) {
      *out = o;
      return true;
    }
  }
  return false;
}

double surface_intensity(const LidarModel& m, const Segment& s, double range_m, double cos_incidence) {
  const double q = range_m / m.intensity_ref_range_m;
  if (s.retro && cos_incidence >= std::cos(s.retro_cutoff_rad > 0 ? s.retro_cutoff_rad : m.retro_cutoff_rad)) {
    return m.intensity_scale * m.retro_gain / (1.0 + q * q);
  }
  return m.intensity_scale * (s.retro ? 0.5 : s.reflectivity) * cos_incidence / (1.0 + q * q);
}

double sensor_intensity(const LidarModel& m, double raw) {
  switch (m.intensity_output) {
    case IntensityOutput::kRaw:
      return raw;
    case IntensityOutput::kLd06:
      return std::clamp(std::round(raw), 0.0, 255.0);
    case IntensityOutput::kRplidarQuality:
      return std::clamp(std::round(15.0 * raw / m.rplidar_saturation), 0.0, 15.0);
    case IntensityOutput::kConstant:
      return 47.0;
    case IntensityOutput::kNone:
      return 0.0;
  }
  return raw;
}

bool lidar_model(const std::string& name, LidarModel* out) {
  LidarModel m;
  m.name = name;
  if (name == "ld06") {
    // LDROBOT LD06 / LD19 datasheets: 4500 samples/s at 10 Hz, 0.02-12 m, +-10 mm class accuracy.
    m.rate_hz = 10.0;
    m.beams = 450;
    m.angle_increment_rad = kTwoPiD / 450.0;
    m.angle_min_rad = -kPiD;
    m.min_range_m = 0.02;
    m.max_range_m = 12.0;
    m.sigma_const_m = 0.010;
    m.sigma_prop = 0.0;
    m.dropout_prob = 0.005;
    m.angular_jitter_rad = 0.05 * kDegD;
    m.beam_divergence_rad = 0.3 * kDegD;
    m.intensity_output = IntensityOutput::kLd06;
  } else if (name == "rplidar-a1") {
    // Slamtec RPLIDAR A1M8: ~1 deg, 5.5 Hz, 0.15-12 m, accuracy ~1 % of range under 3 m.
    m.rate_hz = 5.5;
    m.beams = 360;
    m.angle_increment_rad = kTwoPiD / 360.0;
    m.angle_min_rad = -kPiD;
    m.min_range_m = 0.15;
    m.max_range_m = 12.0;
    m.sigma_const_m = 0.003;
    m.sigma_prop = 0.01;
    m.dropout_prob = 0.02;
    m.angular_jitter_rad = 0.1 * kDegD;
    m.beam_divergence_rad = 0.5 * kDegD;
    m.intensity_output = IntensityOutput::kRplidarQuality;
  } else if (name == "rplidar-a2") {
    // Slamtec RPLIDAR A2M8 at 8000 samples/s and 10 Hz: 800 points (0.45 deg), 0.15-12 m, accuracy ~1 % of range.
    m.rate_hz = 10.0;
    m.beams = 800;
    m.angle_increment_rad = kTwoPiD / 800.0;
    m.angle_min_rad = -kPiD;
    m.min_range_m = 0.15;
    m.max_range_m = 12.0;
    m.sigma_const_m = 0.003;
    m.sigma_prop = 0.01;
    m.dropout_prob = 0.01;
    m.angular_jitter_rad = 0.05 * kDegD;
    m.beam_divergence_rad = 0.4 * kDegD;
    m.intensity_output = IntensityOutput::kRplidarQuality;
  } else if (name == "industrial") {
    // SICK TiM/LMS-class safety-rated scanner: 0.25 deg over 270 deg (1081 beams), 25 Hz, 0.05-30 m, 5 mm.
    m.rate_hz = 25.0;
    m.beams = 1081;
    m.angle_increment_rad = 0.25 * kDegD;
    m.angle_min_rad = -135.0 * kDegD;
    m.min_range_m = 0.05;
    m.max_range_m = 30.0;
    m.sigma_const_m = 0.005;
    m.sigma_prop = 0.0;
    m.dropout_prob = 0.001;
    m.angular_jitter_rad = 0.01 * kDegD;
    m.beam_divergence_rad = 0.2 * kDegD;
  } else {
    return false;
  }
  if (out) *out = m;
  return true;
}

std::vector<std::string> lidar_model_names() { return {"ld06", "rplidar-a1", "rplidar-a2", "industrial"}; }

void simulate_scan(const World& world, const Pose2& lidar_pose, const LidarModel& model, Rng& rng,
                   dockcore::LaserScan* out, std::uint64_t stamp_us) {
  const std::size_t beams = std::min(model.beams, dockcore::kMaxScanPoints);
  out->reset(beams, static_cast<Real>(model.angle_min_rad), static_cast<Real>(model.angle_increment_rad), stamp_us);

  const double sigma_at_max = std::hypot(model.sigma_const_m, model.sigma_prop * model.max_range_m);
  // Cast a little past max range so noise can pull a hit just beyond it back inside, as a real sensor would.
  const double cast_range = model.max_range_m + 6.0 * sigma_at_max;
  ScanCaster caster;
  caster.prepare(world, static_cast<double>(lidar_pose.x_m), static_cast<double>(lidar_pose.y_m), cast_range);

  const double yaw = static_cast<double>(lidar_pose.yaw_rad);
  const bool use_mixed = model.mixed_pixels && model.beam_divergence_rad > 0;
  const bool retro_world = world.has_retro();
  // The model's intensity of a hit on segment k at range t along (dx, dy).
  auto raw_intensity = [&](long k, double t, double ddx, double ddy) {
    const RelSeg& s = caster.seg(k);
    return surface_intensity(model, world.segments[s.index], t, cos_incidence(s, ddx, ddy));
  };
  const double half_div = 0.5 * model.beam_divergence_rad;
  for (std::size_t i = 0; i < beams; ++i) {
    double theta = yaw + model.angle_min_rad + static_cast<double>(i) * model.angle_increment_rad;
    if (model.angular_jitter_rad > 0) theta += model.angular_jitter_rad * rng.normal();

    double r = 0, dx = 0, dy = 0;
    const long k = caster.cast(theta, cast_range, &r, &dx, &dy);
    if (k < 0) continue;
    if (use_mixed) {
      double rl = 0, rh = 0, ddx, ddy;
      const long kl = caster.cast(theta - half_div, cast_range, &rl, &ddx, &ddy);
      const long kh = caster.cast(theta + half_div, cast_range, &rh, &ddx, &ddy);
      if (kl >= 0 && kh >= 0) {
        const double near = std::min(r, std::min(rl, rh));
        const double far = std::max(r, std::max(rl, rh));
        // Only a depth discontinuity mixes: a wall seen obliquely spans > 3 cm across a wide footprint but is one
        // surface, and the sides of a corner meet, so neither blends.
        if (far - near > model.mixed_pixel_threshold_m &&
            (!caster.continuous(kl, k) || !caster.continuous(k, kh) || !caster.continuous(kl, kh)) &&
            rng.bernoulli(model.mixed_pixel_prob)) {
          r = near + rng.uniform() * (far - near);
        }
      }
    }
    const double sigma = std::hypot(model.sigma_const_m, model.sigma_prop * r);
    if (sigma > 0) r += sigma * rng.normal();
    if (r < model.min_range_m || r > model.max_range_m) continue;
    if (model.dropout_prob > 0 && rng.bernoulli(model.dropout_prob)) continue;

    double intensity = raw_intensity(k, r, dx, dy);
    if (retro_world && half_div > 0) {
      // The footprint's mean: tape edges read in between (the sub-rays are geometry only, no noise drawn).
      double sum = intensity;
      for (const double side : {-half_div, half_div}) {
        double ts = 0, sx = 0, sy = 0;
        const long ks = caster.cast(theta + side, cast_range, &ts, &sx, &sy);
        if (ks >= 0) sum += raw_intensity(ks, ts, sx, sy);
      }
      intensity = sum / 3.0;
    }
    out->ranges_m[i] = static_cast<Real>(r);
    out->intensities[i] = static_cast<Real>(sensor_intensity(model, intensity));
  }
}

}  // namespace docksim
