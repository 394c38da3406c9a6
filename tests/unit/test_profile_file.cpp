// Profile TOML files: a good file gives the expected vertices (shifted by contact_offset_m); every kind of error
// names the line:column of the offending key or value.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "dockcore/perception/dock_profile.hpp"
#include "docksim/profile_file.hpp"

#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using dockcore::DockProfile;
using docksim::parse_profile_toml;
using docksim::ProfileFileError;

namespace {

/// Parses `text` expecting failure; returns the error (fails the test if parsing succeeded).
ProfileFileError expect_error(const std::string& text) {
  try {
    parse_profile_toml(text, "t.toml");
  } catch (const ProfileFileError& e) {
    return e;
  }
  FAIL("expected a ProfileFileError");
  return ProfileFileError("unreachable");
}

void check_position(const std::string& text, int line, int column, const char* needle) {
  const ProfileFileError e = expect_error(text);
  const std::string msg = e.what();
  LONGS_EQUAL(line, e.line());
  LONGS_EQUAL(column, e.column());
  const std::string prefix = "t.toml:" + std::to_string(line) + ":" + std::to_string(column) + ": ";
  STRCMP_EQUAL(prefix.c_str(), msg.substr(0, prefix.size()).c_str());
  CHECK_TEXT(msg.find(needle) != std::string::npos, msg.c_str());
}

}  // namespace

TEST_GROUP(ProfileFile){};

TEST(ProfileFile, GoodFileWithOffsetAndName) {
  const std::string text =
      "# a plate with wings\n"
      "name = \"wings\"\n"
      "contact_offset_m = 0.02\n"
      "points = [[-0.05, -0.2], [0.02, -0.15], [0.02, 0.15], [-0.05, 0.2]]\n";
  const DockProfile p = parse_profile_toml(text, "t.toml");
  STRCMP_EQUAL("wings", p.name);
  LONGS_EQUAL(4, p.vertex_count);
  // Every x shifted by -0.02 so the contacts sit at the origin.
  REAL_EQUAL(-0.07, p.vertices_m[0].x(), 1e-12);
  REAL_EQUAL(-0.20, p.vertices_m[0].y(), 1e-12);
  REAL_EQUAL(0.0, p.vertices_m[1].x(), 1e-12);
  REAL_EQUAL(0.15, p.vertices_m[2].y(), 1e-12);
  REAL_EQUAL(0.40, p.width_m(), 1e-12);
  // Face segment 1 runs -y -> +y at x = 0: outward normal +x.
  REAL_EQUAL(1.0, p.normal(1).x(), 1e-12);
}

TEST(ProfileFile, IntegersAcceptedAndDefaultName) {
  const DockProfile p = parse_profile_toml("points = [[-1, -2], [0, -1], [0, 1], [-1, 2]]\n", "x.toml", "fallback");
  STRCMP_EQUAL("fallback", p.name);
  LONGS_EQUAL(4, p.vertex_count);
  REAL_EQUAL(2.0 + 2 * std::sqrt(2.0), p.length_m(), 1e-12);
  // No [mounting]: nothing assumed about what is behind the dock.
  CHECK(p.mounting.kind == dockcore::DockMountKind::kUnknown);
}

TEST(ProfileFile, RoundTripOfBuiltins) {
  for (const char* const* n = dockcore::kBuiltinProfileNames; *n != nullptr; ++n) {
    DockProfile b;
    LONGS_EQUAL(0, static_cast<int>(dockcore::builtin_profile(*n, b)));
    const DockProfile p = parse_profile_toml(docksim::profile_to_toml(b), "rt.toml");
    STRCMP_EQUAL(*n, p.name);
    // 6 decimals in the file: within 1 µm, so not bit-identical, but the same outline for every purpose.
    LONGS_EQUAL(b.vertex_count, p.vertex_count);
    for (std::size_t i = 0; i < b.vertex_count; ++i) CHECK((b.vertices_m[i] - p.vertices_m[i]).norm() < 1e-6);
    CHECK_EQUAL(b.min_inliers, p.min_inliers);  // the small built-ins' own floor goes through the file too
  }
}

TEST(ProfileFile, TomlSyntaxError) {
  // Unterminated array: toml++ gives up at the end of the input (line 3, after the last newline).
  const ProfileFileError e = expect_error("name = \"a\"\npoints = [[0, 1], [0, 2]\n");
  CHECK(e.line() >= 2 && e.line() <= 3);
  CHECK(std::string(e.what()).rfind("t.toml:" + std::to_string(e.line()) + ":", 0) == 0);
}

