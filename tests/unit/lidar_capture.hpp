#pragma once
// Helpers shared by the lidar parser suites (test_lidar_ld06/rplidar/lakibeam.cpp): the recorded captures of
// tests/data/lidar/, the synthetic turn they hold, byte-at-a-time replay and the byte accounting every parser keeps.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "dockcore/laser_scan.hpp"

#include <CppUTest/TestHarness.h>

namespace lidar_test {

/// The bytes of tests/data/lidar/<name>; empty when the file is missing (the size check of the test then fails).
inline std::vector<std::uint8_t> read_capture(const char* name) {
  std::string path = __FILE__;
  path = path.substr(0, path.rfind('/')) + "/../data/lidar/" + name;
  std::vector<std::uint8_t> out;
  FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return out;
  std::uint8_t buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) out.insert(out.end(), buf, buf + n);
  std::fclose(f);
  return out;
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

/// Every byte fed is accepted, dropped (and counted) or still buffered.
template <typename Parser>
void check_accounting(const Parser& p) {
  const auto& c = p.counters();
  CHECK_EQUAL(c.bytes, c.bytes_accepted + c.dropped_bytes + p.buffered());
}

}  // namespace lidar_test
