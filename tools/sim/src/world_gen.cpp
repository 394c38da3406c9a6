// World generator for generalisation benchmarks (see docksim/world_gen.hpp).
#include "docksim/world_gen.hpp"
#include "docksim/angles.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "docksim/scenes.hpp"
#include "docksim/sim_run.hpp"

namespace docksim {
namespace {

constexpr double kFeatureM = 0.02;         // Smallest feature of a random profile.
constexpr double kWallHalfLengthM = 3.0;   // Walls reach this far either side of the dock.
constexpr double kLidarClearanceM = 0.30;  // The robot's body around the lidar stays free of clutter.
constexpr double kClutterMarginM = 0.03;   // Clutter keeps this far from the line of sight and from each other.
constexpr int kPlacementAttempts = 40;

Vec2 v2(double x, double y) {
  return Vec2(static_cast<Real>(x), static_cast<Real>(y));
}
double X(const Vec2& p) {
  return static_cast<double>(p.x());
}
double Y(const Vec2& p) {
  return static_cast<double>(p.y());
}
Pose2 pose(double x, double y, double yaw) {
  return Pose2{static_cast<Real>(x), static_cast<Real>(y), dockcore::wrap_angle(static_cast<Real>(yaw))};
}
int uniform_int(Rng& rng, int lo, int hi) {  // [lo, hi]
  return std::min(hi, lo + static_cast<int>(rng.uniform() * (hi - lo + 1)));
}
double sym(Rng& rng, double half) {
  return rng.uniform(-half, half);
}

// Distance from b to the line through a and c (or to a when a == c).
double off_line(const Vec2& a, const Vec2& b, const Vec2& c) {
  const double ex = X(c) - X(a), ey = Y(c) - Y(a);
  const double len = std::hypot(ex, ey);
  if (len < 1e-12) return std::hypot(X(b) - X(a), Y(b) - Y(a));
  return std::fabs(ex * (Y(b) - Y(a)) - ey * (X(b) - X(a))) / len;
}

// The random-profile rules of world_gen.hpp on a finished outline.
bool valid_outline(const std::vector<Vec2>& v) {
  if (v.size() < 2) return false;
  bool prev_step = false;
  for (std::size_t i = 0; i + 1 < v.size(); ++i) {
    const double dx = X(v[i + 1]) - X(v[i]), dy = Y(v[i + 1]) - Y(v[i]);
    if (dy < 0) return false;
    const bool step = dy == 0;
    if (step && (prev_step || std::fabs(dx) < kFeatureM)) return false;
    if (!step && dy < kFeatureM) return false;
    prev_step = step;
  }
  for (std::size_t i = 1; i + 1 < v.size(); ++i) {
    if (off_line(v[i - 1], v[i], v[i + 1]) < kFeatureM) return false;
  }
  return true;
}

// Outline from -width/2 upwards: `segments` segments, each a step with probability 0.3 (never two in a row, never
// the last one of a half that is mirrored), faces sharing `rise` in y (each >= kFeatureM), x in [-depth, 0]. Each
// vertex's x is redrawn until the bend it completes is >= kFeatureM; false when that keeps failing.
bool draw_outline(Rng& rng, int segments, double y0, double rise, double depth, bool last_is_face,
                  std::vector<Vec2>* out) {
  std::vector<bool> step(static_cast<std::size_t>(segments), false);
  int faces = 0;
  for (int i = 0; i < segments; ++i) {
    const bool can_step = (i == 0 || !step[static_cast<std::size_t>(i - 1)]) && !(last_is_face && i == segments - 1);
    step[static_cast<std::size_t>(i)] = can_step && rng.bernoulli(0.3);
    if (!step[static_cast<std::size_t>(i)]) ++faces;
  }
  if (faces == 0 || rise < kFeatureM * faces) return false;
  std::vector<double> w(static_cast<std::size_t>(faces));
  double wsum = 0;
  for (double& x : w) wsum += (x = rng.uniform(0.2, 1.0));
  const double spare = rise - kFeatureM * faces;
  out->clear();
  out->push_back(v2(rng.uniform(-depth, 0.0), y0));
  double y = y0;
  int f = 0;
  for (int i = 0; i < segments; ++i) {
    if (!step[static_cast<std::size_t>(i)]) {
      y += kFeatureM + spare * w[static_cast<std::size_t>(f)] / wsum;
      ++f;
    }
    bool ok = false;
    for (int attempt = 0; attempt < 50 && !ok; ++attempt) {
      const Vec2 p = v2(rng.uniform(-depth, 0.0), y);
      const Vec2& a = out->back();
      if (step[static_cast<std::size_t>(i)] && std::fabs(X(p) - X(a)) < kFeatureM) continue;
      if (out->size() >= 2 && off_line((*out)[out->size() - 2], a, p) < kFeatureM) continue;
      out->push_back(p);
      ok = true;
    }
    if (!ok) return false;
  }
  return true;
}

// Smallest and largest x and y of a profile.
struct Box {
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
};
Box bounds(const dockcore::DockProfile& p) {
  Box b;
  for (std::size_t i = 0; i < p.vertex_count; ++i) {
    const double x = X(p.vertices_m[i]), y = Y(p.vertices_m[i]);
    if (i == 0 || x < b.x0) b.x0 = x;
    if (i == 0 || x > b.x1) b.x1 = x;
    if (i == 0 || y < b.y0) b.y0 = y;
    if (i == 0 || y > b.y1) b.y1 = y;
  }
  return b;
}

// A candidate clutter object in the dock frame: its shape, a bounding circle, and its half extents along the dock's
// x and y axes (for the walls, which are axis-aligned in the dock frame).
struct Shape {
  ClutterClass kind = ClutterClass::kNone;
  double a = 0, b = 0, r = 0;  // box: sizes a x b; legs: spacing a x b, leg radius r; bin: radius r or size a.
  bool round = false;
  double yaw = 0;     // In the dock frame.
  double radius = 0;  // Bounding circle.
  double half_x = 0, half_y = 0;
  double reflectivity = 0.5;
};

Shape draw_shape(ClutterClass kind, Rng& rng) {
  Shape s;
  s.kind = kind;
  switch (kind) {
    case ClutterClass::kBoxes:
      s.a = rng.uniform(0.2, 0.6);
      s.b = rng.uniform(0.2, 0.6);
      s.yaw = sym(rng, 10 * kDegD);  // Pushed against the wall, roughly square to it.
      s.radius = 0.5 * std::hypot(s.a, s.b);
      break;
    case ClutterClass::kChairLegs:
      s.a = s.b = rng.uniform(0.40, 0.50);
      s.r = rng.uniform(0.010, 0.015);
      s.yaw = sym(rng, kPiD);
      s.radius = 0.5 * std::hypot(s.a, s.b) + s.r;
      break;
    case ClutterClass::kTableLegs:
      s.a = rng.uniform(0.6, 1.4);
      s.b = rng.uniform(0.4, 0.8);
      s.r = rng.uniform(0.020, 0.035);
      s.yaw = sym(rng, 15 * kDegD);
      s.radius = 0.5 * std::hypot(s.a, s.b) + s.r;
      break;
    case ClutterClass::kBin:
      s.round = rng.bernoulli(0.5);
      if (s.round) {
        s.r = rng.uniform(0.12, 0.20);
        s.radius = s.r;
      } else {
        s.a = s.b = rng.uniform(0.25, 0.35);
        s.yaw = sym(rng, 10 * kDegD);
        s.radius = 0.5 * std::hypot(s.a, s.b);
      }
      break;
    case ClutterClass::kPersonLegs:
      s.a = rng.uniform(0.10, 0.30);  // Centre to centre.
      s.r = rng.uniform(0.05, 0.07);
      s.yaw = sym(rng, kPiD);
      s.radius = 0.5 * s.a + s.r;
      break;
    default:
      break;
  }
  // Half extents in the dock frame: exact for boxes, the bounding circle otherwise.
  if (kind == ClutterClass::kBoxes || (kind == ClutterClass::kBin && !s.round)) {
    const double c = std::fabs(std::cos(s.yaw)), sn = std::fabs(std::sin(s.yaw));
    s.half_x = 0.5 * (c * s.a + sn * s.b);
    s.half_y = 0.5 * (sn * s.a + c * s.b);
  } else {
    s.half_x = s.half_y = s.radius;
  }
  s.reflectivity = rng.uniform(0.1, 0.9);
  return s;
}

void add_shape(World* w, const Pose2& dock, const Shape& s, const Vec2& centre_dock) {
  const Pose2 p = dock.compose(pose(X(centre_dock), Y(centre_dock), s.yaw));
  const Vec2 c = v2(static_cast<double>(p.x_m), static_cast<double>(p.y_m));
  switch (s.kind) {
    case ClutterClass::kBoxes:
      w->add_box(c, s.a, s.b, static_cast<double>(p.yaw_rad), s.reflectivity);
      break;
    case ClutterClass::kChairLegs:
    case ClutterClass::kTableLegs:
      for (int sx = -1; sx <= 1; sx += 2)
        for (int sy = -1; sy <= 1; sy += 2)
          w->add_circle(p.transform(v2(0.5 * sx * s.a, 0.5 * sy * s.b)), s.r, 8, s.reflectivity);
      break;
    case ClutterClass::kBin:
      if (s.round) {
        w->add_circle(c, s.r, 16, s.reflectivity);
      } else {
        w->add_box(c, s.a, s.b, static_cast<double>(p.yaw_rad), s.reflectivity);
      }
      break;
    case ClutterClass::kPersonLegs:
      w->add_circle(p.transform(v2(0, -0.5 * s.a)), s.r, 12, s.reflectivity);
      w->add_circle(p.transform(v2(0, 0.5 * s.a)), s.r, 12, s.reflectivity);
      break;
    default:
      break;
  }
}

// Where clutter may go, in the dock frame except for the line-of-sight hull (world).
struct FreeSpace {
  Pose2 dock;
  std::vector<Vec2> lidars;  // World.
  std::vector<Vec2> sight;   // World, convex: lidars + the dock's (and look-alike's) bounding box.
  bool front_limit = false;  // Objects stay at x >= front_x (+ half extent).
  double front_x = 0;
  bool back_limit = false;  // Objects stay at x >= back_x (a room wall behind a free-standing dock).
  double back_x = 0;
  int side_wall = 0;  // Corner: objects stay on the room side of y = side_y.
  double side_y = 0;
  std::vector<std::pair<Vec2, double>> taken;  // Placed objects' circles (dock frame).

