#pragma once
/// Dock profile TOML: the one parser of profile files (docs/docks.md), shared by dock-sim (tools/sim/src/
/// profile_file.cpp) and dockd (app/dockd/config.cpp), and of the [mounting] table, which dockd's [[docks]] entries
/// accept too. Built on the strict key reader (toml_reader.hpp): an unknown key, a wrong type or a value out of range
/// is an `Error` carrying "source:line:col: message". Host-side start-up code: heap and exceptions are fine here.
///
///   name = "my-dock"          # optional, at most 23 characters; default: the caller's default name
///   contact_offset_m = 0.02   # optional, metres in [-1, 1]: every point is shifted by -contact_offset_m in x
///   points = [[x_m, y_m], ...]  # 2..32 points from the dock's -y side to its +y side, >= 1 mm apart
///   min_inliers = 6           # optional, 3..1000: this dock's floor on a detection's beams
///   (DockProfile::min_inliers);
///                             # default: the estimator's; refused together with [[reflectors]], whose code needs that
///   [mounting]                # optional
///   kind = "wall"             # "wall" | "free_standing" | "unknown" (default)
///   wall_gap_m = [0, 0.10]    # metres, each in [0, 0.5], min <= max; only with kind = "wall"; default [0, 0.10]
///   [[reflectors]]            # optional, up to 8: retro-reflective tape on one segment (docs/docks.md, "Reflectors")
///   segment = 2               # segment index: from point 2 to point 3
///   from_m = 0.02             # along the segment from its first point, metres
///   to_m = 0.06               # >= from_m + 0.01, <= the segment's length; stripes must not overlap
///
/// The outline must then pass dockcore::check_profile for an LD06-class lidar (0.8° between beams) at 2.5 m
/// (kProfileCheckDefaultBeamSpacingRad, kProfileCheckDefaultRangeM): it must not cross itself, must hold 3 beams
/// across at 2.5 m, and its surfaces must fix x, y and yaw. Cost: O(text size) + check_profile.

#include <cstdio>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "dockcore/params/toml_reader.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "dockcore/perception/profile_check.hpp"

