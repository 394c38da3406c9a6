// Scene generators (see docksim/scenes.hpp).
#include "docksim/scenes.hpp"
#include "docksim/angles.hpp"

#include <algorithm>
#include <cmath>

namespace docksim {
namespace {

constexpr double kSqrtHalf = 0.70710678118654752440;

Vec2 v2(double x, double y) { return Vec2(static_cast<Real>(x), static_cast<Real>(y)); }
double X(const Vec2& p) { return static_cast<double>(p.x()); }
double Y(const Vec2& p) { return static_cast<double>(p.y()); }
double cross(const Vec2& o, const Vec2& a, const Vec2& b) {
  return (X(a) - X(o)) * (Y(b) - Y(o)) - (Y(a) - Y(o)) * (X(b) - X(o));
}

}  // namespace

// Andrew's monotone chain.
std::vector<Vec2> convex_hull(std::vector<Vec2> p) {
  std::sort(p.begin(), p.end(), [](const Vec2& a, const Vec2& b) { return X(a) < X(b) || (X(a) == X(b) && Y(a) < Y(b)); });
  if (p.size() < 3) return p;
  std::vector<Vec2> h(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(h[k - 2], h[k - 1], p[i - 1]) <= 0) --k;
    h[k++] = p[i - 1];
  }
  h.resize(k - 1);
  return h;
}

namespace {
double point_segment_distance(const Vec2& p, const Vec2& a, const Vec2& b) {
  const double ex = X(b) - X(a), ey = Y(b) - Y(a);
  const double l2 = ex * ex + ey * ey;
  double u = l2 > 0 ? ((X(p) - X(a)) * ex + (Y(p) - Y(a)) * ey) / l2 : 0.0;
  u = std::min(1.0, std::max(0.0, u));
  return std::hypot(X(a) + u * ex - X(p), Y(a) + u * ey - Y(p));
}
}  // namespace

double distance_to_convex(const Vec2& p, const std::vector<Vec2>& poly) {
  if (poly.empty()) return 1e300;
  if (poly.size() == 1) return std::hypot(X(p) - X(poly[0]), Y(p) - Y(poly[0]));
  bool inside = poly.size() >= 3;
  double d = 1e300;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[(i + 1) % poly.size()];
    if (cross(a, b, p) < 0) inside = false;
    d = std::min(d, point_segment_distance(p, a, b));
  }
  return inside ? 0.0 : d;
}

