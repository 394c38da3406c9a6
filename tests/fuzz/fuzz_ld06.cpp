// fuzz-links: core
// LD06: arbitrary bytes, fed one at a time with rising stamps (first byte selects the grid so configure() paths are
// fuzzed too). Invariants: counters never decrease, byte accounting is exact (bytes = accepted + dropped +
// buffered), the buffer stays within one packet, published scans have the configured count and finite ranges >= 0.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "dockcore/protocols/lidar/lidar_ld06.hpp"

using namespace dockcore;

namespace {
// A fresh parser per input (parsers are not copyable: their output points into its own buffers).
std::optional<Ld06Parser> g_fresh;
LaserScan g_scan;
void check(bool ok) {
  if (!ok) __builtin_trap();
}
bool monotonic(const LidarParserCounters& a, const LidarParserCounters& b) {
  return b.scans >= a.scans && b.crc_errors >= a.crc_errors && b.resyncs >= a.resyncs &&
         b.dropped_bytes >= a.dropped_bytes && b.bytes >= a.bytes && b.packets >= a.packets &&
         b.bad_span >= a.bad_span && b.samples >= a.samples;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  Ld06Parser& g_parser = g_fresh.emplace();
  Ld06Config cfg;
  cfg.bins_per_turn = 1u + static_cast<std::uint32_t>(data[0]) * 16u;  // 1 .. 4081
  check(g_parser.configure(cfg));
  LidarParserCounters prev = g_parser.counters();
  for (std::size_t i = 1; i < size; ++i) {
    g_parser.feed(data[i], 1000u + i * 43u);
    const auto& c = g_parser.counters();
    check(monotonic(prev, c));
    check(g_parser.buffered() < kLd06PacketBytes);
    check(c.bytes == c.bytes_accepted + c.dropped_bytes + g_parser.buffered());
    prev = c;
    if (g_parser.take_scan(g_scan)) {
      check(g_scan.count == cfg.bins_per_turn && g_scan.count <= LaserScan::kCapacity);
      for (std::size_t k = 0; k < g_scan.count; ++k)
        check(std::isfinite(g_scan.ranges_m[k]) && g_scan.ranges_m[k] >= 0 && std::isfinite(g_scan.intensities[k]));
    }
  }
  g_parser.reset();
  check(g_parser.counters().bytes == g_parser.counters().bytes_accepted + g_parser.counters().dropped_bytes);
  return 0;
}
