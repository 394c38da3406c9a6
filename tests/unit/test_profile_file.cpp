// Profile TOML files: a good file gives the expected vertices (shifted by contact_offset_m); every kind of error
// names the line:column of the offending key or value.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "dockcore/dock_profile.hpp"
#include "docksim/profile_file.hpp"

#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using dockcore::DockProfile;
using docksim::ProfileFileError;
using docksim::parse_profile_toml;

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
  const DockProfile p = parse_profile_toml("points = [[0, -1], [0, 1]]\n", "x.toml", "fallback");
  STRCMP_EQUAL("fallback", p.name);
  LONGS_EQUAL(2, p.vertex_count);
  REAL_EQUAL(2.0, p.length_m(), 1e-12);
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

TEST(ProfileFile, MissingPoints) { check_position("name = \"x\"\n", 1, 1, "missing 'points'"); }

TEST(ProfileFile, PointsNotArray) { check_position("points = \"abc\"\n", 1, 10, "points must be an array"); }

TEST(ProfileFile, CoordinateNotNumber) {
  //                 col: 1234567890123456789012
  check_position("points = [[0, -1],\n          [0, \"one\"]]\n", 2, 15, "y must be a number");
}

TEST(ProfileFile, PointWithThreeNumbers) {
  check_position("points = [[0, -1], [0, 1, 2]]\n", 1, 20, "must be [x_m, y_m]");
}

TEST(ProfileFile, TooFewPoints) { check_position("\npoints = [[0, -1]]\n", 2, 10, "at least 2"); }

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
  check_position("points = [[0, -1], [0, 1]]\ncontact_offset_m = \"2cm\"\n", 2, 20, "contact_offset_m must be a number");
  check_position("name = 7\npoints = [[0, -1], [0, 1]]\n", 1, 8, "name must be a string");
  check_position("name = \"a-name-that-is-far-too-long\"\npoints = [[0, -1], [0, 1]]\n", 1, 8, "longer than 23");
}

TEST(ProfileFile, NonFinite) { check_position("points = [[0, -1], [nan, 1]]\n", 1, 21, "not finite"); }

TEST(ProfileFile, ResolveBuiltinFileAndUnknown) {
  const DockProfile b = docksim::resolve_profile("v-marker");
  LONGS_EQUAL(3, b.vertex_count);
  CHECK(docksim::same_outline_as_builtin(b, "v-marker"));
  CHECK_FALSE(docksim::same_outline_as_builtin(b, "plate-v"));

  const std::string path = "test_profile_file_tmp.toml";
  {
    std::ofstream f(path);
    f << "points = [[0, -0.1], [0, 0.1]]\n";
  }
  const DockProfile p = docksim::resolve_profile(path);
  STRCMP_EQUAL("test_profile_file_tmp", p.name);
  REAL_EQUAL(0.2, p.width_m(), 1e-12);
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
