// dockd's state file: atomic save with backup, checksum detection of corruption and truncation, recovery from the
// last good copy.
#include <unistd.h>

#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "../support/fake_can_bus.hpp"
#include "learned_file.hpp"
#include "session_record.hpp"
#include "state_file.hpp"

#include "real_tolerance.hpp"

#include "CppUTest/TestHarness.h"

namespace {
std::string read_all(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}
void write_all(const std::string& p, const std::string& t) { std::ofstream(p, std::ios::binary) << t; }
}  // namespace

TEST_GROUP(DockdState) {
  std::string path;
  void setup() override {
    path = "/tmp/dockd_state_test_" + std::to_string(::getpid());
    teardown();
  }
  void teardown() override {
    for (const char* s : {"", ".bak", ".tmp", ".corrupt"}) std::remove((path + s).c_str());
  }
  dockd::StateData one(std::uint16_t id, double x) {
    dockd::StateData d;
    dockd::TaughtTarget t;
    t.dock_id = id;
    t.target = dockcore::Pose2{static_cast<dockcore::Real>(x), static_cast<dockcore::Real>(0.001), static_cast<dockcore::Real>(3.1)};
    t.scans = 20;
    d.put(t);
    return d;
  }
};

TEST(DockdState, RoundTripsAndKeepsTheLastGoodCopy) {
  dockd::StateData s, out;
  std::string msg, err;
  CHECK_EQUAL(static_cast<int>(dockd::StateLoadStatus::kMissing), static_cast<int>(dockd::load_state(path, out, msg)));
  CHECK_TRUE(dockd::save_state(path, one(1, 0.225), err));
  CHECK_TRUE(dockd::save_state(path, one(1, 0.230), err));
  CHECK_EQUAL(static_cast<int>(dockd::StateLoadStatus::kOk), static_cast<int>(dockd::load_state(path, out, msg)));
  REAL_EQUAL(0.230, static_cast<double>(out.find(1)->target.x_m), 1e-9);
  // Flip one digit: the checksum catches it, the file is moved aside and the backup (the previous save) is used.
  std::string text = read_all(path);
  const std::size_t pos = text.find("0.23");
  text[pos + 3] = '9';
  write_all(path, text);
  CHECK_EQUAL(static_cast<int>(dockd::StateLoadStatus::kRecoveredBackup), static_cast<int>(dockd::load_state(path, out, msg)));
  STRCMP_CONTAINS("checksum mismatch", msg.c_str());
  REAL_EQUAL(0.225, static_cast<double>(out.find(1)->target.x_m), 1e-9);
  CHECK_FALSE(read_all(path + ".corrupt").empty());
}