  bool ok(const Shape& s, const Vec2& c) const {
    if (front_limit && X(c) - s.half_x < front_x + 0.005) return false;
    if (back_limit && X(c) - s.half_x < back_x + 0.005) return false;
    if (side_wall > 0 && Y(c) + s.half_y > side_y - 0.005) return false;
    if (side_wall < 0 && Y(c) - s.half_y < side_y + 0.005) return false;
    const Vec2 cw = dock.transform(c);
    for (const Vec2& l : lidars) {
      if (std::hypot(X(cw) - X(l), Y(cw) - Y(l)) < s.radius + kLidarClearanceM) return false;
    }
    if (distance_to_convex(cw, sight) < s.radius + kClutterMarginM) return false;
    for (const auto& t : taken) {
      if (std::hypot(X(c) - X(t.first), Y(c) - Y(t.first)) < s.radius + t.second + kClutterMarginM) return false;
    }
    return true;
  }
};

// Tries to place one object of kind `s` next to the dock (box `db`, dock frame). Returns true and adds it when a
// free spot is found within kPlacementAttempts draws.
bool place(const Shape& s, const Box& db, Rng& rng, FreeSpace* fs, World* w, std::vector<GenObject>* objects) {
  for (int attempt = 0; attempt < kPlacementAttempts; ++attempt) {
    Vec2 c;
    if (s.kind == ClutterClass::kPersonLegs) {
      c = v2(db.x1 + rng.uniform(0.3, 1.0), rng.uniform(db.y0 - 1.2, db.y1 + 1.2));
    } else {
      const int side = rng.bernoulli(0.5) ? 1 : -1;
      const double gap = rng.uniform(0.2, 1.0);  // Dock side to the object's near side.
      const double y = side > 0 ? db.y1 + gap + s.half_y : db.y0 - gap - s.half_y;
      const double base = fs->front_limit ? fs->front_x : db.x0;
      // Boxes and bins stand against the wall (or level with the dock's back); chairs and tables stand out to 0.8 m.
      const bool against = s.kind == ClutterClass::kBoxes || s.kind == ClutterClass::kBin;
      const double x = base + s.half_x + 0.006 + (against ? rng.uniform(0.0, 0.05) : rng.uniform(0.0, 0.8));
      c = v2(x, y);
    }
    if (!fs->ok(s, c)) continue;
    add_shape(w, fs->dock, s, c);
    fs->taken.emplace_back(c, s.radius);
    objects->push_back(GenObject{to_string(s.kind), fs->dock.transform(c), s.radius});
    return true;
  }
  return false;
}

void add_segment(World* w, const Pose2& dock, double xa, double ya, double xb, double yb, double refl) {
  w->add_polyline({dock.transform(v2(xa, ya)), dock.transform(v2(xb, yb))}, false, refl);
}

// Draws a width in [0.2, 0.7] m at least 20 % away from `width`.
double different_width(Rng& rng, double width) {
  for (int i = 0; i < 100; ++i) {
    const double w = rng.uniform(0.2, 0.7);
    if (std::fabs(w - width) >= 0.2 * width) return w;
  }
  return width < 0.45 ? 0.7 : 0.2;
}

// A flat board `thickness` x `width` at `at` (its centre; world), its front face (+x in its frame) split where the
// tape starts and ends: the parts within `tape` (intervals of y along the face, from -width/2) are retro.
void add_taped_board(World* w, const Pose2& at, double thickness, double width, double refl,
                     const std::vector<std::pair<double, double>>& tape) {
  const double hx = 0.5 * thickness, hy = 0.5 * width;
  auto seg = [&](double xa, double ya, double xb, double yb, bool retro) {
    Segment g;
    g.a = at.transform(v2(xa, ya));
    g.b = at.transform(v2(xb, yb));
    g.reflectivity = refl;
    g.retro = retro;
    w->segments.push_back(g);
  };
  seg(-hx, -hy, -hx, hy, false);
  seg(-hx, hy, hx, hy, false);
  seg(hx, -hy, -hx, -hy, false);
  std::vector<double> cuts{-hy, hy};
  for (const auto& t : tape) {
    cuts.push_back(std::clamp(t.first, -hy, hy));
    cuts.push_back(std::clamp(t.second, -hy, hy));
  }
  std::sort(cuts.begin(), cuts.end());
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    if (cuts[i + 1] - cuts[i] < 1e-9) continue;
    const double mid = 0.5 * (cuts[i] + cuts[i + 1]);
    bool retro = false;
    for (const auto& t : tape) retro = retro || (mid > t.first && mid < t.second);
    seg(hx, cuts[i], hx, cuts[i + 1], retro);
  }
}

// The tape intervals of a 3-region pattern over a face `width` wide centred on 0 (regions from -width/2).
std::vector<std::pair<double, double>> pattern_tape(double width, int pattern) {
  std::vector<std::pair<double, double>> t;
  const double r = width / 3.0;
  for (int k = 0; k < 3; ++k) {
    if ((pattern >> k) & 1) t.emplace_back(-0.5 * width + k * r, -0.5 * width + (k + 1) * r);
  }
  return t;
}

// Draws one reflective object of `kind` (world_gen.hpp) and tries to place it beside the dock (box `db`, dock frame)
// or, for a vest, in front of it; true and added when a free spot is found within kPlacementAttempts draws.
bool place_reflective(ReflectiveClass kind, const Box& db, Rng& rng, FreeSpace* fs, World* w,
                      std::vector<GenObject>* objects) {
  constexpr double kBoardM = 0.02;
  constexpr int kSides = 16;
  Shape fit;  // Only its extents, for FreeSpace::ok.
  double r = 0, a = 0, yaw = 0, cutoff = 0;
  int bands = 0;
  double band_c[2] = {}, band_w[2] = {};
  std::vector<std::pair<double, double>> tape;
  const double refl = rng.uniform(0.1, 0.9);
  switch (kind) {
    case ReflectiveClass::kVest:
      r = rng.uniform(0.10, 0.20);
      bands = uniform_int(rng, 1, 2);
      for (int b = 0; b < bands; ++b) {
        band_c[b] = sym(rng, kPiD);
        band_w[b] = rng.uniform(40.0, 120.0) * kDegD;
      }
      fit.radius = r;
      break;
    case ReflectiveClass::kSign: {
      a = rng.uniform(0.2, 0.6);
      yaw = sym(rng, 5 * kDegD);
      if (rng.bernoulli(0.5)) {
        tape.emplace_back(-0.5 * a, 0.5 * a);
      } else {
        const double frac = rng.uniform(0.2, 1.0);
        const double t0 = rng.uniform(0.0, 1.0 - frac);
        tape.emplace_back(-0.5 * a + t0 * a, -0.5 * a + (t0 + frac) * a);
      }
      fit.radius = 0.5 * std::hypot(a, kBoardM);
      break;
    }
    case ReflectiveClass::kChromeLegs:
      a = rng.uniform(0.35, 0.50);
      r = rng.uniform(0.010, 0.025);
      yaw = sym(rng, kPiD);
      cutoff = rng.uniform(10.0, 15.0) * kDegD;
      fit.radius = 0.5 * std::hypot(a, a) + r;
      break;
    case ReflectiveClass::kGlassPane:
      a = rng.uniform(0.3, 1.0);
      yaw = sym(rng, 5 * kDegD);
      fit.radius = 0.5 * std::hypot(a, kBoardM);
      break;
    default:
      return false;
  }
  const bool flat = kind == ReflectiveClass::kSign || kind == ReflectiveClass::kGlassPane;
  if (flat) {
    const double c = std::fabs(std::cos(yaw)), sn = std::fabs(std::sin(yaw));
    fit.half_x = 0.5 * (c * kBoardM + sn * a);
    fit.half_y = 0.5 * (sn * kBoardM + c * a);
  } else {
    fit.half_x = fit.half_y = fit.radius;
  }
  for (int attempt = 0; attempt < kPlacementAttempts; ++attempt) {
    Vec2 c;
    if (kind == ReflectiveClass::kVest) {
      c = v2(db.x1 + rng.uniform(0.3, 1.5), rng.uniform(db.y0 - 1.5, db.y1 + 1.5));
    } else {
      const int side = rng.bernoulli(0.5) ? 1 : -1;
      const double gap = rng.uniform(0.2, 2.0);
      const double y = side > 0 ? db.y1 + gap + fit.half_y : db.y0 - gap - fit.half_y;
      const double base = fs->front_limit ? fs->front_x : db.x0;
      c = v2(base + fit.half_x + 0.006 + (flat ? rng.uniform(0.0, 0.10) : rng.uniform(0.0, 0.8)), y);
    }
    if (!fs->ok(fit, c)) continue;
    const Pose2 p = fs->dock.compose(pose(X(c), Y(c), yaw));
    const Vec2 cw = fs->dock.transform(c);
    const char* name = "";
    switch (kind) {
      case ReflectiveClass::kVest: {
        const std::size_t first = w->segments.size();
        w->add_circle(cw, r, kSides, refl);
        for (int i = 0; i < kSides; ++i) {
          const double mid = -2.0 * kPiD * (i + 0.5) / kSides;  // add_circle goes clockwise.
          for (int b = 0; b < bands; ++b) {
            if (std::fabs(std::remainder(mid - band_c[b], 2.0 * kPiD)) <= 0.5 * band_w[b])
              w->segments[first + static_cast<std::size_t>(i)].retro = true;
          }
        }
        name = "vest";
        break;
      }
      case ReflectiveClass::kSign:
        add_taped_board(w, p, kBoardM, a, refl, tape);
        name = "sign";
        break;
      case ReflectiveClass::kChromeLegs:
        for (int sx = -1; sx <= 1; sx += 2) {
          for (int sy = -1; sy <= 1; sy += 2) {
            const std::size_t first = w->segments.size();
            w->add_circle(p.transform(v2(0.5 * sx * a, 0.5 * sy * a)), r, kSides, refl);
            for (std::size_t k = first; k < w->segments.size(); ++k) {
              w->segments[k].retro = true;
              w->segments[k].retro_cutoff_rad = cutoff;
            }
          }
        }
        name = "chrome-legs";
        break;
      case ReflectiveClass::kGlassPane:
        name = "glass-pane";  // No return: nothing for the lidar, only the place is taken.
        break;
      default:
        break;
    }
    fs->taken.emplace_back(c, fit.radius);
    objects->push_back(GenObject{name, cw, fit.radius});
    return true;
  }
  return false;
}

}  // namespace

