// dockd's config: every error names file:line:column; defaults and derived values; the docked-target correction.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "config.hpp"

#include "real_tolerance.hpp"

#include "CppUTest/TestHarness.h"

namespace {
std::string error_of(const std::string& text) {
  try {
    dockd::parse_config_toml(text, "t.toml");
  } catch (const dockd::ConfigError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST_GROUP(DockdConfig){};

TEST(DockdConfig, DefaultsAreUsable) {
  const dockd::DockdConfig c = dockd::parse_config_toml("", "t.toml");
  STRCMP_EQUAL("can0", c.can_interface.c_str());
  CHECK_EQUAL(200u, c.watchdog.lidar_stale_ms);
  CHECK_EQUAL(200u, c.watchdog.chassis_stale_ms);
  STRCMP_EQUAL("127.0.0.1", c.host.bind_address.c_str());
  CHECK_EQUAL(1u, c.docks.size());
  CHECK_EQUAL(1u, c.task.accepted_dock_ids);
  STRCMP_EQUAL("smooth", c.controller.c_str());
}

TEST(DockdConfig, ErrorsCarryLineAndColumn) {
  STRCMP_CONTAINS("t.toml:2:1: unknown key 'lidar.speed'", error_of("[lidar]\nspeed = 1\n").c_str());
  STRCMP_CONTAINS("t.toml:2:12: lidar.protocol = \"ld07\" is not one of", error_of("[lidar]\nprotocol = \"ld07\"\n").c_str());
  STRCMP_CONTAINS("t.toml:2:11: robot.track_m = 9 is out of range", error_of("[robot]\ntrack_m = 9\n").c_str());
  STRCMP_CONTAINS("t.toml:2:8: host.port must be an integer, not a float", error_of("[host]\nport = 1.5\n").c_str());
  STRCMP_CONTAINS("t.toml:1:1: unknown key 'hosts'", error_of("hosts = 1\n").c_str());
  STRCMP_CONTAINS("t.toml:2:14: host.allowlist: '10.0.0.300'", error_of("[host]\nallowlist = [\"10.0.0.300\"]\n").c_str());
  STRCMP_CONTAINS("t.toml:3:1: dock id 1 appears twice", error_of("[[docks]]\nid = 1\n[[docks]]\nid = 1\n").c_str());
  STRCMP_CONTAINS("dock profile \"round\" is neither", error_of("[[docks]]\nid = 1\nprofile = \"round\"\n").c_str());
  STRCMP_CONTAINS("t.toml:1:", error_of("[can\n").c_str());
  STRCMP_CONTAINS("dock.default_id = 4 is not a configured dock id", error_of("[dock]\ndefault_id = 4\n").c_str());
}

TEST(DockdConfig, DockDatabaseAndDerivedValues) {
  const dockd::DockdConfig c = dockd::parse_config_toml(
      "[robot]\npad_reach_m = 0.3\n[dock]\ndefault_id = 5\n[[docks]]\nid = 5\nprofile = \"v-marker\"\n"
      "target_x_m = 0.31\ntarget_y_m = 0.002\ntarget_yaw_deg = 179\n[[docks]]\nid = 2\n",
      "t.toml");
  CHECK_EQUAL(2u, c.docks.size());
  CHECK_EQUAL((1u << 5) | (1u << 2), c.task.accepted_dock_ids);
  const dockd::DockEntry* d = c.find_dock(5);
  CHECK_TRUE(d != nullptr && d->has_target);
  DOUBLES_EQUAL(0.3, static_cast<double>(c.smooth.common.pad_reach_m), 1e-6);
}

TEST(DockdConfig, TargetCorrectionMovesTheEstimateOntoTheNominalPose) {
  // A dock seen at `target` from the docked robot must be reported at `nominal` by an estimator using the corrected
  // profile: the corrected vertices placed at nominal equal the true vertices placed at target.
  dockcore::DockProfile p;
  CHECK_EQUAL(static_cast<int>(dockcore::ProfileError::kOk), static_cast<int>(dockcore::builtin_profile("plate-v", p)));
  const dockcore::Pose2 nominal{static_cast<dockcore::Real>(0.225), 0, dockcore::kPi};
  const dockcore::Pose2 target{static_cast<dockcore::Real>(0.235), static_cast<dockcore::Real>(-0.006),
                               static_cast<dockcore::Real>(3.10)};
  const dockcore::DockProfile q = dockd::profile_for_target(p, nominal, target);
  for (std::size_t i = 0; i < p.vertex_count; ++i) {
    const dockcore::Vec2 a = target.transform(p.vertices_m[i]);
    const dockcore::Vec2 b = nominal.transform(q.vertices_m[i]);
    // Two chains of rotations and translations in Real: in the float build they differ by a few ulps.
    DOUBLES_EQUAL(static_cast<double>(a.x()), static_cast<double>(b.x()),
                  dockcore_test::real_tol(static_cast<double>(a.x()), 1e-9, 16));
    DOUBLES_EQUAL(static_cast<double>(a.y()), static_cast<double>(b.y()),
                  dockcore_test::real_tol(static_cast<double>(a.y()), 1e-9, 16));
  }
}

// every config input is bounded (docs/reliability.md, "Security").
TEST(DockdConfig, InputCapsAreEnforcedWithPositions) {
  std::string allow = "[host]\nallowlist = [";
  for (std::size_t i = 0; i <= dockd::kMaxAllowlistEntries; ++i) allow += (i ? ", " : "") + std::string("\"10.0.0.1\"");
  allow += "]\n";
  STRCMP_CONTAINS("t.toml:2:13: host.allowlist has 65 entries (at most 64)", error_of(allow).c_str());
  std::string big = "# " + std::string(dockd::kMaxConfigBytes, 'x') + "\n";
  STRCMP_CONTAINS("t.toml:1:1: config larger than 1048576 bytes", error_of(big).c_str());
  // A device or FIFO as a profile file must not block or grow memory: refused before reading.
  STRCMP_CONTAINS("profile file /dev/zero: not a regular file",
                  error_of("[[docks]]\nid = 1\nprofile = \"/dev/zero\"\n").c_str());
  const std::string path = "/tmp/dockd_cfg_big_profile_" + std::to_string(::getpid()) + ".toml";
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    CHECK_TRUE(f != nullptr);
    const std::string pad(dockd::kMaxProfileFileBytes, '#');
    std::fwrite(pad.data(), 1, pad.size(), f);
    std::fputs("\npoints = [[0, 0], [0.1, 0]]\n", f);
    std::fclose(f);
  }
  STRCMP_CONTAINS("t.toml:3:11: profile file", error_of("[[docks]]\nid = 1\nprofile = \"" + path + "\"\n").c_str());
  STRCMP_CONTAINS("larger than 65536 bytes", error_of("[[docks]]\nid = 1\nprofile = \"" + path + "\"\n").c_str());
  std::remove(path.c_str());
  // Config file itself: a non-regular file is refused by load_config_file.
  bool threw = false;
  try {
    dockd::load_config_file("/dev/zero");
  } catch (const dockd::ConfigError& e) {
    threw = true;
    STRCMP_CONTAINS("/dev/zero: config file: not a regular file", e.what());
  }
  CHECK_TRUE(threw);
  // 32 docks (ids 0..31) is the most a valid database can hold: the 33rd id is out of range or a duplicate.
  std::string docks;
  for (int i = 0; i < 32; ++i) docks += "[[docks]]\nid = " + std::to_string(i) + "\n";
  CHECK_EQUAL(32u, dockd::parse_config_toml(docks, "t.toml").docks.size());
  STRCMP_CONTAINS("appears twice", error_of(docks + "[[docks]]\nid = 0\n").c_str());
}

// which keys a SIGHUP reload may change (docs/dockd.md, "Config reload").
TEST(DockdConfig, RestartOnlyChangesNameTheKeys) {
  const dockd::DockdConfig a = dockd::parse_config_toml("", "t.toml");
  // Runtime keys: no restart-only change.
  const dockd::DockdConfig b = dockd::parse_config_toml(
      "[watchdog]\nchassis_stale_ms = 300\n[controller.smooth]\nv_max_mps = 0.2\n[task]\nmax_retries = 5\n"
      "[host]\nallowlist = [\"10.1.0.0/16\"]\n[[docks]]\nid = 4\n[dock]\ndefault_id = 4\n[log]\nlevel = \"debug\"\n"
      "[lidar]\nmount_x_m = 0.1\n[can]\nstatus_rate_hz = 20\n[robot.footprint]\nself_sectors_deg = [[80, 100]]\n",
      "t.toml");
  CHECK_TRUE(dockd::restart_only_changes(a, b).empty());
  const dockd::DockdConfig c = dockd::parse_config_toml(
      "[can]\ninterface = \"vcan0\"\n[host]\nport = 7400\n[robot]\nwheel_radius_m = 0.08\n[lidar]\ndevice = \"/dev/ttyS1\"\n",
      "t.toml");
  const std::vector<std::string> ch = dockd::restart_only_changes(a, c);
  CHECK_EQUAL(4u, ch.size());
  STRCMP_EQUAL("lidar.device", ch[0].c_str());
  STRCMP_EQUAL("can.interface", ch[1].c_str());
  STRCMP_CONTAINS("wheel_radius_m", ch[2].c_str());
  STRCMP_EQUAL("host.port", ch[3].c_str());
}

TEST(DockdConfig, LidarUdpSourceIsAnIpv4AddressAndNeedsARestart) {
  const dockd::DockdConfig a = dockd::parse_config_toml("", "t.toml");
  CHECK_TRUE(a.lidar.udp_source_address.empty());  // any source unless configured
  const dockd::DockdConfig b = dockd::parse_config_toml(
      "[lidar]\nprotocol = \"lakibeam\"\ntransport = \"udp\"\nudp_source = \"192.168.198.2\"\n", "t.toml");
  STRCMP_EQUAL("192.168.198.2", b.lidar.udp_source_address.c_str());
  const std::vector<std::string> ch = dockd::restart_only_changes(a, b);
  CHECK(std::find(ch.begin(), ch.end(), "lidar.udp_source") != ch.end());
  STRCMP_CONTAINS("t.toml:2:14: lidar.udp_source = \"lidar.local\" is not an IPv4 address",
                  error_of("[lidar]\nudp_source = \"lidar.local\"\n").c_str());
}

// Cross-key errors point at the key at fault, not at 1:1 (found while writing fuzz_config: every message was
// positioned, but these all said 1:1).
TEST(DockdConfig, CrossKeyErrorsPointAtTheKey) {
  STRCMP_CONTAINS("t.toml:4:14: dock.default_id = 4 is not a configured dock id",
                  error_of("\n\n[dock]\ndefault_id = 4\n").c_str());
  STRCMP_CONTAINS("t.toml:3:20: lidar.reconnect_max_ms must be >=",
                  error_of("[lidar]\nreconnect_min_ms = 500\nreconnect_max_ms = 100\n").c_str());
  STRCMP_CONTAINS("t.toml:2:15: lidar.min_range_m must be <", error_of("[lidar]\nmin_range_m = 3\nmax_range_m = 2\n").c_str());
  STRCMP_CONTAINS("t.toml:5:8: camera.port must differ",
                  error_of("[host]\nport = 7400\n[camera]\nenabled = true\nport = 7400\n").c_str());
}

// robot.footprint.self_sectors_deg -> FootprintParams::self_sectors (only configured sectors are the robot).
TEST(DockdConfig, SelfSectorsAreParsedInRadians) {
  CHECK_EQUAL(0u, dockd::parse_config_toml("", "t.toml").footprint.self_sector_count);
  const dockd::DockdConfig c = dockd::parse_config_toml(
      "[robot.footprint]\nself_sectors_deg = [[-100, -80.5], [80, 100], [170, -170], [-180, -175]]\n", "t.toml");
  const dockcore::FootprintParams& f = c.footprint;
  CHECK_EQUAL(4u, f.self_sector_count);
  const double deg = 3.14159265358979323846 / 180.0;
  const double want[4][2] = {{-100, -80.5}, {80, 100}, {170, -170}, {180, -175}};  // -180 is stored as 180 (wrap)
  for (int i = 0; i < 4; ++i) {
    REAL_EQUAL(want[i][0] * deg, static_cast<double>(f.self_sectors[i].min_rad), 1e-12);
    REAL_EQUAL(want[i][1] * deg, static_cast<double>(f.self_sectors[i].max_rad), 1e-12);
  }
  // The parsed sectors act in the core: a return at the body edge on bearing 90 deg is the robot, at 0 deg it is not.
  dockcore::ObstacleChecker chk;
  chk.configure(f, nullptr);
  CHECK_TRUE(chk.is_self_point(dockcore::Vec2(0, f.half_width_m), dockcore::kPi / 2));
  CHECK_FALSE(chk.is_self_point(dockcore::Vec2(f.half_length_m, 0), 0));
  CHECK_TRUE(chk.is_self_point(dockcore::Vec2(-f.half_length_m, 0), dockcore::kPi));  // the wrapping sector
  // An empty array clears them (a reload can remove sectors).
  CHECK_EQUAL(0u, dockd::parse_config_toml("[robot.footprint]\nself_sectors_deg = []\n", "t.toml").footprint.self_sector_count);
}

TEST(DockdConfig, BadSelfSectorsAreRejectedWithPositions) {
  STRCMP_CONTAINS("t.toml:2:20: robot.footprint.self_sectors_deg has 5 sectors (at most 4)",
                  error_of("[robot.footprint]\nself_sectors_deg = [[1, 2], [3, 4], [5, 6], [7, 8], [9, 10]]\n").c_str());
  STRCMP_CONTAINS("t.toml:2:22: robot.footprint.self_sectors_deg must be a number, not a string",
                  error_of("[robot.footprint]\nself_sectors_deg = [[\"a\", 2]]\n").c_str());
  STRCMP_CONTAINS("t.toml:2:37: robot.footprint.self_sectors_deg = 181 is out of range [-180, 180]",
                  error_of("[robot.footprint]\nself_sectors_deg = [[80, 100], [10, 181]]\n").c_str());
  STRCMP_CONTAINS("t.toml:2:25: robot.footprint.self_sectors_deg is not finite",
                  error_of("[robot.footprint]\nself_sectors_deg = [[1, nan]]\n").c_str());
  STRCMP_CONTAINS("t.toml:2:21: robot.footprint.self_sectors_deg sector 1 must be a [from_deg, to_deg] pair, not an array of 3",
                  error_of("[robot.footprint]\nself_sectors_deg = [[1, 2, 3]]\n").c_str());
  STRCMP_CONTAINS("t.toml:2:21: robot.footprint.self_sectors_deg sector 1 must be a [from_deg, to_deg] pair, not an integer",
                  error_of("[robot.footprint]\nself_sectors_deg = [1, 2]\n").c_str());
  STRCMP_CONTAINS("t.toml:2:20: robot.footprint.self_sectors_deg must be an array of [from_deg, to_deg] pairs, not an integer",
                  error_of("[robot.footprint]\nself_sectors_deg = 90\n").c_str());
  // -180 and 180 are one bearing: refused rather than read as "all round", which would hide every obstacle inside
  // the body again.
  STRCMP_CONTAINS("t.toml:2:21: robot.footprint.self_sectors_deg sector 1 [-180, 180] has from and to on the same bearing",
                  error_of("[robot.footprint]\nself_sectors_deg = [[-180, 180]]\n").c_str());
}

namespace {
/// Writes `text` to a fresh file under /tmp and returns its path.
std::string write_temp(const std::string& stem, const std::string& text) {
  const std::string path = "/tmp/dockd_cfg_" + stem + "_" + std::to_string(::getpid()) + ".toml";
  std::FILE* f = std::fopen(path.c_str(), "wb");
  CHECK_TRUE(f != nullptr);
  std::fputs(text.c_str(), f);
  std::fclose(f);
  return path;
}
}  // namespace

TEST(DockdConfig, ProfileFilesAreReadByTheSharedParserWithTheirMounting) {
  const std::string path = write_temp("wall_dock", "points = [[-0.07, -0.22], [0, -0.15], [0, 0.15], [-0.07, 0.22]]\n"
                                                   "[mounting]\nkind = \"wall\"\nwall_gap_m = [0.01, 0.06]\n");
  const dockd::DockdConfig c = dockd::parse_config_toml("[dock]\ndefault_id = 2\n[[docks]]\nid = 2\nprofile = \"" + path + "\"\n", "t.toml");
  CHECK_EQUAL(1u, c.docks.size());
  const dockcore::DockProfile& p = c.docks[0].profile;
  CHECK_EQUAL(4u, p.vertex_count);
  // The default name is the file name without .toml, as in dock-sim.
  STRCMP_EQUAL(("dockd_cfg_wall_dock_" + std::to_string(::getpid())).substr(0, 23).c_str(), p.name);
  CHECK(p.mounting.kind == dockcore::DockMountKind::kWall);
  REAL_EQUAL(0.01, p.mounting.wall_gap_min_m, 1e-12);
  REAL_EQUAL(0.06, p.mounting.wall_gap_max_m, 1e-12);
  std::remove(path.c_str());
}

TEST(DockdConfig, BadProfileFileIsReportedAtTheProfileFilesLine) {
  // A flat plate (cannot fix y) on line 2, and a bad mounting kind on line 4 of another file.
  const std::string plate = write_temp("plate", "name = \"plate\"\npoints = [[0, -0.2], [0, 0.2]]\n");
  const std::string kind = write_temp("kind", "points = [[-0.07, -0.22], [0, -0.15], [0, 0.15], [-0.07, 0.22]]\n\n"
                                              "[mounting]\nkind = \"shelf\"\n");
  const std::string cfg = "[[docks]]\nid = 1\nprofile = \"";
  STRCMP_CONTAINS((plate + ":2:10: points: the outline cannot fix the dock's y").c_str(),
                  error_of(cfg + plate + "\"\n").c_str());
  // ... naming the config key that refers to it.
  STRCMP_CONTAINS("(dock profile named at t.toml:3:11)", error_of(cfg + plate + "\"\n").c_str());
  STRCMP_CONTAINS((kind + ":4:8: mounting.kind = \"shelf\" is not one of").c_str(), error_of(cfg + kind + "\"\n").c_str());
  try {
    dockd::parse_config_toml(cfg + kind + "\"\n", "t.toml");
    FAIL("bad profile accepted");
  } catch (const dockd::ConfigError& e) {
    CHECK_EQUAL(4, e.line());
    CHECK_EQUAL(8, e.column());
  }
  std::remove(plate.c_str());
  std::remove(kind.c_str());
}

TEST(DockdConfig, DockEntriesTakeAMountingThatReplacesTheProfiles) {
  const dockd::DockdConfig c = dockd::parse_config_toml(
      "[dock]\ndefault_id = 1\n[[docks]]\nid = 1\nprofile = \"plate-v\"\nmounting = { kind = \"wall\", wall_gap_m = [0.02, 0.05] }\n"
      "[[docks]]\nid = 2\nprofile = \"v-marker\"\n[docks.mounting]\nkind = \"free_standing\"\n"
      "[[docks]]\nid = 3\n",
      "t.toml");
  CHECK_EQUAL(3u, c.docks.size());
  CHECK(c.docks[0].profile.mounting.kind == dockcore::DockMountKind::kWall);
  REAL_EQUAL(0.02, c.docks[0].profile.mounting.wall_gap_min_m, 1e-12);
  REAL_EQUAL(0.05, c.docks[0].profile.mounting.wall_gap_max_m, 1e-12);
  CHECK(c.docks[1].profile.mounting.kind == dockcore::DockMountKind::kFreeStanding);
  CHECK(c.docks[2].profile.mounting.kind == dockcore::DockMountKind::kUnknown);
  // The [dock] shorthand too.
  const dockd::DockdConfig s = dockd::parse_config_toml("[dock]\ndefault_id = 4\nid = 4\n[dock.mounting]\nkind = \"wall\"\n", "t.toml");
  CHECK(s.docks[0].profile.mounting.kind == dockcore::DockMountKind::kWall);
  REAL_EQUAL(0.10, s.docks[0].profile.mounting.wall_gap_max_m, 1e-12);
  // A dock's mounting replaces the one in its profile file.
  const std::string path = write_temp("free_dock", "points = [[-0.07, -0.22], [0, -0.15], [0, 0.15], [-0.07, 0.22]]\n"
                                                   "[mounting]\nkind = \"free_standing\"\n");
  const dockd::DockdConfig f = dockd::parse_config_toml(
      "[dock]\ndefault_id = 1\n[[docks]]\nid = 1\nprofile = \"" + path + "\"\n[docks.mounting]\nkind = \"wall\"\nwall_gap_m = [0, 0.2]\n",
      "t.toml");
  CHECK(f.docks[0].profile.mounting.kind == dockcore::DockMountKind::kWall);
  REAL_EQUAL(0.2, f.docks[0].profile.mounting.wall_gap_max_m, 1e-12);
  std::remove(path.c_str());
}

TEST(DockdConfig, BadDockMountingIsPositioned) {
  STRCMP_CONTAINS("t.toml:5:18: docks.mounting.wall_gap_m = 0.7 is out of range [0, 0.5]",
                  error_of("[[docks]]\nid = 1\n[docks.mounting]\nkind = \"wall\"\nwall_gap_m = [0, 0.7]\n").c_str());
  STRCMP_CONTAINS("t.toml:4:14: docks.mounting.wall_gap_m is only meaningful with docks.mounting.kind = \"wall\"",
                  error_of("[[docks]]\nid = 1\n[docks.mounting]\nwall_gap_m = [0, 0.1]\n").c_str());
  STRCMP_CONTAINS("t.toml:4:8: dock.mounting.kind = \"floor\" is not one of unknown, wall, free_standing",
                  error_of("[dock]\nid = 1\n[dock.mounting]\nkind = \"floor\"\n").c_str());
  STRCMP_CONTAINS("t.toml:4:1: unknown key 'docks.mounting.gap_m'",
                  error_of("[[docks]]\nid = 1\n[docks.mounting]\ngap_m = 0.1\n").c_str());
}

TEST(DockdConfig, EstimatorTuningKeys) {
  const dockd::DockdConfig c = dockd::parse_config_toml(
      "[estimator]\ninlier_gate_m = 0.02\nmax_view_angle_deg = 60\nselect = \"hint\"\nmin_inliers = 14\n"
      "[estimator.segments]\nmin_points = 4\n",
      "t.toml");
  REAL_EQUAL(0.02, c.estimator.inlier_gate_m, 1e-12);
  REAL_EQUAL(60 * 3.14159265358979323846 / 180, c.estimator.max_view_angle_rad, 1e-9);
  CHECK(c.estimator.select == dockcore::DockSelect::kHint);
  CHECK_EQUAL(14u, c.estimator.min_inliers);
  CHECK_EQUAL(4u, c.estimator.segments.min_points);
  // Untouched keys keep the estimator's defaults.
  const dockcore::EstimatorParams d{};
  REAL_EQUAL(d.min_evidence_nats, c.estimator.min_evidence_nats, 0);
  REAL_EQUAL(d.wall_tolerance_m, c.estimator.wall_tolerance_m, 0);
  // Out of range, wrong type, unknown: at the value / key.
  STRCMP_CONTAINS("t.toml:2:17: estimator.inlier_gate_m = 0.6 is out of range [0.001, 0.5]",
                  error_of("[estimator]\ninlier_gate_m = 0.6\n").c_str());
  STRCMP_CONTAINS("t.toml:2:15: estimator.min_inliers must be an integer, not a float",
                  error_of("[estimator]\nmin_inliers = 2.5\n").c_str());
  STRCMP_CONTAINS("t.toml:2:1: unknown key 'estimator.require_wall_behind'",
                  error_of("[estimator]\nrequire_wall_behind = false\n").c_str());
  STRCMP_CONTAINS("t.toml:3:14: estimator.segments.min_points = 1 is out of range [2, 100]",
                  error_of("[estimator.segments]\n\nmin_points = 1\n").c_str());
}

TEST(DockdConfig, EachDockPicksItsDetector) {
  const dockd::DockdConfig c = dockd::parse_config_toml(
      "[dock]\ndefault_id = 1\n[[docks]]\nid = 1\nprofile = \"breakpoint\"\ndetector = \"breakpoint\"\n"
      "[[docks]]\nid = 2\nprofile = \"breakpoint\"\n[[docks]]\nid = 3\ndetector = \"estimator\"\n",
      "t.toml");
  CHECK(c.find_dock(1)->detector == dockcore::DockDetector::kBreakpoint);
  CHECK(c.find_dock(2)->detector == dockcore::DockDetector::kEstimator);  // the default
  CHECK(c.find_dock(3)->detector == dockcore::DockDetector::kEstimator);
  // The [dock] shorthand takes it too.
  const dockd::DockdConfig s = dockd::parse_config_toml(
      "[dock]\nid = 4\ndefault_id = 4\nprofile = \"breakpoint\"\ndetector = \"breakpoint\"\n", "t.toml");
  CHECK(s.find_dock(4)->detector == dockcore::DockDetector::kBreakpoint);
}

TEST(DockdConfig, BadDetectorIsRefusedWithItsPosition) {
  STRCMP_CONTAINS("t.toml:3:12: docks.detector = \"vmarker\" is not one of estimator, breakpoint",
                  error_of("[[docks]]\nid = 1\ndetector = \"vmarker\"\n").c_str());
  STRCMP_CONTAINS("t.toml:3:12: docks.detector must be a string",
                  error_of("[[docks]]\nid = 1\ndetector = 1\n").c_str());
  // A detector that cannot find the dock: at the detector key, naming dock, detector and profile.
  STRCMP_CONTAINS(
      "t.toml:4:12: dock 1: detector = \"breakpoint\" with profile \"plate-v\": detector breakpoint "
      "finds only the breakpoint dock",
      error_of("[[docks]]\nid = 1\nprofile = \"plate-v\"\ndetector = \"breakpoint\"\n").c_str());
  STRCMP_CONTAINS(
      "t.toml:3:12: dock 1: detector = \"breakpoint\" with profile \"breakpoint\": detector breakpoint "
      "needs the dock against a wall",
      error_of("[[docks]]\nid = 1\ndetector = \"breakpoint\"\nprofile = \"breakpoint\"\n"
               "[docks.mounting]\nkind = \"free_standing\"\n")
          .c_str());
}
