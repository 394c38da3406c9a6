#pragma once
// Helpers shared by the lidar parser suites (test_lidar_ld06/rplidar/lakibeam.cpp): the recorded captures of
// tests/data/lidar/, the real captures of the realdata folder, the synthetic turn they hold, byte-at-a-time replay and
// the byte accounting every parser keeps.
#include <sys/stat.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/laser_scan.hpp"

#include <CppUTest/TestHarness.h>

namespace lidar_test {

/// The repository root: DOCKCORE_SOURCE_DIR when the build defines it (__FILE__ can be relative to the build
/// directory under ccache's base_dir), else derived from this file's path.
inline std::string repo_root() {
#ifdef DOCKCORE_SOURCE_DIR
  return DOCKCORE_SOURCE_DIR;
#else
  const std::string f = __FILE__;  // .../tests/unit/lidar_capture.hpp
  return f.substr(0, f.rfind('/')) + "/../..";
#endif
}

/// All bytes of the file at `path`; empty when it cannot be read.
inline std::vector<std::uint8_t> read_file_bytes(const std::string& path) {
  std::vector<std::uint8_t> out;
  FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return out;
  std::uint8_t buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) out.insert(out.end(), buf, buf + n);
  std::fclose(f);
  return out;
}

/// The bytes of tests/data/lidar/<name>; empty when the file is missing (the size check of the test then fails).
inline std::vector<std::uint8_t> read_capture(const char* name) {
  return read_file_bytes(repo_root() + "/tests/data/lidar/" + name);
}

/// The real-data folder: $DOCKCORE_REALDATA if set, else <repo root>/../shared/realdata. Prints where it looked and,
/// when the folder is absent, one "skipped" line for `what`; returns "" then (the caller returns: a skip, not a
/// failure). The data are evaluation data read in place, never copied into the repository.
inline std::string realdata_dir(const char* what) {
  const char* env = std::getenv("DOCKCORE_REALDATA");
  const std::string dir = (env != nullptr && *env != '\0') ? std::string(env) : repo_root() + "/../shared/realdata";
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    std::printf("\n%s: skipped, no real data at %s (set DOCKCORE_REALDATA)\n", what, dir.c_str());
    return "";
  }
  std::printf("\n%s: real data from %s\n", what, dir.c_str());
  return dir;
}

/// Range (mm) of sample j of the synthetic turn of tests/data/lidar/make_captures.py; 0 = no return.
inline int capture_dist_mm(int j) { return j % 37 == 0 ? 0 : 1000 + 10 * (j % 50); }

/// Feeds `bytes` one at a time (stamp 0) and collects every scan the parser publishes.
template <typename Parser>
std::vector<dockcore::LaserScan> replay_bytes(Parser& p, const std::vector<std::uint8_t>& bytes) {
  std::vector<dockcore::LaserScan> scans;
  for (std::uint8_t b : bytes) {
    if (p.feed(b, 0)) {
      scans.emplace_back();
      CHECK(p.take_scan(scans.back()));
    }
  }
  return scans;
}

/// Feeds `bytes` one at a time, byte i stamped stamps[i], and returns the stamps of the scans the parser publishes
/// (the scans themselves are not kept: a long capture holds thousands). Precondition: stamps.size() == bytes.size().
template <typename Parser>
std::vector<std::uint64_t> replay_scan_stamps(Parser& p, const std::vector<std::uint8_t>& bytes,
                                              const std::vector<std::uint64_t>& stamps) {
  std::vector<std::uint64_t> out;
  auto scan = std::make_unique<dockcore::LaserScan>();
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (p.feed(bytes[i], stamps[i])) {
      CHECK(p.take_scan(*scan));
      out.push_back(scan->stamp_us);
    }
  }
  return out;
}

/// Every byte fed is accepted, dropped (and counted) or still buffered.
template <typename Parser>
void check_accounting(const Parser& p) {
  const auto& c = p.counters();
  CHECK_EQUAL(c.bytes, c.bytes_accepted + c.dropped_bytes + p.buffered());
}

}  // namespace lidar_test