const char* to_string(MountClass c) {
  switch (c) {
    case MountClass::kFlush:
      return "flush";
    case MountClass::kGap:
      return "gap";
    case MountClass::kSkirting:
      return "skirting";
    case MountClass::kGlass:
      return "glass";
    case MountClass::kFreeStanding:
      return "free-standing";
    case MountClass::kCorner:
      return "corner";
    default:
      break;
  }
  return "unknown";
}

const char* to_string(ClutterClass c) {
  switch (c) {
    case ClutterClass::kNone:
      return "none";
    case ClutterClass::kBoxes:
      return "boxes";
    case ClutterClass::kChairLegs:
      return "chair-legs";
    case ClutterClass::kTableLegs:
      return "table-legs";
    case ClutterClass::kBin:
      return "bin";
    case ClutterClass::kPersonLegs:
      return "person-legs";
    case ClutterClass::kMixed:
      return "mixed";
    default:
      break;
  }
  return "unknown";
}

const char* to_string(LookAlike c) {
  switch (c) {
    case LookAlike::kNothing:
      return "nothing";
    case LookAlike::kBoard:
      return "board";
    case LookAlike::kBox:
      return "box";
    case LookAlike::kNotch:
      return "notch";
    case LookAlike::kOtherDock:
      return "other-dock";
    case LookAlike::kOtherCode:
      return "other-code";
    case LookAlike::kUntaped:
      return "untaped";
    case LookAlike::kTapedBoard:
      return "taped-board";
    default:
      break;
  }
  return "unknown";
}