// A taught code goes on its own line after its target; a file without code lines (an older one) loads as before.
TEST(DockdState, TheTaughtCodeRoundTripsAndOlderFilesLoad) {
  dockd::StateData s = one(3, 0.23);
  dockd::TaughtTarget t = *s.find(3);
  t.stripe_count = 2;
  t.stripes[0] = dockcore::ReflectorStripe{1, static_cast<dockcore::Real>(0.0), static_cast<dockcore::Real>(0.1004)};
  t.stripes[1] = dockcore::ReflectorStripe{1, static_cast<dockcore::Real>(0.2011), static_cast<dockcore::Real>(0.3)};
  t.code_scans = 18;
  t.code_spread_m = 0.0021;
  s.put(t);
  s.put(*one(5, 0.22).find(5));  // no code
  std::string err, msg;
  CHECK_TRUE(dockd::save_state(path, s, err));
  const std::string text = read_all(path);
  STRCMP_CONTAINS("\ncode 3 18 0.002100 2 1 0.000000 0.100400 1 0.201100 0.300000\n", text.c_str());
  dockd::StateData out;
  std::vector<std::string> warnings;
  CHECK_EQUAL(static_cast<int>(dockd::StateLoadStatus::kOk),
              static_cast<int>(dockd::load_state(path, out, msg, &warnings)));
  CHECK_TRUE(warnings.empty());
  const dockd::TaughtTarget* got = out.find(3);
  CHECK_EQUAL(2, got->stripe_count);
  CHECK_EQUAL(1, got->stripes[1].segment);
  REAL_EQUAL(0.2011, static_cast<double>(got->stripes[1].from_m), 1e-9);
  CHECK_EQUAL(18, got->code_scans);
  CHECK_EQUAL(3u, got->code_line);
  CHECK_EQUAL(0, out.find(5)->stripe_count);
  // Applied to a profile without stripes of its own, all or nothing.
  dockcore::DockProfile p;
  CHECK(dockcore::builtin_profile("plate-v", p) == dockcore::ProfileError::kOk);
  CHECK_TRUE(dockd::with_taught_code(p, *got));
  CHECK_EQUAL(2u, p.reflector_count);
  CHECK_FALSE(dockd::with_taught_code(p, *got));  // it has its own now
  // An older file: target lines only.
  std::string old_body = "dockd-state 1\ntarget 3 0.230000000 0.001000000 3.100000000 20 0.000000 0\n";
  char crc[32];
  std::snprintf(crc, sizeof crc, "crc32 %08x\n", dockd::crc32_ieee(old_body.data(), old_body.size()));
  write_all(path, old_body + crc);
  CHECK_EQUAL(static_cast<int>(dockd::StateLoadStatus::kOk), static_cast<int>(dockd::load_state(path, out, msg)));
  CHECK_EQUAL(0, out.find(3)->stripe_count);
}

// A bad code line (with a good checksum: written by hand or by another program) is reported with the file and line
// and left out; the targets and the other codes load as they are, and the file is not moved aside.
TEST(DockdState, ABadCodeLineIsReportedAndChangesNothingElse) {
  const char* bad_lines[] = {
      "code 3 18 0.0021 2 1 0.0 0.1",             // a stripe missing
      "code 3 18 0.0021 1 1 0.20 0.205",          // shorter than 1 cm
      "code 3 18 0.0021 2 1 0.0 0.1 1 0.05 0.2",  // overlapping
      "code 3 18 0.0021 1 1 nan 0.1",             // not a number
      "code 9 18 0.0021 1 1 0.0 0.1",             // no target of dock 9
      "code 3 18 0.0021 1 1 0.0 0.1 junk",        // trailing text
  };
  for (const char* bad : bad_lines) {
    const std::string body =
        std::string("dockd-state 1\n") + "target 3 0.230000000 0.001000000 3.100000000 20 0.000000 0\n" + bad + "\n" +
        "target 5 0.220000000 0.000000000 3.100000000 20 0.000000 0\n" + "code 5 20 0.001 1 1 0.1 0.2\n";
    char crc[32];
    std::snprintf(crc, sizeof crc, "crc32 %08x\n", dockd::crc32_ieee(body.data(), body.size()));
    write_all(path, body + crc);
    dockd::StateData out;
    std::vector<std::string> warnings;
    std::string msg;
    CHECK_EQUAL(static_cast<int>(dockd::StateLoadStatus::kOk),
                static_cast<int>(dockd::load_state(path, out, msg, &warnings)));
    CHECK_EQUAL_TEXT(1u, warnings.size(), bad);
    STRCMP_CONTAINS((path + ":3: bad code line").c_str(), warnings[0].c_str());
    CHECK(out.find(3) != nullptr);
    CHECK_EQUAL(0, out.find(3)->stripe_count);
    CHECK_EQUAL(1, out.find(5)->stripe_count);
    CHECK_EQUAL(5u, out.find(5)->code_line);
    CHECK_TRUE(read_all(path + ".corrupt").empty());
  }
}

TEST(DockdState, TruncatedFileWithoutBackupIsReported) {
  std::string err, msg;
  CHECK_TRUE(dockd::save_state(path, one(2, 0.2), err));
  const std::string text = read_all(path);
  write_all(path, text.substr(0, text.size() / 2));
  dockd::StateData out = one(9, 1.0);
  CHECK_EQUAL(static_cast<int>(dockd::StateLoadStatus::kCorruptNoBackup), static_cast<int>(dockd::load_state(path, out, msg)));
  CHECK_TRUE(out.targets.empty());
  STRCMP_CONTAINS("corrupt", msg.c_str());
}