namespace {

// A candidate object: kind, pose and shape parameters; its bounding circle is about `pose`'s origin.
struct Candidate {
  ObjectKind kind;
  Pose2 pose;
  double radius = 0;
  double p1 = 0, p2 = 0, p3 = 0;  // Shape parameters, meaning per kind (see draw_shape / add_object).
  double reflectivity = 0.5;
};

// Draws the kind-specific shape (size) for a candidate; rng use depends only on the kind.
void draw_shape(Candidate* c, Rng& rng) {
  switch (c->kind) {
    case ObjectKind::kBox:
      c->p1 = rng.uniform(0.15, 0.6);
      c->p2 = rng.uniform(0.15, 0.6);
      c->radius = 0.5 * std::hypot(c->p1, c->p2);
      break;
    case ObjectKind::kTableLegs:
      c->p1 = rng.uniform(0.5, 1.2);    // Width between leg centres.
      c->p2 = rng.uniform(0.4, 0.8);    // Depth between leg centres.
      c->p3 = rng.uniform(0.02, 0.04);  // Leg radius.
      c->radius = 0.5 * std::hypot(c->p1, c->p2) + c->p3;
      break;
    case ObjectKind::kPersonLegs:
      c->p1 = rng.uniform(0.1, 0.3);    // Centre-to-centre.
      c->p3 = rng.uniform(0.05, 0.07);  // Leg radius.
      c->radius = 0.5 * c->p1 + c->p3;
      break;
    case ObjectKind::kCorner:
      c->p1 = rng.uniform(0.3, 1.5);
      c->p2 = rng.uniform(0.3, 1.5);
      c->radius = 0.5 * std::hypot(c->p1, c->p2);
      break;
    case ObjectKind::kWallPiece:
      c->p1 = rng.uniform(0.5, 2.0);
      c->radius = 0.5 * c->p1;
      break;
    case ObjectKind::kLookAlikeBoard:
      c->p1 = 0.02;
      c->p2 = 0.30;
      c->radius = 0.5 * std::hypot(c->p1, c->p2);
      break;
    case ObjectKind::kLookAlikeCorner:
      c->p1 = rng.uniform(0.15, 0.6);  // Arm length.
      c->radius = std::hypot(0.5 * c->p1 * kSqrtHalf, c->p1 * kSqrtHalf);
      break;
    case ObjectKind::kLookAlikeBox:
      c->p1 = rng.uniform(0.10, 0.30);  // Depth.
      c->p2 = 0.30;                     // Width, facing the lidar.
      c->radius = 0.5 * std::hypot(c->p1, c->p2);
      break;
    default:
      break;
  }
}

void add_object(World* w, const Candidate& c) {
  const Pose2& p = c.pose;
  switch (c.kind) {
    case ObjectKind::kBox:
    case ObjectKind::kLookAlikeBoard:
    case ObjectKind::kLookAlikeBox:
      w->add_box(v2(static_cast<double>(p.x_m), static_cast<double>(p.y_m)), c.p1, c.p2,
                 static_cast<double>(p.yaw_rad), c.reflectivity);
      break;
    case ObjectKind::kTableLegs:
      for (int sx = -1; sx <= 1; sx += 2)
        for (int sy = -1; sy <= 1; sy += 2)
          w->add_circle(p.transform(v2(0.5 * sx * c.p1, 0.5 * sy * c.p2)), c.p3, 12, c.reflectivity);
      break;
    case ObjectKind::kPersonLegs:
      w->add_circle(p.transform(v2(0, -0.5 * c.p1)), c.p3, 12, c.reflectivity);
      w->add_circle(p.transform(v2(0, 0.5 * c.p1)), c.p3, 12, c.reflectivity);
      break;
    case ObjectKind::kCorner: {
      // Right angle at local (-p1/2, -p2/2) so the bounding circle (hypotenuse midpoint) is at the origin.
      const double hx = 0.5 * c.p1, hy = 0.5 * c.p2;
      w->add_polyline({p.transform(v2(hx, -hy)), p.transform(v2(-hx, -hy)), p.transform(v2(-hx, hy))}, false,
                      c.reflectivity);
      break;
    }
    case ObjectKind::kWallPiece:
      w->add_polyline({p.transform(v2(0, -0.5 * c.p1)), p.transform(v2(0, 0.5 * c.p1))}, false, c.reflectivity);
      break;
    case ObjectKind::kLookAlikeCorner: {
      // Concave V opening towards local +x: apex at (-q/2, 0), arm ends at (q/2, +-q), q = arm * sqrt(1/2).
      const double q = c.p1 * kSqrtHalf;
      w->add_polyline({p.transform(v2(0.5 * q, -q)), p.transform(v2(-0.5 * q, 0)), p.transform(v2(0.5 * q, q))},
                      false, c.reflectivity);
      break;
    }
    default:
      break;
  }
}

// Where objects may go and what they must keep clear of.
struct Placement {
  Vec2 lidar;
  double radius_m = 4;        // Around the lidar.
  double clearance_m = 0.3;   // From the lidar.
  double margin_m = 0.05;
  std::vector<Vec2> keep_out;  // Convex CCW polygon (dock + line of sight); empty = none.
  bool has_front_plane = false;  // Stay on the +x side of the wall line (in front_frame).
  Pose2 front_frame;
  double front_x = 0;
  bool has_room = false;  // Stay inside |x| <= room_hx, |y| <= room_hy in room_frame.
  Pose2 room_frame;
  double room_hx = 0, room_hy = 0;