const char* to_string(ReflectiveClass c) {
  switch (c) {
    case ReflectiveClass::kVest:
      return "vest";
    case ReflectiveClass::kSign:
      return "sign";
    case ReflectiveClass::kChromeLegs:
      return "chrome-legs";
    case ReflectiveClass::kGlassPane:
      return "glass-pane";
    default:
      break;
  }
  return "unknown";
}

std::size_t longest_segment(const dockcore::DockProfile& profile, double* length_m) {
  std::size_t best = 0;
  double best_len = -1;
  for (std::size_t i = 0; i + 1 < profile.vertex_count; ++i) {
    const double len = static_cast<double>((profile.vertices_m[i + 1] - profile.vertices_m[i]).norm());
    if (len > best_len) {
      best_len = len;
      best = i;
    }
  }
  if (length_m) *length_m = std::max(0.0, best_len);
  return best;
}

bool add_code(dockcore::DockProfile* profile, std::size_t segment, double region_m, int pattern) {
  profile->reflector_count = 0;
  if (segment + 1 >= profile->vertex_count) return false;
  const double len = static_cast<double>((profile->vertices_m[segment + 1] - profile->vertices_m[segment]).norm());
  const double start = 0.5 * (len - 3 * region_m);
  if (start < -1e-9 || region_m <= 0) return false;
  for (int k = 0; k < 3; ++k) {
    if (!((pattern >> k) & 1)) continue;
    dockcore::ReflectorStripe st;
    st.segment = static_cast<std::uint8_t>(segment);
    st.from_m = static_cast<Real>(std::max(0.0, start + k * region_m));
    st.to_m = static_cast<Real>(std::min(len, start + (k + 1) * region_m));
    if (dockcore::add_reflector(*profile, st) != dockcore::ProfileError::kOk) {
      profile->reflector_count = 0;
      return false;
    }
  }
  return true;
}