TEST(ProfileFile, UnknownKey) {
  check_position("points = [[0, -1], [0, 1]]\n  widht = 3\n", 2, 3, "unknown key 'widht'");
}

TEST(ProfileFile, MissingPoints) {
  check_position("name = \"x\"\n", 1, 1, "missing 'points'");
}

TEST(ProfileFile, PointsNotArray) {
  check_position("points = \"abc\"\n", 1, 10, "points must be an array");
}

TEST(ProfileFile, CoordinateNotNumber) {
  //                 col: 1234567890123456789012
  check_position("points = [[0, -1],\n          [0, \"one\"]]\n", 2, 15, "y must be a number");
}

TEST(ProfileFile, PointWithThreeNumbers) {
  check_position("points = [[0, -1], [0, 1, 2]]\n", 1, 20, "must be [x_m, y_m]");
}

TEST(ProfileFile, TooFewPoints) {
  check_position("\npoints = [[0, -1]]\n", 2, 10, "at least 2");
}

TEST(ProfileFile, TooManyPoints) {
  std::string text = "points = [\n";
  for (int i = 0; i < 33; ++i) text += "  [0, " + std::to_string(i) + "],\n";  // point i on line i + 2
  text += "]\n";
  // The 33rd point (index 32) is the first one too many: line 34, column 3.
  check_position(text, 34, 3, "at most 32");
}

TEST(ProfileFile, DegenerateSegment) {
  check_position("points = [[0, -1],\n  [0, 0], [0.0005, 0]]\n", 2, 11, "closer than 1 mm");
}

TEST(ProfileFile, BadContactOffsetAndName) {
  check_position("points = [[0, -1], [0, 1]]\ncontact_offset_m = \"2cm\"\n", 2, 20,
                 "contact_offset_m must be a number");
  check_position("name = 7\npoints = [[0, -1], [0, 1]]\n", 1, 8, "name must be a string");
  check_position("name = \"a-name-that-is-far-too-long\"\npoints = [[0, -1], [0, 1]]\n", 1, 8, "longer than 23");
}

TEST(ProfileFile, NonFinite) {
  check_position("points = [[0, -1], [nan, 1]]\n", 1, 21, "not finite");
}

TEST(ProfileFile, ResolveBuiltinFileAndUnknown) {
  const DockProfile b = docksim::resolve_profile("v-marker");
  LONGS_EQUAL(3, b.vertex_count);
  CHECK(docksim::same_outline_as_builtin(b, "v-marker"));
  CHECK_FALSE(docksim::same_outline_as_builtin(b, "plate-v"));

  const std::string path = "test_profile_file_tmp.toml";
  {
    std::ofstream f(path);
    f << "points = [[-0.05, -0.15], [0, -0.1], [0, 0.1], [-0.05, 0.15]]\n";
  }
  const DockProfile p = docksim::resolve_profile(path);
  STRCMP_EQUAL("test_profile_file_tmp", p.name);
  REAL_EQUAL(0.3, p.width_m(), 1e-12);
  std::remove(path.c_str());

  try {
    docksim::resolve_profile("plate");
    FAIL("unknown name accepted");
  } catch (const ProfileFileError& e) {
    CHECK(std::string(e.what()).find("breakpoint, v-marker, plate-v") != std::string::npos);
  }
  try {
    docksim::resolve_profile("no/such/file.toml");
    FAIL("missing file accepted");
  } catch (const ProfileFileError& e) {
    CHECK(std::string(e.what()).find("cannot open") != std::string::npos);
    LONGS_EQUAL(0, e.line());
  }
}

namespace {
/// A good outline (plate-v's shape) to which the mounting tests add tables; one line, so [mounting] starts on line 2.
const std::string kWings = "points = [[-0.07, -0.22], [0, -0.15], [0, 0.15], [-0.07, 0.22]]\n";
}  // namespace

TEST(ProfileFile, MountingKinds) {
  const DockProfile wall =
      parse_profile_toml(kWings + "[mounting]\nkind = \"wall\"\nwall_gap_m = [0.02, 0.08]\n", "t.toml");
  CHECK(wall.mounting.kind == dockcore::DockMountKind::kWall);
  REAL_EQUAL(0.02, wall.mounting.wall_gap_min_m, 1e-12);
  REAL_EQUAL(0.08, wall.mounting.wall_gap_max_m, 1e-12);
  // kind wall without a gap: the default range [0, 0.10].
  const DockProfile flush = parse_profile_toml(kWings + "[mounting]\nkind = \"wall\"\n", "t.toml");
  REAL_EQUAL(0.0, flush.mounting.wall_gap_min_m, 1e-12);
  REAL_EQUAL(0.10, flush.mounting.wall_gap_max_m, 1e-12);
  const DockProfile free = parse_profile_toml(kWings + "[mounting]\nkind = \"free_standing\"\n", "t.toml");
  CHECK(free.mounting.kind == dockcore::DockMountKind::kFreeStanding);
  const DockProfile unknown = parse_profile_toml(kWings + "[mounting]\nkind = \"unknown\"\n", "t.toml");
  CHECK(unknown.mounting.kind == dockcore::DockMountKind::kUnknown);
  // An empty [mounting] is allowed and changes nothing.
  CHECK(parse_profile_toml(kWings + "[mounting]\n", "t.toml").mounting.kind == dockcore::DockMountKind::kUnknown);
}