  bool ok(const Vec2& c, double r) const {
    const double dl = std::hypot(X(c) - X(lidar), Y(c) - Y(lidar));
    if (dl < r + clearance_m) return false;
    if (!keep_out.empty() && distance_to_convex(c, keep_out) < r + margin_m) return false;
    if (has_front_plane && X(front_frame.inverse_transform(c)) < front_x + r + margin_m) return false;
    if (has_room) {
      const Vec2 q = room_frame.inverse_transform(c);
      if (std::fabs(X(q)) > room_hx - r - margin_m || std::fabs(Y(q)) > room_hy - r - margin_m) return false;
    }
    return true;
  }
};

int object_count(int level) {
  if (level <= 0) return 0;
  if (level == 1) return 3;
  if (level == 2) return 6;
  if (level == 3) return 12;
  return 4 * level;
}

void place_clutter(const ClutterSpec& spec, const Placement& place, Rng& rng, World* world,
                   std::vector<SceneObject>* objects) {
  static const ObjectKind kClutterKinds[] = {ObjectKind::kBox, ObjectKind::kTableLegs, ObjectKind::kPersonLegs,
                                             ObjectKind::kCorner, ObjectKind::kWallPiece};
  static const ObjectKind kLookAlikeKinds[] = {ObjectKind::kLookAlikeBoard, ObjectKind::kLookAlikeCorner,
                                               ObjectKind::kLookAlikeBox};
  const int n_clutter = object_count(spec.clutter_level);
  const int n_total = n_clutter + std::max(0, spec.look_alikes);
  for (int i = 0; i < n_total; ++i) {
    Candidate c;
    const bool look_alike = i >= n_clutter;
    c.kind = look_alike ? kLookAlikeKinds[(i - n_clutter) % 3]
                        : kClutterKinds[std::min<std::uint64_t>(4, static_cast<std::uint64_t>(rng.uniform() * 5))];
    draw_shape(&c, rng);
    c.reflectivity = rng.uniform(spec.reflectivity_min, spec.reflectivity_max);
    bool placed = false;
    for (int attempt = 0; attempt < spec.max_attempts && !placed; ++attempt) {
      const double rr = spec.radius_m * std::sqrt(rng.uniform());
      const double aa = rng.uniform(-kPiD, kPiD);
      const Vec2 centre = v2(X(place.lidar) + rr * std::cos(aa), Y(place.lidar) + rr * std::sin(aa));
      double yaw;
      if (look_alike) {
        // Face the lidar within +-45° so the look-alike is seen from the side that imitates a dock.
        yaw = std::atan2(Y(place.lidar) - Y(centre), X(place.lidar) - X(centre)) + rng.uniform(-0.25 * kPiD, 0.25 * kPiD);
      } else {
        yaw = rng.uniform(-kPiD, kPiD);
      }
      if (!place.ok(centre, c.radius)) continue;
      c.pose = Pose2{centre.x(), centre.y(), dockcore::wrap_angle(static_cast<Real>(yaw))};
      placed = true;
    }
    if (!placed) continue;
    add_object(world, c);
    if (objects) objects->push_back(SceneObject{c.kind, v2(static_cast<double>(c.pose.x_m), static_cast<double>(c.pose.y_m)), c.radius});
  }
}

}  // namespace

const char* to_string(ObjectKind k) {
  switch (k) {
    case ObjectKind::kDock: return "dock";
    case ObjectKind::kWall: return "wall";
    case ObjectKind::kBox: return "box";
    case ObjectKind::kTableLegs: return "table-legs";
    case ObjectKind::kPersonLegs: return "person-legs";
    case ObjectKind::kCorner: return "corner";
    case ObjectKind::kWallPiece: return "wall-piece";
    case ObjectKind::kLookAlikeBoard: return "look-alike-board";
    case ObjectKind::kLookAlikeCorner: return "look-alike-corner";
    case ObjectKind::kLookAlikeBox: return "look-alike-box";
  }
  return "unknown";
}

World build_scene(const SceneSpec& spec, Rng& rng, std::vector<SceneObject>* objects) {
  World world;
  const dockcore::DockProfile& prof = spec.profile;
  double min_x = 0, max_x = 0, min_y = 0, max_y = 0;
  for (std::size_t i = 0; i < prof.vertex_count; ++i) {
    const double x = X(prof.vertices_m[i]), y = Y(prof.vertices_m[i]);
    if (i == 0 || x < min_x) min_x = x;
    if (i == 0 || x > max_x) max_x = x;
    if (i == 0 || y < min_y) min_y = y;
    if (i == 0 || y > max_y) max_y = y;
  }
  const Pose2& dp = spec.dock_pose_in_world;
  if (spec.with_dock && prof.vertex_count >= 2) {
    world.add_dock(prof, dp, spec.dock_reflectivity);
    if (objects) {
      const Vec2 c = dp.transform(v2(0.5 * (min_x + max_x), 0.5 * (min_y + max_y)));
      objects->push_back(SceneObject{ObjectKind::kDock, c, 0.5 * std::hypot(max_x - min_x, max_y - min_y)});
    }
  }
  if (spec.with_wall) {
    // Ordered -y to +y so its (dy, -dx) normal faces the dock's +x, like a profile segment (two-sided anyway).
    world.add_polyline({dp.transform(v2(min_x, -spec.wall_half_length_m)), dp.transform(v2(min_x, spec.wall_half_length_m))},
                       false, spec.wall_reflectivity);
    if (objects) objects->push_back(SceneObject{ObjectKind::kWall, dp.transform(v2(min_x, 0)), spec.wall_half_length_m});
  }

  Placement place;
  place.lidar = v2(static_cast<double>(spec.lidar_pose_in_world.x_m), static_cast<double>(spec.lidar_pose_in_world.y_m));
  place.radius_m = spec.clutter.radius_m;
  place.clearance_m = spec.clutter.lidar_clearance_m;
  place.margin_m = spec.clutter.margin_m;
  // The keep-out region is the same with or without the dock, so with_dock = false gives the same clutter.
  if (prof.vertex_count >= 2) {
    std::vector<Vec2> pts = {place.lidar, dp.transform(v2(min_x, min_y)), dp.transform(v2(min_x, max_y)),
                             dp.transform(v2(max_x, min_y)), dp.transform(v2(max_x, max_y))};
    place.keep_out = convex_hull(pts);
  }
  if (spec.with_wall) {
    place.has_front_plane = true;
    place.front_frame = dp;
    place.front_x = min_x;
  }
  ClutterSpec cs = spec.clutter;
  cs.clutter_level = spec.clutter_level;
  cs.look_alikes = spec.look_alikes;
  place_clutter(cs, place, rng, &world, objects);
  return world;
}