Pose2 GenScene::lidar_in_world(std::size_t k) const {
  return robot_path.at(k).compose(true_mount());
}
Pose2 GenScene::dock_in_robot(std::size_t k) const {
  return robot_path.at(k).inverse().compose(dock_in_world);
}
Pose2 GenScene::dock_in_sensor(std::size_t k) const {
  return lidar_in_world(k).inverse().compose(dock_in_world);
}
double GenScene::sigma_at(double range_m) const {
  return std::hypot(lidar.sigma_const_m, lidar.sigma_prop * range_m);
}

dockcore::DockProfile random_profile(Rng& rng, const char* name) {
  std::vector<Vec2> v;
  for (int attempt = 0;; ++attempt) {
    const int n = uniform_int(rng, 2, 8);
    const double width = rng.uniform(0.2, 0.7);
    const double depth = rng.uniform(0.04, 0.20);
    // Half of the docks are mirror-symmetric about y = 0, as most real docks are.
    const bool symmetric = n >= 3 && rng.bernoulli(0.5);
    bool ok;
    if (symmetric) {
      // Odd n: the half ends on y = 0 with a face; even n: the half ends at -c and a flat middle face joins the halves.
      const int half_segments = (n - 1) / 2;
      const double c = n % 2 == 0 ? rng.uniform(kFeatureM, 0.5 * width - kFeatureM * half_segments) : 0.0;
      ok = c >= 0 && draw_outline(rng, half_segments, -0.5 * width, 0.5 * width - c, depth, true, &v);
      if (ok) {
        const std::size_t h = v.size();
        for (std::size_t i = h; i-- > 0;) {
          if (i == h - 1 && n % 2 == 1) continue;  // The vertex on y = 0 is shared.
          v.push_back(v2(X(v[i]), -Y(v[i])));
        }
      }
    } else {
      ok = draw_outline(rng, n - 1, -0.5 * width, width, depth, false, &v);
    }
    if (ok && static_cast<int>(v.size()) == n && valid_outline(v)) break;
    if (attempt > 10000) {  // Unreachable in practice; a plain plate keeps the generator total.
      v = {v2(0, -0.5 * width), v2(0, 0.5 * width)};
      break;
    }
  }
  // Contacts at y = 0 on the outline: interpolate the face crossing y = 0, or take the front of a step there.
  double x_at_0 = -1e9;
  for (std::size_t i = 0; i + 1 < v.size(); ++i) {
    const double ya = Y(v[i]), yb = Y(v[i + 1]);
    if (ya <= 0 && yb >= 0) {
      const double x =
          yb > ya ? X(v[i]) + (X(v[i + 1]) - X(v[i])) * (0 - ya) / (yb - ya) : std::max(X(v[i]), X(v[i + 1]));
      x_at_0 = std::max(x_at_0, x);
    }
  }
  dockcore::DockProfile p;
  const dockcore::ProfileError e = dockcore::make_profile(v.data(), v.size(), static_cast<Real>(x_at_0), "random", p);
  if (e != dockcore::ProfileError::kOk) throw std::logic_error("random_profile: invalid outline");
  std::strncpy(p.name, name, sizeof p.name - 1);
  p.name[sizeof p.name - 1] = '\0';
  return p;
}

WorldGenerator::WorldGenerator(const WorldGenParams& params, std::uint64_t seed) : params_(params), seed_(seed) {
  for (std::size_t i = 0; dockcore::kBuiltinProfileNames[i] != nullptr; ++i) {
    dockcore::DockProfile p;
    dockcore::builtin_profile(dockcore::kBuiltinProfileNames[i], p);
    builtin_.push_back(p);
  }
  Rng rng(seed_stream(seed, 0x50524f46 /* "PROF" */));
  for (int i = 0; i < params.random_profiles; ++i) {
    char name[24];
    std::snprintf(name, sizeof name, "random-%03d", i);
    random_.push_back(random_profile(rng, name));
  }
  for (const std::string& l : params.lidars) {
    if (!lidar_model(l, nullptr)) throw std::invalid_argument("world generator: unknown lidar model " + l);
  }
}