namespace dockcore::params::profile_toml {

/// A profile file's default name: `path` without its directory and ".toml".
inline std::string name_from_path(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::string ext = ".toml";
  if (base.size() > ext.size() && base.compare(base.size() - ext.size(), ext.size(), ext) == 0) {
    base.resize(base.size() - ext.size());
  }
  return base;
}

/// Reads a [mounting] table (kind, wall_gap_m) at `n`; `path` prefixes its keys in messages ("mounting.",
/// "docks.mounting."). Throws the reader's Error for an unknown key, a bad kind, a gap that is not two numbers in
/// [0, kMaxWallGapM] with min <= max, or a gap given with a kind other than "wall".
template <typename Error>
DockMounting read_mounting(const toml_reader::Reader<Error>& p, const toml::node& n, const std::string& path) {
  DockMounting m;
  const toml::node* gap_node = nullptr;
  p.each(p.table(n), path,
         toml_reader::Handlers{
             {"kind",
              [&](const toml::node& v) {
                const std::string k = p.choice(v, {to_string(DockMountKind::kUnknown), to_string(DockMountKind::kWall),
                                                   to_string(DockMountKind::kFreeStanding)});
                parse_mount_kind(k.c_str(), &m.kind);
              }},
             {"wall_gap_m",
              [&](const toml::node& v) {
                const toml::array* a = v.as_array();
                if (a == nullptr || a->size() != 2) {
                  p.fail(v.source(), p.key() + " must be [min_m, max_m] (two numbers), not " +
                                         (a == nullptr ? std::string(toml_reader::type_name(v))
                                                       : "an array of " + std::to_string(a->size())));
                }
                const double hi = static_cast<double>(kMaxWallGapM);
                const double lo_m = p.number((*a)[0], 0, hi);
                const double hi_m = p.number((*a)[1], 0, hi);
                if (lo_m > hi_m) {
                  char buf[128];
                  std::snprintf(buf, sizeof(buf), " = [%g, %g]: the minimum is larger than the maximum", lo_m, hi_m);
                  p.fail(v.source(), p.key() + buf);
                }
                m.wall_gap_min_m = static_cast<Real>(lo_m);
                m.wall_gap_max_m = static_cast<Real>(hi_m);
                gap_node = &v;
              }},
         });
  if (gap_node != nullptr && m.kind != DockMountKind::kWall) {
    p.fail(gap_node->source(), path + "wall_gap_m is only meaningful with " + path + "kind = \"wall\"");
  }
  if (!mounting_valid(m)) p.fail(n.source(), path + " is not a valid mounting");
  return m;
}

/// Why check_profile refused a profile, as a sentence for a message (no position). `beam_spacing_rad` and
/// `max_range_m` are what it was checked against.
inline std::string check_message(const ProfileCheck& c, Real beam_spacing_rad, Real max_range_m) {
  char buf[400];
  const double deg = static_cast<double>(rad_to_deg(beam_spacing_rad));
  const double range = static_cast<double>(max_range_m);
  switch (c.reason) {
    case ProfileCheckReason::kOk:
      return "ok";
    case ProfileCheckReason::kSelfIntersecting:
      std::snprintf(buf, sizeof(buf),
                    "segments %zu (points %zu-%zu) and %zu (points %zu-%zu) meet: a profile must not "
                    "cross or fold back onto itself",
                    c.segment_a, c.segment_a, c.segment_a + 1, c.segment_b, c.segment_b, c.segment_b + 1);
      break;
    case ProfileCheckReason::kTooSmall:
      if (c.component == PoseComponent::kNone) {
        std::snprintf(buf, sizeof(buf),
                      "the dock is %.3f m wide: at %.2f m a %.2f° lidar puts fewer than %zu beams "
                      "on it (it needs %.3f m)",
                      static_cast<double>(c.width_m), range, deg, kProfileCheckMinBeams,
                      static_cast<double>(c.min_width_m));
      } else {
        std::snprintf(buf, sizeof(buf),
                      "every surface that fixes the dock's %s is narrower than %.3f m (the widest is "
                      "%.3f m): at %.2f m a %.2f° lidar puts fewer than %zu beams on each",
                      to_string(c.component), static_cast<double>(c.min_width_m), static_cast<double>(c.width_m), range,
                      deg, kProfileCheckMinBeams);
      }
      break;
    case ProfileCheckReason::kAmbiguous: {
      const char* hint = c.component == PoseComponent::kY     ? " (a flat face slides along itself: add surfaces that "
                                                                "face sideways, such as wings or steps)"
                         : c.component == PoseComponent::kYaw ? " (a circular arc turns about its centre: add corners)"
                                                              : "";
      std::snprintf(buf, sizeof(buf),
                    "the outline cannot fix the dock's %s: seen from %.0f m ahead and at ±%.0f°, "
                    "its weakest direction has %.2f %% of the strongest one's information (at least %.0f %% needed)%s",
                    to_string(c.component), static_cast<double>(kProfileCheckViewRangeM),
                    static_cast<double>(rad_to_deg(kProfileCheckViewBearingRad)),
                    100 * static_cast<double>(c.eigen_ratio), 100 * static_cast<double>(kProfileCheckMinEigenRatio),
                    hint);
      break;
    }
    case ProfileCheckReason::kNotVisible:
      return "no surface faces the front of the dock (+x): list the points from the dock's -y side to its +y side";
    case ProfileCheckReason::kBadArguments:
      return "the profile has no segment";
  }
  return buf;
}

/// Parses profile TOML held in `text` (format in the file comment); `source` names it in messages, `default_name`
/// is the profile's name when the file gives none. Throws Error. O(text size) + check_profile.
template <typename Error>
DockProfile parse(const std::string& text, const std::string& source, const std::string& default_name) {
  toml_reader::Reader<Error> p(source);
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    p.fail(e.source(), std::string(e.description()));
  }
  const toml::array* points = nullptr;
  std::string name = default_name;
  double contact_offset_m = 0;
  std::int64_t min_inliers = 0;
  const toml::node* min_inliers_node = nullptr;
  DockMounting mounting;
  std::vector<Vec2> v;
  struct StripeEntry {
    ReflectorStripe stripe;
    toml::source_region where;
  };
  std::vector<StripeEntry> stripes;
  p.each(root, "",
         toml_reader::Handlers{
             {"name",
              [&](const toml::node& n) {
                name = p.string(n);
                if (name.empty()) p.fail(n.source(), "name is empty");
                if (name.size() >= sizeof(DockProfile{}.name)) {
                  p.fail(n.source(),
                         "name is longer than " + std::to_string(sizeof(DockProfile{}.name) - 1) + " characters");
                }
              }},
             {"contact_offset_m", [&](const toml::node& n) { contact_offset_m = p.number(n, -1, 1); }},
             {"points",
              [&](const toml::node& n) {
                points = n.as_array();
                if (points == nullptr) {
                  p.fail(n.source(),
                         "points must be an array of [x_m, y_m] pairs, not " + std::string(toml_reader::type_name(n)));
                }
                if (points->size() < 2) {
                  p.fail(n.source(), "points has " + std::to_string(points->size()) + " point(s), at least 2 needed");
                }
                if (points->size() > kMaxProfileVertices) {
                  p.fail((*points)[kMaxProfileVertices].source(), "points has " + std::to_string(points->size()) +
                                                                      " points, at most " +
                                                                      std::to_string(kMaxProfileVertices) + " allowed");
                }
                for (std::size_t i = 0; i < points->size(); ++i) {
                  const toml::node& e = (*points)[i];
                  const toml::array* xy = e.as_array();
                  if (xy == nullptr || xy->size() != 2) {
                    p.fail(e.source(), "point " + std::to_string(i) + " must be [x_m, y_m] (two numbers), not " +
                                           (xy == nullptr ? std::string(toml_reader::type_name(e))
                                                          : "an array of " + std::to_string(xy->size())));
                  }
                  double c[2] = {0, 0};
                  for (std::size_t j = 0; j < 2; ++j) {
                    const toml::node& k = (*xy)[j];
                    const char* axis = j == 0 ? "x" : "y";
                    if (k.as_floating_point() == nullptr && k.as_integer() == nullptr) {
                      p.fail(k.source(), "point " + std::to_string(i) + ": " + axis + " must be a number, not " +
                                             toml_reader::type_name(k));
                    }
                    c[j] = k.as_integer() != nullptr ? static_cast<double>(k.as_integer()->get())
                                                     : k.as_floating_point()->get();
                    if (!std::isfinite(c[j])) p.fail(k.source(), "point " + std::to_string(i) + " is not finite");
                  }
                  const Vec2 q(static_cast<Real>(c[0]), static_cast<Real>(c[1]));
                  if (!v.empty() && (q - v.back()).norm() < static_cast<Real>(0.001)) {
                    p.fail(e.source(), "point " + std::to_string(i) + " is closer than 1 mm to point " +
                                           std::to_string(i - 1) + " (degenerate segment)");
                  }
                  v.push_back(q);
                }
              }},
             {"min_inliers",
              [&](const toml::node& n) {
                // Three beams fix a pose at all; the estimator's own parameter stops at 1000 too.
                min_inliers = p.integer(n, 3, 1000);
                min_inliers_node = &n;
              }},
             {"mounting", [&](const toml::node& n) { mounting = read_mounting(p, n, "mounting."); }},
             {"reflectors",
              [&](const toml::node& n) {
                const toml::array* a = n.as_array();
                if (a == nullptr) p.fail(n.source(), "reflectors must be an array of tables ([[reflectors]])");
                for (const toml::node& e : *a) {
                  StripeEntry s;
                  s.where = e.source();
                  double from_m = -1, to_m = -1;
                  std::int64_t segment = -1;
                  p.each(p.table(e), "reflectors.",
                         toml_reader::Handlers{
                             {"segment",
                              [&](const toml::node& k) {
                                segment = p.integer(k, 0, static_cast<std::int64_t>(kMaxProfileVertices) - 2);
                              }},
                             {"from_m", [&](const toml::node& k) { from_m = p.number(k, 0, 10); }},
                             {"to_m", [&](const toml::node& k) { to_m = p.number(k, 0, 10); }},
                         });
                  if (segment < 0 || from_m < 0 || to_m < 0) {
                    p.fail(e.source(), "a reflector needs segment, from_m and to_m");
                  }
                  s.stripe.segment = static_cast<std::uint8_t>(segment);
                  s.stripe.from_m = static_cast<Real>(from_m);
                  s.stripe.to_m = static_cast<Real>(to_m);
                  stripes.push_back(s);
                }
              }},
         });
  if (points == nullptr) {
    // An empty document has no source region of its own; point at its start.
    toml::source_region start;
    start.begin = {1, 1};
    p.fail(start, "missing 'points' (an array of [x_m, y_m] pairs)");
  }
  DockProfile out;
  const ProfileError err = make_profile(v.data(), v.size(), static_cast<Real>(contact_offset_m), name.c_str(), out);
  // Everything make_profile checks was checked above; keep a positioned message for any future rule.
  if (err != ProfileError::kOk) p.fail(points->source(), to_string(err));
  const ProfileCheck check = check_profile(out, kProfileCheckDefaultBeamSpacingRad, kProfileCheckDefaultRangeM);
  if (check.reason != ProfileCheckReason::kOk) {
    // A crossing is pointed at the first point of the later segment; the other verdicts concern the whole outline.
    const toml::source_region& at =
        check.reason == ProfileCheckReason::kSelfIntersecting ? (*points)[check.segment_b].source() : points->source();
    p.fail(at, "points: " + check_message(check, kProfileCheckDefaultBeamSpacingRad, kProfileCheckDefaultRangeM));
  }
  out.mounting = mounting;
  if (min_inliers_node != nullptr && !stripes.empty()) {
    // The estimator would ignore it (DockProfile::min_inliers): say so rather than keep a setting that does nothing.
    p.fail(min_inliers_node->source(),
           "min_inliers has no effect on a dock with [[reflectors]]: its code is read with the estimator's floor "
           "([estimator] min_inliers)");
  }
  out.min_inliers = static_cast<std::uint16_t>(min_inliers);
  for (std::size_t i = 0; i < stripes.size(); ++i) {
    const ReflectorStripe& s = stripes[i].stripe;
    const std::string what = "reflectors[" + std::to_string(i) + "]: ";
    const ProfileError e = add_reflector(out, s);
    if (e == ProfileError::kOk) continue;
    // add_reflector decides; the message adds what a user needs to mend the entry.
    char detail[96] = "";
    if (e == ProfileError::kReflectorNoSegment) {
      std::snprintf(detail, sizeof detail, " (segment %u; the outline has %zu)", static_cast<unsigned>(s.segment),
                    out.segment_count());
    } else if (e == ProfileError::kReflectorOffSegment) {
      const double len = static_cast<double>((out.vertices_m[s.segment + 1] - out.vertices_m[s.segment]).norm());
      std::snprintf(detail, sizeof detail, " (%.3f-%.3f m on segment %u, which is %.3f m long)",
                    static_cast<double>(s.from_m), static_cast<double>(s.to_m), static_cast<unsigned>(s.segment), len);
    }
    p.fail(stripes[i].where, what + to_string(e) + detail);
  }
  return out;
}

}  // namespace dockcore::params::profile_toml