TEST(ProfileFile, MountingRoundTrips) {
  for (const char* table :
       {"[mounting]\nkind = \"wall\"\nwall_gap_m = [0.03, 0.25]\n", "[mounting]\nkind = \"free_standing\"\n", ""}) {
    const DockProfile a = parse_profile_toml(kWings + table, "a.toml");
    const DockProfile b = parse_profile_toml(docksim::profile_to_toml(a), "b.toml");
    CHECK(a.mounting.kind == b.mounting.kind);
    REAL_EQUAL(a.mounting.wall_gap_min_m, b.mounting.wall_gap_min_m, 1e-9);
    REAL_EQUAL(a.mounting.wall_gap_max_m, b.mounting.wall_gap_max_m, 1e-9);
  }
}

TEST(ProfileFile, BadMountingValuesArePositioned) {
  check_position(kWings + "[mounting]\nkind = \"glued\"\n", 3, 8,
                 "mounting.kind = \"glued\" is not one of unknown, wall, free_standing");
  check_position(kWings + "[mounting]\nkind = 1\n", 3, 8, "mounting.kind must be a string");
  check_position(kWings + "[mounting]\nkind = \"wall\"\n  gap = 0.1\n", 4, 3,
                 "unknown key 'mounting.gap' (expected kind, wall_gap_m)");
  //                                                     col: 12345678901234567890
  check_position(kWings + "[mounting]\nkind = \"wall\"\nwall_gap_m = [0, 0.6]\n", 4, 18,
                 "mounting.wall_gap_m = 0.6 is out of range [0, 0.5]");
  check_position(kWings + "[mounting]\nkind = \"wall\"\nwall_gap_m = [-0.01, 0.1]\n", 4, 15, "out of range [0, 0.5]");
  check_position(kWings + "[mounting]\nkind = \"wall\"\nwall_gap_m = [0.2, 0.1]\n", 4, 14,
                 "minimum is larger than the maximum");
  check_position(kWings + "[mounting]\nkind = \"wall\"\nwall_gap_m = 0.1\n", 4, 14, "must be [min_m, max_m]");
  check_position(kWings + "[mounting]\nkind = \"wall\"\nwall_gap_m = [0, \"5cm\"]\n", 4, 18,
                 "mounting.wall_gap_m must be a number");
  check_position(kWings + "[mounting]\nkind = \"free_standing\"\nwall_gap_m = [0, 0.1]\n", 4, 14,
                 "mounting.wall_gap_m is only meaningful with mounting.kind = \"wall\"");
  // Without kind the kind is unknown, so a gap is refused as well.
  check_position(kWings + "[mounting]\nwall_gap_m = [0, 0.1]\n", 3, 14, "only meaningful with");
  check_position(kWings + "mounting = \"wall\"\n", 2, 12, "mounting must be a table");
}

TEST(ProfileFile, OutlinesCheckProfileRefusesArePositioned) {
  // A flat plate cannot fix y.
  check_position("name = \"plate\"\npoints = [[0, -0.2], [0, 0.2]]\n", 2, 10, "cannot fix the dock's y");
  // A Z whose last segment crosses the first: pointed at the later segment's first point (point 2).
  check_position("points = [[0, -0.15],\n  [0, 0.15],\n  [-0.1, 0.15], [0.05, 0]]\n", 3, 3,
                 "segments 0 (points 0-1) and 2 (points 2-3) meet");
  // 5 cm wide: fewer than 3 beams of an 0.8° lidar at 2.5 m.
  check_position("points = [[0, -0.025], [-0.025, 0], [0, 0.025]]\n", 1, 10,
                 "the dock is 0.050 m wide: at 2.50 m a 0.80° lidar puts fewer than 3 beams on it (it needs 0.070 m)");
  // Every outward normal points away from the front.
  check_position("points = [[0, 0.2], [0, -0.2]]\n", 1, 10, "no surface faces the front");
}

