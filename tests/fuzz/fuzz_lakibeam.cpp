// fuzz-links: core
// Lakibeam: the input is split into datagrams by a 2-byte length prefix each (so sizes other than 1206 are
// fuzzed), fed with rising stamps. Invariants: counters never decrease, bytes = accepted + dropped, every datagram
// is either a packet or a bad packet, published scans have the configured count and finite ranges >= 0.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "dockcore/protocols/lidar/lidar_lakibeam.hpp"

using namespace dockcore;

namespace {
// A fresh parser per input (parsers are not copyable: their output points into its own buffers).
std::optional<LakibeamParser> g_fresh;
LaserScan g_scan;
std::uint8_t g_dgram[1400];
void check(bool ok) {
  if (!ok) __builtin_trap();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  LakibeamParser& g_parser = g_fresh.emplace();
  LakibeamConfig cfg;
  cfg.bins_per_turn = 1u + static_cast<std::uint32_t>(data[0]) * 16u;
  check(g_parser.configure(cfg));
  std::size_t off = 1, datagrams = 0;
  LidarParserCounters prev = g_parser.counters();
  while (off + 2 <= size) {
    std::size_t n = (static_cast<std::size_t>(data[off]) | (static_cast<std::size_t>(data[off + 1]) << 8)) % sizeof g_dgram;
    off += 2;
    // Short inputs grow into full datagrams: the tail repeats the input so markers can line up.
    for (std::size_t k = 0; k < n; ++k) g_dgram[k] = data[(off + k) % size];
    off += n < size ? n : size;
    g_parser.feed_datagram(g_dgram, n, 1000u + datagrams * 1000u);
    ++datagrams;
    const auto& c = g_parser.counters();
    check(c.bytes >= prev.bytes && c.scans >= prev.scans && c.bad_packets >= prev.bad_packets &&
          c.packets >= prev.packets && c.dropped_bytes >= prev.dropped_bytes);
    check(c.bytes == c.bytes_accepted + c.dropped_bytes);
    check(c.packets + c.bad_packets == datagrams);
    prev = c;
    if (g_parser.take_scan(g_scan)) {
      check(g_scan.count == cfg.bins_per_turn);
      for (std::size_t k = 0; k < g_scan.count; ++k)
        check(std::isfinite(g_scan.ranges_m[k]) && g_scan.ranges_m[k] >= 0);
    }
  }
  return 0;
}