TEST(DockdState, SaveNeverLeavesAPartialFile) {
  std::string err;
  dockd::StateData many;
  for (std::uint16_t i = 0; i < 32; ++i) many.put(one(i, 0.2 + i * 0.001).targets[0]);
  CHECK_TRUE(dockd::save_state(path, many, err));
  CHECK_TRUE(read_all(path + ".tmp").empty());
  dockd::StateData out;
  std::string perr;
  CHECK_TRUE(dockd::parse_state(read_all(path), out, perr));
  CHECK_EQUAL(32u, out.targets.size());
  CHECK_FALSE(dockd::save_state("/nonexistent-dir/state", many, err));
  STRCMP_CONTAINS("cannot create", err.c_str());
}

TEST(DockdState, Crc32MatchesTheStandardCheckValue) {
  CHECK_EQUAL(0xCBF43926u, dockd::crc32_ieee("123456789", 9));
}

// an oversized state file is treated as corrupt without being read whole; the backup is used.
TEST(DockdState, OversizedFileIsCorruptAndTheBackupIsUsed) {
  dockd::StateData s;
  dockd::TaughtTarget t;
  t.dock_id = 2;
  t.scans = 5;
  s.put(t);
  std::string err;
  CHECK_TRUE(dockd::save_state(path, s, err));
  CHECK_TRUE(dockd::save_state(path, s, err));  // the first copy becomes the .bak
  {
    std::FILE* f = std::fopen(path.c_str(), "ab");
    const std::string junk(dockd::kMaxStateFileBytes, 'x');
    std::fwrite(junk.data(), 1, junk.size(), f);
    std::fclose(f);
  }
  dockd::StateData out;
  std::string msg;
  CHECK_EQUAL(static_cast<int>(dockd::StateLoadStatus::kRecoveredBackup), static_cast<int>(dockd::load_state(path, out, msg)));
  STRCMP_CONTAINS("larger than 1048576 bytes", msg.c_str());
  CHECK_TRUE(out.find(2) != nullptr);
}

// Received frames reach the record once the bus is drained (or before a send), sent frames at once, all in order.
TEST(DockdState, RecordedCanFramesAreWrittenPerDrainAndInOrder) {
  const std::string dir = path + "_can";
  ::mkdir(dir.c_str(), 0700);
  {
    dockd::RotatingLog log;
    std::string err;
    CHECK_TRUE_TEXT(log.open(dir, "can.log", 1 << 20, 2, err), err.c_str());
    dockcore::testing::FakeCanBus inner;
    dockd::RecordingCanBus bus(inner, log, "vcan0");
    for (int i = 0; i < 300; ++i) {  // more than the gathering buffer holds
      dockcore::CanFrame f{};
      f.id = 0x100u + static_cast<std::uint32_t>(i);
      f.dlc = 1;
      f.data[0] = static_cast<std::uint8_t>(i);
      inner.inject(f);
    }
    dockcore::CanFrame f{};
    std::uint64_t t = 0;
    for (int i = 0; i < 250; ++i) CHECK_TRUE(bus.receive(f, t));
    const std::string mid = read_all(dir + "/can.log");  // the full buffer was written, the rest waits
    CHECK(std::count(mid.begin(), mid.end(), '\n') > 100);
    CHECK(std::count(mid.begin(), mid.end(), '\n') < 250);
    dockcore::CanFrame out{};
    out.id = 0x7FF;
    out.dlc = 0;
    CHECK_TRUE(bus.send(out));  // writes the received frames before it, then itself
    const std::string after_send = read_all(dir + "/can.log");
    CHECK_EQUAL(251, std::count(after_send.begin(), after_send.end(), '\n'));
    STRCMP_CONTAINS(" vcan0 1F9#F9\n", after_send.c_str());  // frame 249
    CHECK(after_send.size() > 12 && after_send.compare(after_send.size() - 12, 12, " vcan0 7FF#\n") == 0);
    while (bus.receive(f, t)) {
    }
    const std::string drained = read_all(dir + "/can.log");  // the drain's end wrote the other 50
    CHECK_EQUAL(301, std::count(drained.begin(), drained.end(), '\n'));
    CHECK(drained.size() > 14 && drained.compare(drained.size() - 14, 14, " vcan0 22B#2B\n") == 0);
  }
  std::remove((dir + "/can.log").c_str());
  ::rmdir(dir.c_str());
}