World build_clutter_scene(const ClutterSceneSpec& spec, Rng& rng, std::vector<SceneObject>* objects) {
  World world;
  Placement place;
  place.lidar = v2(static_cast<double>(spec.lidar_pose_in_world.x_m), static_cast<double>(spec.lidar_pose_in_world.y_m));
  place.radius_m = spec.clutter.radius_m;
  place.clearance_m = spec.clutter.lidar_clearance_m;
  place.margin_m = spec.clutter.margin_m;
  if (spec.with_room) {
    const double lo = std::max(0.6, spec.room_half_min_m);
    const double hi = std::max(lo, spec.room_half_max_m);
    const double hx = rng.uniform(lo, hi), hy = rng.uniform(lo, hi);
    const double yaw = rng.uniform(-kPiD, kPiD);
    // Lidar at (ox, oy) in the room frame, at least 0.5 m from every wall.
    const double ox = rng.uniform(-(hx - 0.5), hx - 0.5), oy = rng.uniform(-(hy - 0.5), hy - 0.5);
    const double c = std::cos(yaw), s = std::sin(yaw);
    const Pose2 room{static_cast<Real>(X(place.lidar) - (c * ox - s * oy)),
                     static_cast<Real>(Y(place.lidar) - (s * ox + c * oy)), static_cast<Real>(yaw)};
    world.add_polyline({room.transform(v2(-hx, -hy)), room.transform(v2(-hx, hy)), room.transform(v2(hx, hy)),
                        room.transform(v2(hx, -hy))},
                       true, spec.wall_reflectivity);
    if (objects) objects->push_back(SceneObject{ObjectKind::kWall, v2(static_cast<double>(room.x_m), static_cast<double>(room.y_m)), std::hypot(hx, hy)});
    place.has_room = true;
    place.room_frame = room;
    place.room_hx = hx;
    place.room_hy = hy;
  }
  place_clutter(spec.clutter, place, rng, &world, objects);
  return world;
}

Pose2 dock_pose_from_lidar(double distance_m, double bearing_rad, double dock_yaw_rad) {
  return Pose2{static_cast<Real>(distance_m * std::cos(bearing_rad)), static_cast<Real>(distance_m * std::sin(bearing_rad)),
               dockcore::wrap_angle(static_cast<Real>(bearing_rad + kPiD + dock_yaw_rad))};
}

Pose2 dock_pose_in_world_from_lidar(const Pose2& lidar_pose_in_world, double distance_m, double bearing_rad,
                                    double dock_yaw_rad) {
  return lidar_pose_in_world.compose(dock_pose_from_lidar(distance_m, bearing_rad, dock_yaw_rad));
}

std::vector<Vec2> dock_outline_points(const dockcore::DockProfile& profile, const Pose2& dock_pose_in_world,
                                      int per_segment) {
  std::vector<Vec2> out;
  for (std::size_t i = 0; i + 1 < profile.vertex_count; ++i) {
    for (int k = 1; k <= per_segment; ++k) {
      const double u = static_cast<double>(k) / (per_segment + 1);
      const Vec2 p = profile.vertices_m[i] + static_cast<Real>(u) * (profile.vertices_m[i + 1] - profile.vertices_m[i]);
      out.push_back(dock_pose_in_world.transform(p));
    }
  }
  return out;
}

}  // namespace docksim
