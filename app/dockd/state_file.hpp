#pragma once
/// @file dockd's persistent state: the taught docked-pose targets, by dock id. A small text file ending in a CRC-32
/// line; written atomically (temp file, fsync, rename, directory fsync) with the previous good copy kept as
/// "<file>.bak". A file whose checksum or syntax is wrong is reported, moved aside to "<file>.corrupt", and the last
/// good copy (.bak) is used instead. Start-up / teach only: heap and stdio are fine here.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "dockcore/geometry.hpp"

namespace dockd {

/// One taught target: where the dock appeared in the robot frame with the robot on the charger.
struct TaughtTarget {
  std::uint16_t dock_id = 0;
  dockcore::Pose2 target{};
  std::uint16_t scans = 0;        ///< Detections averaged.
  double spread_m = 0;            ///< Largest position deviation of one detection from the mean, m.
  std::uint64_t taught_unix_s = 0;
};

struct StateData {
  std::vector<TaughtTarget> targets;
  /// The target of `dock_id`, or nullptr.
  const TaughtTarget* find(std::uint16_t dock_id) const;
  /// Adds or replaces the target of t.dock_id.
  void put(const TaughtTarget& t);
};

enum class StateLoadStatus : std::uint8_t {
  kOk = 0,
  kMissing = 1,            ///< No file (first start): empty state.
  kRecoveredBackup = 2,    ///< The file was missing or corrupt; the .bak copy was used.
  kCorruptNoBackup = 3,    ///< The file is corrupt and no good backup exists: empty state (reported).
};

/// A state file larger than this is treated as corrupt without being read whole (32 docks need ~3 KiB).
constexpr std::size_t kMaxStateFileBytes = 1u << 20;

/// Serialised form (with its checksum line). O(targets).
std::string serialize_state(const StateData& s);
/// Parses serialised text; false + reason when the checksum, header or a line is wrong. O(size).
bool parse_state(const std::string& text, StateData& out, std::string& error);
/// CRC-32 (IEEE, reflected, as zlib) of `len` bytes.
std::uint32_t crc32_ieee(const char* data, std::size_t len);

/// Loads `path` as described in the file comment; `message` explains anything other than kOk / kMissing.
StateLoadStatus load_state(const std::string& path, StateData& out, std::string& message);
/// Writes `s` atomically. False + reason on any I/O error (the previous file is then untouched).
bool save_state(const std::string& path, const StateData& s, std::string& error);

}  // namespace dockd
