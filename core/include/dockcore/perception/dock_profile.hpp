#pragma once
/// @file Dock profiles: the dock's outline as the lidar sees it, a polyline in the dock frame.
///
/// Dock frame: origin at the centre of the charging contacts, x forward out of the dock face (towards an approaching
/// robot), y to the left of x. Vertices run from the dock's -y side to its +y side, so the outward normal of the
/// segment a->b is (b-a) rotated by -90°: n = (dy, -dx)/|b-a|. A lidar sees a segment only from its outward side.

#include <cstddef>
#include <cstdint>

#include "dockcore/geometry.hpp"

namespace dockcore {

/// Most vertices a profile may have; 32 covers every built-in with room for custom steps and notches.
constexpr std::size_t kMaxProfileVertices = 32;

/// Why a profile was refused.
enum class ProfileError : std::uint8_t {
  kOk = 0,
  kTooFewVertices,       ///< Fewer than 2 vertices.
  kTooManyVertices,      ///< More than kMaxProfileVertices.
  kDegenerateSegment,    ///< Two consecutive vertices closer than 1 mm.
  kNotFinite,            ///< A coordinate is NaN or inf.
  kUnknownName,          ///< No built-in profile by that name.
  kReflectorNoSegment,   ///< A reflector stripe names a segment the outline does not have.
  kReflectorOffSegment,  ///< A stripe starts before its segment or ends past it (or is not finite).
  kReflectorTooShort,    ///< A stripe shorter than 1 cm.
  kReflectorOverlap,     ///< A stripe overlaps another on its segment.
  kTooManyReflectors,    ///< kMaxReflectors stripes are there already.
};

/// Human-readable name of a ProfileError, for messages. Never null.
const char* to_string(ProfileError e);

/// How a dock is installed: what lies behind it, as far as the lidar can tell.
enum class DockMountKind : std::uint8_t {
  kUnknown = 0,      ///< Nothing assumed: a wall behind the dock is evidence for it when seen, never a requirement.
  kWall = 1,         ///< Against a wall the lidar sees, its face wall_gap_min_m..wall_gap_max_m behind the dock's back.
  kFreeStanding = 2, ///< Open space (or glass, which the lidar sees through) behind the dock.
};

/// Human-readable name of a DockMountKind ("unknown", "wall", "free_standing"), as in profile and config files.
const char* to_string(DockMountKind k);

/// Parses a DockMountKind name as written by to_string(); false (out untouched) for anything else. O(1).
bool parse_mount_kind(const char* name, DockMountKind* out);

/// A dock's mounting. The gap is measured along the dock's x axis from its back plane (the profile's smallest x)
/// to the wall's face, metres; only used with kWall.
struct DockMounting {
  DockMountKind kind = DockMountKind::kUnknown;
  Real wall_gap_min_m = 0;                         ///< >= 0.
  Real wall_gap_max_m = static_cast<Real>(0.10);   ///< >= wall_gap_min_m, <= kMaxWallGapM.
};

/// Largest wall gap a mounting may state: beyond it the wall is just part of the room.
constexpr Real kMaxWallGapM = static_cast<Real>(0.5);

/// Checks a mounting's bounds (gap range ordered, within [0, kMaxWallGapM], finite). O(1).
bool mounting_valid(const DockMounting& m);

/// Most reflector stripes a profile may carry.
constexpr std::size_t kMaxReflectors = 8;

/// A stripe of retro-reflective tape on one profile segment: from `from_m` to `to_m` along it, measured from the
/// segment's first vertex (docs/docks.md, "Reflectors"). The pattern of stripes and gaps tells docks of one shape
/// apart.
struct ReflectorStripe {
  std::uint8_t segment = 0;  ///< Segment index: vertices segment .. segment+1.
  Real from_m = 0;           ///< Start along the segment, m, >= 0.
  Real to_m = 0;             ///< End along the segment, m, <= the segment's length, >= from_m + 0.01.
};

/// A dock outline. Trivially copyable, fixed size.
struct DockProfile {
  Vec2 vertices_m[kMaxProfileVertices] = {};
  std::size_t vertex_count = 0;
  char name[24] = {};
  DockMounting mounting{};  ///< How this dock is installed; the built-ins are kUnknown.
  /// Retro-reflective stripes, in order along the outline (segment, then from_m); none on the built-ins.
  ReflectorStripe reflectors[kMaxReflectors] = {};
  std::size_t reflector_count = 0;
  /// This dock's own floor on the beams a detection needs (0: EstimatorParams::min_inliers). A small dock seen from
  /// afar gives fewer returns than a large one; its floor is the lowest that keeps its false docks on real dock-less
  /// scans within 1 % (docs/docks.md, "Which floor"): the built-in v-marker and breakpoint 6, plate-v the estimator's.
  /// Not used once the profile carries reflector stripes (their code needs the estimator's floor).
  std::uint16_t min_inliers = 0;

  std::size_t segment_count() const { return vertex_count > 0 ? vertex_count - 1 : 0; }
  /// Length of the polyline in metres. O(vertices).
  Real length_m() const;
  /// Outward unit normal of segment i (precondition i < segment_count()). O(1).
  Vec2 normal(std::size_t i) const;
  /// Width across y (max y - min y) in metres. O(vertices).
  Real width_m() const;
};

/// Builds a profile from vertices given in a frame where the contacts' centre lies at (contact_offset_m, 0):
/// every vertex is shifted by -contact_offset_m in x so the result is in the dock frame. Validates as documented by
/// ProfileError; on error `out` is untouched. O(n).
ProfileError make_profile(const Vec2* vertices_m, std::size_t n, Real contact_offset_m, const char* name,
                          DockProfile& out);

/// Adds a reflector stripe to `profile`, keeping the stripes in order along the outline. A stripe ending up to 0.5 mm
/// past its segment's end (a file's millimetre rounding) is cut at the end. On error the profile is unchanged and the
/// result says which rule the stripe broke: kTooManyReflectors, kReflectorNoSegment, kReflectorOffSegment (also not
/// finite), kReflectorTooShort (under 1 cm), kReflectorOverlap. O(kMaxReflectors).
ProfileError add_reflector(DockProfile& profile, const ReflectorStripe& stripe);

/// Names of the built-in profiles, null-terminated list: "breakpoint", "v-marker", "plate-v". Dimensions in docs/docks.md.
extern const char* const kBuiltinProfileNames[];

/// Fills `out` with the built-in profile called `name`. Returns kUnknownName (out untouched) otherwise. O(1).
ProfileError builtin_profile(const char* name, DockProfile& out);

}  // namespace dockcore
