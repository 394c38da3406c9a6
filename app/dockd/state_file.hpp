#pragma once
/// @file dockd's persistent state: the taught docked-pose targets, by dock id, each with the reflector code teach
/// read on the dock, if any. A small text file ending in a CRC-32 line; written atomically (temp file, fsync, rename,
/// directory fsync) with the previous good copy kept as
/// "<file>.bak". A file whose checksum or syntax is wrong is reported, moved aside to "<file>.corrupt", and the last
/// good copy (.bak) is used instead. Start-up / teach only: heap and stdio are fine here.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "dockcore/geometry.hpp"
#include "dockcore/perception/dock_profile.hpp"

namespace dockd {

/// One taught target: where the dock appeared in the robot frame with the robot on the charger.
struct TaughtTarget {
  std::uint16_t dock_id = 0;
  dockcore::Pose2 target{};
  std::uint16_t scans = 0;        ///< Detections averaged.
  double spread_m = 0;            ///< Largest position deviation of one detection from the mean, m.
  std::uint64_t taught_unix_s = 0;
  /// The dock's reflector code as teach read it (docs/dockd.md, "Teach"): stripes along the segments of the dock's
  /// own profile, in order. None (0) when the dock showed no tape or no code could be read.
  dockcore::ReflectorStripe stripes[dockcore::kMaxReflectors] = {};
  std::uint8_t stripe_count = 0;
  std::uint16_t code_scans = 0;  ///< Scans that read this pattern.
  double code_spread_m = 0;      ///< Largest deviation of one scan's stripe edge from the mean edge, m.
  std::size_t code_line = 0;     ///< The code's line in the state file it was loaded from (0: not loaded), for reports.
};

struct StateData {
  std::vector<TaughtTarget> targets;
  /// The target of `dock_id`, or nullptr.
  const TaughtTarget* find(std::uint16_t dock_id) const;
  /// Adds or replaces the target of t.dock_id.
  void put(const TaughtTarget& t);
};

/// Adds t's taught stripes to `profile` when it has none of its own and every stripe fits (add_reflector); true
/// then, else false with `profile` unchanged and, when a stripe did not fit, add_reflector's reason in `why` (if not
/// null; kOk otherwise). O(kMaxReflectors²).
bool with_taught_code(dockcore::DockProfile& profile, const TaughtTarget& t, dockcore::ProfileError* why = nullptr);

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
/// Parses serialised text; false + reason when the checksum, header or a target line is wrong. A bad `code` line
/// (malformed, a stripe shorter than 1 cm, out of order or overlapping, no target line before it) is left out and
/// reported in `warnings` ("line N: ..."), changing nothing else. O(size).
bool parse_state(const std::string& text, StateData& out, std::string& error,
                 std::vector<std::string>* warnings = nullptr);
/// The length of `text` before its last line, a `crc32 <8 hex digits>` line that ends the text and matches the CRC-32
/// of everything before it (dockd's state and learned files end so); false + reason otherwise. O(size).
bool checked_body(const std::string& text, std::size_t* body_size, std::string& error);
/// CRC-32 (IEEE, reflected, as zlib) of `len` bytes.
std::uint32_t crc32_ieee(const char* data, std::size_t len);

// The durable-file steps both of dockd's files use (the state file here, the learned file in learned_file.hpp).

/// How read_bounded() ended: read, no such file, could not be opened, or over its size bound.
enum class FileRead : std::uint8_t { kOk, kMissing, kUnreadable, kTooLarge };
/// Reads `path` whole into `text` when it holds at most `max_bytes`; kMissing when it does not exist; kUnreadable
/// ("cannot open: ...") or kTooLarge ("larger than N bytes", without reading a runaway file whole) with `why`
/// otherwise. O(size).
FileRead read_bounded(const std::string& path, std::size_t max_bytes, std::string& text, std::string& why);
/// The directory `path` lies in, as open() takes it ("." for a bare name, "/" at the root).
std::string directory_of(const std::string& path);
/// Creates (or truncates) `tmp`, writes `len` bytes and fsyncs it; false with `tmp` removed and the reason ("cannot
/// create|write|fsync|close TMP: ...") in `error` (NUL-terminated, at most `error_size`). No heap. O(len).
bool write_synced(const char* tmp, const char* data, std::size_t len, char* error, std::size_t error_size);
/// Renames `tmp` over `path` and fsyncs `dir`, the directory both lie in, so the new file outlives a power cut; false
/// with `tmp` removed and the reason ("cannot rename TMP to PATH: ...") in `error`. No heap. O(1).
bool replace_synced(const char* tmp, const char* path, const char* dir, char* error, std::size_t error_size);

/// Loads `path` as described in the file comment; `message` explains anything other than kOk / kMissing.
/// `warnings` receives the code lines left out of the file used ("FILE:LINE: ..."); they make no other change.
StateLoadStatus load_state(const std::string& path, StateData& out, std::string& message,
                           std::vector<std::string>* warnings = nullptr);
/// Writes `s` atomically. False + reason on any I/O error (the previous file is then untouched).
bool save_state(const std::string& path, const StateData& s, std::string& error);

}  // namespace dockd