// The learned file: what the core learned about the robot, kept across restarts with the configuration it belongs to.
namespace {

dockd::LearnedState sample_learned() {
  dockd::LearnedState l;
  l.lidar_mount = dockcore::Pose2{static_cast<dockcore::Real>(0.12), static_cast<dockcore::Real>(-0.03),
                                  static_cast<dockcore::Real>(0.087)};
  l.drive.kind = dockcore::DriveKind::kDifferential;
  l.drive.wheel_radius_m = static_cast<dockcore::Real>(0.076);
  l.drive.wheel_base_m = static_cast<dockcore::Real>(0.36);
  l.saved_unix_s = 1796000000;
  l.learned.deadband.radps[0][0] = static_cast<dockcore::Real>(1.1);
  l.learned.deadband.radps[1][0] = static_cast<dockcore::Real>(0.65);
  l.learned.deadband.radps[1][1] = static_cast<dockcore::Real>(0.7);
  l.learned.deadband.raises = 4;
  dockcore::TaskLearned& t = l.learned.task;
  t.remembered_aim_m[0] = static_cast<dockcore::Real>(-0.006);
  t.remembered_aim_m[31] = static_cast<dockcore::Real>(0.012);
  t.mount_shift_m = dockcore::Vec2(static_cast<dockcore::Real>(-0.0011), static_cast<dockcore::Real>(0.0087));
  t.calibrations = 1;
  t.last_calibration.status = dockcore::MountCalibrationStatus::kOk;
  t.last_calibration.lateral_error_m = static_cast<dockcore::Real>(0.0088);
  t.last_calibration.rms_m = static_cast<dockcore::Real>(0.0014);
  t.last_calibration.sweep_rad = static_cast<dockcore::Real>(0.96);
  t.last_calibration.detections = 36;
  t.last_calibration.mount = dockcore::Pose2{static_cast<dockcore::Real>(0.119), static_cast<dockcore::Real>(-0.021),
                                             static_cast<dockcore::Real>(0.087)};
  return l;
}

std::string formatted(const dockd::LearnedState& l) {
  char buf[dockd::kMaxLearnedFileBytes];
  const std::size_t n = dockd::format_learned(l, buf, sizeof buf);
  return std::string(buf, n);
}

/// `text` with its checksum line made right again (a well-formed file saying something wrong).
std::string resealed(const std::string& text) {
  const std::string body = text.substr(0, text.rfind("crc32 "));
  char crc[32];
  std::snprintf(crc, sizeof crc, "crc32 %08x\n", dockd::crc32_ieee(body.data(), body.size()));
  return body + crc;
}

}  // namespace

