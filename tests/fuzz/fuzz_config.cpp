// fuzz-links: core drivers dockd_lib
// dockd's config parser: arbitrary bytes as the TOML text of a config. Every input either
// throws dockd::ConfigError whose message starts with "fuzz.toml:<line>:<column>: " (1-based, matching line() and
// column()) — the message --check-config, start-up and a SIGHUP reload print — or returns a config that passes
// dockd's validation: a non-empty dock database of unique ids 0..31 matching the accepted-id mask, an existing
// default dock, every profile accepted by the estimator, a bounded and well-formed allowlist, consistent ranges.
// Any other exception, crash, leak or UB fails the target.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>

#include "config.hpp"
#include "dockcore/drivers/udp_host_link.hpp"
#include "dockcore/perception/dock_pose_estimator.hpp"

namespace {

bool positioned(const dockd::ConfigError& e) {
  // "fuzz.toml:L:C: " with L, C >= 1 equal to line() / column().
  const char* m = e.what();
  const char* prefix = "fuzz.toml:";
  if (std::strncmp(m, prefix, std::strlen(prefix)) != 0) return false;
  int line = 0, col = 0, used = 0;
  if (std::sscanf(m + std::strlen(prefix), "%d:%d: %n", &line, &col, &used) != 2 || used == 0) return false;
  return line >= 1 && col >= 1 && line == e.line() && col == e.column();
}

dockcore::DockPoseEstimator& estimator() {
  static dockcore::DockPoseEstimator* e = new dockcore::DockPoseEstimator();  // large: once, never freed
  return *e;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  dockd::DockdConfig c;
  try {
    c = dockd::parse_config_toml(text, "fuzz.toml");
  } catch (const dockd::ConfigError& e) {
    if (!positioned(e)) {
      std::fprintf(stderr, "unpositioned ConfigError: %s\n", e.what());
      __builtin_trap();
    }
    return 0;
  }  // anything else propagates: libFuzzer reports the uncaught exception as a crash
  if (c.docks.empty() || c.docks.size() > 32) __builtin_trap();
  std::uint32_t mask = 0;
  for (const dockd::DockEntry& d : c.docks) {
    if (d.id > 31 || (mask & (1u << d.id)) != 0) __builtin_trap();
    mask |= 1u << d.id;
    if (!estimator().configure(d.profile, c.estimator)) {
      std::fprintf(stderr, "dock %u: profile accepted by the config but refused by the estimator\n", d.id);
      __builtin_trap();
    }
  }
  if (mask != c.task.accepted_dock_ids || c.find_dock(c.default_dock_id) == nullptr) __builtin_trap();
  if (c.host.allowlist.size() > dockd::kMaxAllowlistEntries) __builtin_trap();
  for (const std::string& a : c.host.allowlist) {
    std::uint32_t addr = 0, m = 0;
    if (!dockcore::drivers::parse_ipv4_cidr(a, addr, m)) __builtin_trap();
  }
  if (c.lidar.reconnect_max_ms < c.lidar.reconnect_min_ms) __builtin_trap();
  if (!(c.estimator.min_range_m < c.estimator.max_range_m)) __builtin_trap();
  if (!(c.status_rate_hz >= 1 && c.status_rate_hz <= 50)) __builtin_trap();
  if (!dockd::restart_only_changes(c, c).empty()) __builtin_trap();
  return 0;
}
