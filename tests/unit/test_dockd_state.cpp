// dockd's state file: atomic save with backup, checksum detection of corruption and truncation, recovery from the
// last good copy.
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

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