TEST(DockdState, TheLearnedStateRoundTripsAndBelongsToItsConfiguration) {
  const dockd::LearnedState l = sample_learned();
  const dockd::LearnedPaths paths = dockd::LearnedPaths::beside(path);
  STRCMP_EQUAL((path + ".learned").c_str(), paths.file.c_str());
  char buf[dockd::kMaxLearnedFileBytes];
  char err[128] = "";
  CHECK_TRUE_TEXT(dockd::save_learned(paths, l, buf, sizeof buf, err, sizeof err), err);
  dockd::LearnedState back;
  std::string msg;
  CHECK_EQUAL(static_cast<int>(dockd::LearnedLoadStatus::kOk),
              static_cast<int>(dockd::load_learned(paths.file, back, msg)));
  CHECK_TRUE(dockd::same_learned(l.learned, back.learned));
  CHECK_TRUE(back.learned_on(l.lidar_mount, l.drive));
  CHECK_EQUAL(l.saved_unix_s, back.saved_unix_s);
  // Another mount or another drive is another robot.
  dockcore::Pose2 moved = l.lidar_mount;
  moved.yaw_rad += static_cast<dockcore::Real>(0.01);
  CHECK_FALSE(back.learned_on(moved, l.drive));
  dockcore::DriveGeometry mecanum = l.drive;
  mecanum.kind = dockcore::DriveKind::kMecanum;
  CHECK_FALSE(back.learned_on(l.lidar_mount, mecanum));
  // Any learned value that changes is a change.
  dockd::LearnedState other = l;
  other.learned.task.remembered_aim_m[5] = static_cast<dockcore::Real>(0.001);
  CHECK_FALSE(dockd::same_learned(l.learned, other.learned));
  other = l;
  other.learned.deadband.raises = 5;
  CHECK_FALSE(dockd::same_learned(l.learned, other.learned));
  // A buffer too small formats nothing.
  CHECK_EQUAL(0u, dockd::format_learned(l, buf, 64));
  std::remove(paths.file.c_str());
}

TEST(DockdState, ABadLearnedFileIsReportedMovedAsideAndLearnedAgain) {
  const std::string good = formatted(sample_learned());
  dockd::LearnedState out;
  std::string why;
  CHECK_TRUE(dockd::parse_learned(good, out, why));
  // Each of these is refused whole, with the line that is wrong. (The first floor's digits depend on Real.)
  const std::size_t first_floor = good.find("deadband 4 ") + 11;
  const struct {
    std::string text;
    const char* reason;
  } bad[] = {
      {good.substr(0, good.size() - 3), "checksum"},
      {std::string(good).replace(good.find("deadband 4"), 10, "deadband 5"), "checksum mismatch"},
      {resealed(std::string(good).replace(good.find("aim 31"), 6, "aim 32")), "line 6"},
      {resealed(std::string(good).replace(first_floor, good.find(' ', first_floor) - first_floor, "nan")), "line 3"},
      {resealed(std::string(good).replace(good.find("mount 1 1"), 9, "mount 1 9")), "line 4"},
      {resealed(std::string(good).replace(good.find("\nlearned ") + 1, 8, "learnt ")), "line 2"},
      {resealed("dockd-learned 1\ndeadband 0 0 0 0 0 0 0 0 0\ncrc32 00000000\n"), "no 'learned' line before it"},
      {resealed("dockd-learned 2\ncrc32 00000000\n"), "unknown header"},
  };
  for (const auto& b : bad) {
    why.clear();
    CHECK_FALSE_TEXT(dockd::parse_learned(b.text, out, why), b.text.c_str());
    STRCMP_CONTAINS(b.reason, why.c_str());
  }
  // Loaded from disk: reported, moved to .corrupt, and the next start finds none.
  const std::string file = path + ".learned";
  write_all(file, bad[3].text);
  std::string msg;
  CHECK_EQUAL(static_cast<int>(dockd::LearnedLoadStatus::kCorrupt),
              static_cast<int>(dockd::load_learned(file, out, msg)));
  STRCMP_CONTAINS("line 3", msg.c_str());
  STRCMP_CONTAINS(".corrupt", msg.c_str());
  CHECK_EQUAL(bad[3].text, read_all(file + ".corrupt"));
  CHECK_EQUAL(static_cast<int>(dockd::LearnedLoadStatus::kMissing),
              static_cast<int>(dockd::load_learned(file, out, msg)));
  std::remove((file + ".corrupt").c_str());
  // A directory that cannot be written: the save fails with the reason, and no file appears.
  dockd::LearnedPaths nowhere = dockd::LearnedPaths::beside("/nonexistent-dir/state");
  char buf[dockd::kMaxLearnedFileBytes];
  char err[128] = "";
  CHECK_FALSE(dockd::save_learned(nowhere, sample_learned(), buf, sizeof buf, err, sizeof err));
  STRCMP_CONTAINS("cannot create /nonexistent-dir/state.learned.tmp", err);
}
