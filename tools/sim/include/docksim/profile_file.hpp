#pragma once
// Dock profiles from TOML files, and the name-or-path resolution the command-line tools share.
//
// File format (all lengths in metres, dock frame: origin at the charging contacts' centre, x out of the dock face,
// vertices from the dock's -y side to its +y side so the outward normal of a->b is (dy, -dx)):
//
//   name = "my-dock"                  # optional, at most 23 characters; default: the file name without .toml
//   contact_offset_m = 0.0            # optional, [-1, 1]: the contacts' centre lies at (contact_offset_m, 0) in the
//                                     # frame the points are written in; every point is shifted by -contact_offset_m
//   points = [[-0.07, -0.22], [0.0, -0.15], [0.0, 0.15], [-0.07, 0.22]]
//
//   [mounting]                        # optional: how the dock is installed (dockcore::DockMounting)
//   kind = "wall"                     # "wall" | "free_standing" | "unknown" (default "unknown")
//   wall_gap_m = [0.0, 0.10]          # only with kind = "wall": the wall's face lies min..max metres behind the
//                                     # dock's back plane; each in [0, 0.5], min <= max; default [0, 0.10]
//
// Integers are accepted where numbers are expected. Anything else — an unknown key, a value of the wrong type or out
// of range, a point that is not two finite numbers, fewer than 2 or more than 32 points, two consecutive points
// closer than 1 mm, and an outline that dockcore::check_profile refuses for an LD06-class lidar (0.8°) at 2.5 m
// (crossing itself, too small, or unable to fix x, y or yaw, e.g. a flat plate) — is an error whose message starts
// with "<source>:<line>:<column>: " (1-based, from the TOML source region of the offending key or value; a crossing
// points at the later segment's first point, the other outline verdicts at the points array).
// The parser is dockcore/params/profile_toml.hpp, which dockd's config uses for the same files.
// Host-side: errors are exceptions (ProfileFileError).
#include <stdexcept>
#include <string>

#include "dockcore/perception/dock_profile.hpp"

namespace docksim {

/// A profile file or name could not be turned into a profile. what() is a complete, user-readable message; for
/// errors inside a file it starts with "<source>:<line>:<column>: ".
class ProfileFileError : public std::runtime_error {
 public:
  ProfileFileError(const std::string& message, int line = 0, int column = 0)
      : std::runtime_error(message), line_(line), column_(column) {}
  /// 1-based position in the TOML source of what was wrong; 0 when not tied to a position (e.g. unreadable file).
  int line() const { return line_; }
  int column() const { return column_; }

 private:
  int line_;
  int column_;
};

/// Parses profile TOML held in `text`. `source_name` names it in messages (a path, or e.g. "<string>");
/// `default_name` is the profile name used when the file gives none. Throws ProfileFileError. O(text size).
dockcore::DockProfile parse_profile_toml(const std::string& text, const std::string& source_name,
                                         const std::string& default_name = "custom");

/// Reads and parses a profile TOML file; the default name is the file name without directory and ".toml".
/// Throws ProfileFileError (also when the file cannot be read).
dockcore::DockProfile load_profile_file(const std::string& path);

/// A built-in profile name ("breakpoint", "v-marker", "plate-v") or, when `name_or_path` ends in ".toml" or
/// contains a '/', a profile file. Throws ProfileFileError with the list of built-in names otherwise.
dockcore::DockProfile resolve_profile(const std::string& name_or_path);

/// True when `profile` has exactly the vertices of the built-in profile `builtin_name` (within 1e-9 m): lets tools
/// decide whether a detector made for one particular dock (the breakpoint detector) applies.
bool same_outline_as_builtin(const dockcore::DockProfile& profile, const char* builtin_name);

/// The profile as TOML in the format above (points with 6 decimals, contact_offset_m omitted, [mounting] unless the
/// kind is unknown). Round-trips through parse_profile_toml.
std::string profile_to_toml(const dockcore::DockProfile& profile);

}  // namespace docksim