TEST(ProfileFile, ReflectorsAreReadInOrderAndRoundTrip) {
  const std::string text =
      "points = [[-0.05, -0.2], [0, -0.15], [0, 0.15], [-0.05, 0.2]]\n"
      "[[reflectors]]\nsegment = 1\nfrom_m = 0.20\nto_m = 0.30\n"
      "[[reflectors]]\nsegment = 1\nfrom_m = 0\nto_m = 0.1\n";
  const DockProfile p = parse_profile_toml(text, "t.toml");
  CHECK_EQUAL(2u, p.reflector_count);
  CHECK_EQUAL(1, p.reflectors[0].segment);
  REAL_EQUAL(0.0, p.reflectors[0].from_m, 1e-12);  // in order along the outline, whatever the file's order
  REAL_EQUAL(0.30, p.reflectors[1].to_m, 1e-6);
  const DockProfile q = parse_profile_toml(docksim::profile_to_toml(p), "rt.toml");
  CHECK_EQUAL(2u, q.reflector_count);
  for (std::size_t i = 0; i < 2; ++i) {
    CHECK_EQUAL(p.reflectors[i].segment, q.reflectors[i].segment);
    REAL_EQUAL(p.reflectors[i].from_m, q.reflectors[i].from_m, 1e-9);
    REAL_EQUAL(p.reflectors[i].to_m, q.reflectors[i].to_m, 1e-9);
  }
}

TEST(ProfileFile, BadReflectorsArePositioned) {
  const std::string pts = "points = [[-0.05, -0.2], [0, -0.15], [0, 0.15], [-0.05, 0.2]]\n";
  check_position(pts + "[[reflectors]]\nsegment = 3\nfrom_m = 0\nto_m = 0.05\n", 2, 1,
                 "on a segment the outline does not have (segment 3; the outline has 3)");
  check_position(pts + "[[reflectors]]\nsegment = 1\nfrom_m = 0.25\nto_m = 0.35\n", 2, 1,
                 "runs off its segment (0.250-0.350 m on segment 1, which is 0.300 m long)");
  check_position(pts + "[[reflectors]]\nsegment = 1\nfrom_m = 0.1\nto_m = 0.105\n", 2, 1, "shorter than 1 cm");
  check_position(pts +
                     "[[reflectors]]\nsegment = 1\nfrom_m = 0\nto_m = 0.1\n[[reflectors]]\nsegment = 1\n"
                     "from_m = 0.05\nto_m = 0.15\n",
                 6, 1, "overlaps another");
  std::string nine = pts;
  for (int k = 0; k < 9; ++k) {
    nine += "[[reflectors]]\nsegment = 1\nfrom_m = " + std::to_string(0.03 * k) +
            "\nto_m = " + std::to_string(0.03 * k + 0.02) + "\n";
  }
  check_position(nine, 2 + 4 * 8, 1, "more than 8 reflector stripes");
  check_position(pts + "[[reflectors]]\nsegment = 1\nfrom_m = 0\n", 2, 1, "needs segment, from_m and to_m");
  check_position(pts + "[[reflectors]]\nsegment = 1\nfrom_m = 0\nto_m = 0.1\nwidth_m = 3\n", 6, 1,
                 "unknown key 'reflectors.width_m'");
  check_position(pts + "reflectors = 3\n", 2, 14, "array of tables");
}

TEST(ProfileFile, ADocksOwnFloorOnInliersIsReadAndRoundTrips) {
  const DockProfile none = parse_profile_toml(kWings, "t.toml");
  CHECK_EQUAL(0, none.min_inliers);  // no key: the estimator's floor
  const DockProfile p = parse_profile_toml(kWings + "min_inliers = 7\n", "t.toml");
  CHECK_EQUAL(7, p.min_inliers);
  CHECK_EQUAL(7, parse_profile_toml(docksim::profile_to_toml(p), "rt.toml").min_inliers);
}

TEST(ProfileFile, BadFloorsOnInliersArePositioned) {
  //                                 col: 1234567890123456
  check_position(kWings + "min_inliers = 2\n", 2, 15, "min_inliers = 2 is out of range [3, 1000]");
  check_position(kWings + "min_inliers = 6.5\n", 2, 15, "min_inliers must be an integer");
  // A coded dock's code is read with the estimator's floor: a floor of its own would do nothing, so it is refused.
  check_position(kWings + "min_inliers = 6\n[[reflectors]]\nsegment = 1\nfrom_m = 0\nto_m = 0.1\n", 2, 15,
                 "min_inliers has no effect on a dock with [[reflectors]]");
}