GenScene WorldGenerator::draw(std::uint64_t index, bool with_dock, ScenePath path) const {
  const std::uint64_t salt =
      0x574f524c44000000ull /* "WORLD" */ + (with_dock ? 0u : 0x100u) + static_cast<unsigned>(path);
  Rng rng(trial_seed(seed_stream(seed_, salt), index));
  const WorldGenParams& P = params_;
  GenScene s;
  s.index = index;
  s.with_dock = with_dock;

  // Profile.
  s.builtin = random_.empty() || rng.bernoulli(P.builtin_share);
  if (s.builtin) {
    s.profile = builtin_[static_cast<std::size_t>(uniform_int(rng, 0, static_cast<int>(builtin_.size()) - 1))];
  } else {
    s.random_index = uniform_int(rng, 0, static_cast<int>(random_.size()) - 1);
    s.profile = random_[static_cast<std::size_t>(s.random_index)];
  }
  s.profile.mounting = dockcore::DockMounting{};
  const Box db = bounds(s.profile);
  if (P.reflectors) {
    s.profile.reflector_count = 0;
    double len = 0;
    const std::size_t seg = longest_segment(s.profile, &len);
    const double region = P.code_region_m > 0 ? P.code_region_m : len / 3.0;
    const bool fits = P.code_region_m > 0 ? 3 * region <= len + 1e-9 : len >= kCodeMinSegmentM;
    const int pattern = uniform_int(rng, kCodePatternMin, kCodePatternMax);
    if (fits && add_code(&s.profile, seg, region, pattern)) {
      s.code_pattern = pattern;
      s.code_segment = static_cast<int>(seg);
      s.code_region_m = region;
    }
  }

  // Lidar and its noise.
  const std::string& lname =
      P.lidars[static_cast<std::size_t>(uniform_int(rng, 0, static_cast<int>(P.lidars.size()) - 1))];
  lidar_model(lname, &s.lidar);
  s.lidar.sigma_const_m =
      rng.bernoulli(0.5) ? rng.uniform(P.sigma_min_m, P.sigma_split_m) : rng.uniform(P.sigma_split_m, P.sigma_max_m);
  s.lidar.sigma_prop = rng.uniform(0.0, P.sigma_prop_max);
  s.lidar.dropout_prob = rng.uniform(0.0, P.dropout_max);
  s.lidar.mixed_pixels = true;
  s.lidar.mixed_pixel_prob = rng.uniform();

  // Mount, calibration error, poses.
  s.lidar_mount = pose(sym(rng, P.mount_x_max_m), sym(rng, P.mount_y_max_m), sym(rng, P.mount_yaw_max_rad));
  s.calibration_error = pose(sym(rng, P.calib_xy_max_m), sym(rng, P.calib_xy_max_m), sym(rng, P.calib_yaw_max_rad));
  if (path == ScenePath::kApproach) {
    s.distance_m = rng.uniform(0.45, 1.0);
    s.bearing_rad = sym(rng, 45 * kDegD);
    s.dock_yaw_rad = sym(rng, 30 * kDegD);
  } else {
    s.distance_m = rng.uniform(P.distance_min_m, P.distance_max_m);
    s.bearing_rad = sym(rng, P.bearing_max_rad);
    s.dock_yaw_rad = sym(rng, P.dock_yaw_max_rad);
  }
  s.robot_path.push_back(Pose2{});
  if (path == ScenePath::kConfirm) {
    for (int k = 0; k < 2; ++k) {
      s.robot_path.push_back(
          s.robot_path.back().compose(pose(rng.uniform(0.01, 0.03), sym(rng, 0.01), sym(rng, 1.0 * kDegD))));
    }
  } else if (path == ScenePath::kApproach) {
    const double v = rng.uniform(0.05, 0.15);
    const double w = sym(rng, 0.1) + 0.5 * s.bearing_rad;  // Turning towards the dock.
    for (int k = 1; k < 10; ++k) s.robot_path.push_back(s.robot_path.back().compose(pose(0.1 * v, 0, 0.1 * w)));
  }
  const Pose2 lidar0 = s.robot_path[0].compose(s.true_mount());
  s.dock_in_world = Pose2{lidar0.x_m, lidar0.y_m, s.robot_path[0].yaw_rad}.compose(
      dock_pose_from_lidar(s.distance_m, s.bearing_rad, s.dock_yaw_rad));
  const Pose2& dock = s.dock_in_world;
  std::vector<Vec2> lidar_dock;  // Lidar positions in the dock frame.
  FreeSpace fs;
  fs.dock = dock;
  for (std::size_t k = 0; k < s.robot_path.size(); ++k) {
    const Pose2 l = s.lidar_in_world(k);
    fs.lidars.push_back(v2(static_cast<double>(l.x_m), static_cast<double>(l.y_m)));
    lidar_dock.push_back(dock.inverse_transform(fs.lidars.back()));
  }

  // Mounting.
  s.mount = static_cast<MountClass>(uniform_int(rng, 0, static_cast<int>(MountClass::kCount) - 1));
  const double wall_refl = rng.uniform(0.2, 0.9);
  dockcore::DockMounting told;
  switch (s.mount) {
    case MountClass::kFlush:
      told = {dockcore::DockMountKind::kWall, 0, static_cast<Real>(0.01)};
      break;
    case MountClass::kGap:
      s.wall_gap_m = P.gap_max_m * (1.0 - rng.uniform());
      break;
    case MountClass::kSkirting:
      s.skirting_depth_m = rng.uniform(0.01, 0.02);
      s.skirting_end_gap_m = rng.uniform(0.0, 0.02);
      told = {dockcore::DockMountKind::kWall, 0, static_cast<Real>(0.02)};
      break;
    case MountClass::kGlass:
    case MountClass::kFreeStanding:
      if (rng.bernoulli(0.5)) s.back_wall_distance_m = rng.uniform(0.6, 3.0);
      told = {dockcore::DockMountKind::kFreeStanding, 0, 0};
      break;
    case MountClass::kCorner: {
      s.wall_gap_m = rng.bernoulli(0.5) ? 0.0 : P.gap_max_m * (1.0 - rng.uniform());
      s.corner_side = rng.bernoulli(0.5) ? 1 : -1;
      s.corner_distance_m = rng.uniform(0.0, 0.5);
      // The robot must stand on the room side of the second wall, 0.3 m clear: try the other side, else move the wall.
      auto violation = [&](int side) {
        double worst = -1e9;
        const double wall_y = side > 0 ? db.y1 + s.corner_distance_m : db.y0 - s.corner_distance_m;
        for (const Vec2& l : lidar_dock) worst = std::max(worst, side * (Y(l) - wall_y) + kLidarClearanceM);
        return worst;
      };
      if (violation(s.corner_side) > 0) {
        if (violation(-s.corner_side) <= 0) {
          s.corner_side = -s.corner_side;
        } else {
          s.corner_distance_m += violation(s.corner_side);
        }
      }
      break;
    }
    default:
      break;
  }
  if (s.mount == MountClass::kGap || s.mount == MountClass::kCorner) {
    told = {dockcore::DockMountKind::kWall, static_cast<Real>(std::max(0.0, s.wall_gap_m - 0.02)),
            static_cast<Real>(std::min(static_cast<double>(dockcore::kMaxWallGapM), s.wall_gap_m + 0.02))};
  }
  s.told_mounting = told;

  // The dock, or a look-alike in its place.
  Box keep = db;  // What the line of sight must reach: the dock's box, widened to the look-alike's.
  if (with_dock) {
    s.dock_reflectivity = rng.uniform(0.5, 0.95);
    s.world.add_dock(s.profile, dock, s.dock_reflectivity);
    s.objects.push_back(GenObject{"dock", dock.transform(v2(0.5 * (db.x0 + db.x1), 0.5 * (db.y0 + db.y1))),
                                  0.5 * std::hypot(db.x1 - db.x0, db.y1 - db.y0)});
  } else {
    const int kinds = P.reflectors ? static_cast<int>(LookAlike::kCount) : kPlainLookAlikes;
    s.look_alike = static_cast<LookAlike>(uniform_int(rng, 0, kinds - 1));
    const double refl = s.dock_reflectivity = rng.uniform(0.5, 0.95);
    const double width = static_cast<double>(s.profile.width_m());
    double lw = different_width(rng, width);
    double ldepth = 0.02;
    switch (s.look_alike) {
      case LookAlike::kBoard:
        s.world.add_box(dock.transform(v2(db.x0 + 0.01, 0)), 0.02, lw, static_cast<double>(dock.yaw_rad), refl);
        break;
      case LookAlike::kBox:
        ldepth = std::max(0.05, db.x1 - db.x0);
        s.world.add_box(dock.transform(v2(db.x0 + 0.5 * ldepth, 0)), ldepth, lw, static_cast<double>(dock.yaw_rad),
                        refl);
        break;
      case LookAlike::kNotch:
        ldepth = 0.5 * lw;
        s.world.add_polyline({dock.transform(v2(db.x0 + ldepth, -0.5 * lw)), dock.transform(v2(db.x0, 0)),
                              dock.transform(v2(db.x0 + ldepth, 0.5 * lw))},
                             false, refl);
        break;
      case LookAlike::kOtherDock: {
        const std::size_t pool = builtin_.size() + random_.size();
        const dockcore::DockProfile* other = nullptr;
        for (int i = 0; i < 100 && other == nullptr; ++i) {
          const std::size_t k = static_cast<std::size_t>(uniform_int(rng, 0, static_cast<int>(pool) - 1));
          const dockcore::DockProfile& c = k < builtin_.size() ? builtin_[k] : random_[k - builtin_.size()];
          if (std::fabs(static_cast<double>(c.width_m()) - width) >= 0.2 * width) other = &c;
        }
        if (other == nullptr) {
          s.look_alike = LookAlike::kBoard;
          s.world.add_box(dock.transform(v2(db.x0 + 0.01, 0)), 0.02, lw, static_cast<double>(dock.yaw_rad), refl);
          break;
        }
        const Box ob = bounds(*other);
        // Its back plane on the dock's, centred on the dock's origin in y.
        const Pose2 at = dock.compose(pose(db.x0 - ob.x0, -0.5 * (ob.y0 + ob.y1), 0));
        s.world.add_dock(*other, at, refl);
        lw = ob.y1 - ob.y0;
        ldepth = ob.x1 - ob.x0;
        break;
      }
      case LookAlike::kOtherCode:
      case LookAlike::kUntaped: {
        dockcore::DockProfile same = s.profile;
        same.reflector_count = 0;
        if (s.look_alike == LookAlike::kOtherCode && s.code_pattern != 0) {
          int p = uniform_int(rng, kCodePatternMin, kCodePatternMax - 1);  // One of the 5 others.
          if (p >= s.code_pattern) ++p;
          s.look_alike_pattern = p;
          add_code(&same, static_cast<std::size_t>(s.code_segment), s.code_region_m, p);
        }
        s.world.add_dock(same, dock, refl);
        lw = db.y1 - db.y0;
        ldepth = db.x1 - db.x0;
        break;
      }
      case LookAlike::kTapedBoard:
        s.look_alike_pattern = uniform_int(rng, kCodePatternMin, kCodePatternMax);
        add_taped_board(&s.world, dock.compose(pose(db.x0 + 0.01, 0, 0)), 0.02, lw, refl,
                        pattern_tape(lw, s.look_alike_pattern));
        break;
      default:
        lw = 0;
        break;
    }
    keep.x1 = std::max(keep.x1, db.x0 + ldepth);
    keep.y0 = std::min(keep.y0, -0.5 * lw);
    keep.y1 = std::max(keep.y1, 0.5 * lw);
    s.objects.push_back(GenObject{std::string("look-alike-") + to_string(s.look_alike),
                                  dock.transform(v2(db.x0 + 0.5 * ldepth, 0)), 0.5 * std::hypot(ldepth, lw)});
  }

  // Walls, in the dock frame. Back plane x0 = the profile's smallest x.
  const double x0 = db.x0, L = kWallHalfLengthM;
  // A back wall at x = xw, from y = ya to yb. In reflector mode, with the dock (or its shape) standing there, it leaves
  // out where a dock segment lies in the wall's plane: there the dock's surface is what the lidar sees, its tape
  // included (a coincident wall would win the ray cast's tie and hide the tape). Outside the mode it is one segment,
  // as it always was.
  auto back_wall = [&](double xw, double ya, double yb) {
    const bool dock_shape = with_dock || s.look_alike == LookAlike::kOtherCode || s.look_alike == LookAlike::kUntaped;
    if (!P.reflectors || !dock_shape || xw != x0) {
      add_segment(&s.world, dock, xw, ya, xw, yb, wall_refl);
      return;
    }
    const double lo = std::min(ya, yb), hi = std::max(ya, yb);
    std::vector<std::pair<double, double>> cuts;
    for (std::size_t i = 0; i + 1 < s.profile.vertex_count; ++i) {
      const Vec2& a = s.profile.vertices_m[i];
      const Vec2& b = s.profile.vertices_m[i + 1];
      if (X(a) == x0 && X(b) == x0) cuts.emplace_back(std::min(Y(a), Y(b)), std::max(Y(a), Y(b)));
    }
    std::sort(cuts.begin(), cuts.end());
    double from = lo;
    for (const auto& c : cuts) {
      if (c.first > from) add_segment(&s.world, dock, xw, from, xw, std::min(c.first, hi), wall_refl);
      from = std::max(from, c.second);
    }
    if (hi > from) add_segment(&s.world, dock, xw, from, xw, hi, wall_refl);
  };
  auto wall_object = [&](const char* kind, double xa, double ya, double xb, double yb) {
    s.objects.push_back(
        GenObject{kind, dock.transform(v2(0.5 * (xa + xb), 0.5 * (ya + yb))), 0.5 * std::hypot(xb - xa, yb - ya)});
  };
  switch (s.mount) {
    case MountClass::kFlush:
    case MountClass::kGap:
      back_wall(x0 - s.wall_gap_m, -L, L);
      wall_object("wall", x0 - s.wall_gap_m, -L, x0 - s.wall_gap_m, L);
      fs.front_limit = true;
      fs.front_x = x0 - s.wall_gap_m;
      break;
    case MountClass::kSkirting: {
      const double d = s.skirting_depth_m, ya = db.y1 + s.skirting_end_gap_m, yb = db.y0 - s.skirting_end_gap_m;
      back_wall(x0, -L, L);
      const double board_refl = rng.uniform(0.2, 0.9);
      s.world.add_polyline({dock.transform(v2(x0, ya)), dock.transform(v2(x0 + d, ya)), dock.transform(v2(x0 + d, L))},
                           false, board_refl);
      s.world.add_polyline({dock.transform(v2(x0 + d, -L)), dock.transform(v2(x0 + d, yb)), dock.transform(v2(x0, yb))},
                           false, board_refl);
      wall_object("wall", x0, -L, x0, L);
      wall_object("skirting", x0 + d, ya, x0 + d, L);
      wall_object("skirting", x0 + d, -L, x0 + d, yb);
      fs.front_limit = true;
      fs.front_x = x0 + d;
      break;
    }
    case MountClass::kGlass:
    case MountClass::kFreeStanding:
      if (s.back_wall_distance_m > 0) {
        const double xb = x0 - s.back_wall_distance_m;
        add_segment(&s.world, dock, xb, -L - 1, xb, L + 1, wall_refl);
        wall_object("room-wall", xb, -L - 1, xb, L + 1);
        fs.back_limit = true;
        fs.back_x = xb;
      }
      if (s.mount == MountClass::kGlass) {  // Clutter stands on this side of the pane.
        fs.front_limit = true;
        fs.front_x = x0;
      }
      break;
    case MountClass::kCorner: {
      const double xw = x0 - s.wall_gap_m;
      const double ys = s.corner_side > 0 ? db.y1 + s.corner_distance_m : db.y0 - s.corner_distance_m;
      const double far = s.corner_side > 0 ? -L : L;
      back_wall(xw, far, ys);
      add_segment(&s.world, dock, xw, ys, xw + 2.5, ys, wall_refl);
      wall_object("wall", xw, far, xw, ys);
      wall_object("second-wall", xw, ys, xw + 2.5, ys);
      fs.front_limit = true;
      fs.front_x = xw;
      fs.side_wall = s.corner_side;
      fs.side_y = ys;
      break;
    }
    default:
      break;
  }

  // Clutter next to the dock, clear of the line of sight from every lidar position to the dock (or look-alike).
  {
    std::vector<Vec2> pts = fs.lidars;
    for (double x : {keep.x0, keep.x1})
      for (double y : {keep.y0, keep.y1}) pts.push_back(dock.transform(v2(x, y)));
    fs.sight = convex_hull(pts);
    // The dock's own box is kept out as well (it is inside the hull already, this keeps a margin round it).
  }
  s.clutter = static_cast<ClutterClass>(uniform_int(rng, 0, static_cast<int>(ClutterClass::kCount) - 1));
  std::vector<ClutterClass> kinds;
  switch (s.clutter) {
    case ClutterClass::kNone:
      break;
    case ClutterClass::kBoxes:
    case ClutterClass::kChairLegs:
      kinds.assign(static_cast<std::size_t>(uniform_int(rng, 1, 2)), s.clutter);
      break;
    case ClutterClass::kMixed: {
      const int n = uniform_int(rng, 2, 4);
      for (int i = 0; i < n; ++i) kinds.push_back(static_cast<ClutterClass>(uniform_int(rng, 1, 5)));
      break;
    }
    default:
      kinds.push_back(s.clutter);
      break;
  }
  for (ClutterClass k : kinds) {
    const Shape sh = draw_shape(k, rng);
    ++s.clutter_wanted;
    if (place(sh, db, rng, &fs, &s.world, &s.objects)) ++s.clutter_placed;
  }
  if (P.reflectors) {
    s.reflective_wanted = uniform_int(rng, 0, 3);
    for (int i = 0; i < s.reflective_wanted; ++i) {
      const auto k = static_cast<ReflectiveClass>(uniform_int(rng, 0, static_cast<int>(ReflectiveClass::kCount) - 1));
      if (place_reflective(k, db, rng, &fs, &s.world, &s.objects)) s.reflective.push_back(k);
    }
  }
  return s;
}

}  // namespace docksim
