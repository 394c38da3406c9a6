#pragma once
/// @file What the core learned about the robot (Dockcore::Learned: the wheels' deadband floors, the lidar mount's
/// calibration, the aim that closed each dock's contacts), kept across restarts in a small file beside the state file
/// ("<state_file>.learned"), with the robot configuration it was learned on. Text lines ending in a CRC-32 line,
/// written atomically (temp file, fsync, rename, directory fsync). The writer formats into a fixed buffer and uses no
/// heap: dockd writes the file from its control loop at the end of a task that changed what was learned. Loading
/// (start-up) may allocate. A file that is missing, corrupt or learned on another configuration is learned again.

#include <cstddef>
#include <cstdint>
#include <string>

#include "dockcore/control/kinematics.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/geometry.hpp"

namespace dockd {

/// The learned state and the configuration it was learned on: the configured lidar mount and drive. It belongs to
/// that robot only.
struct LearnedState {
  dockcore::Pose2 lidar_mount{};    ///< [robot.lidar] as configured when it was learned.
  dockcore::DriveGeometry drive{};  ///< [robot] drive as configured when it was learned.
  std::uint64_t saved_unix_s = 0;
  dockcore::DockcoreBase::Learned learned{};
  /// True when `mount` and `drive` are the configuration it was learned on (each value within 1e-6). O(1).
  bool learned_on(const dockcore::Pose2& mount, const dockcore::DriveGeometry& drive) const;
};

/// True when the two hold the same floors, raises, aims, mount shift, calibration and swing count. O(kDockIds).
bool same_learned(const dockcore::DockcoreBase::Learned& a, const dockcore::DockcoreBase::Learned& b);

/// Largest learned file: the header, four lines and at most kDockIds aim lines, with the checksum.
constexpr std::size_t kMaxLearnedFileBytes = 4096;

/// The file's text into `buf` (NUL-terminated): a `dockd-learned 1` header, then
///   learned <mount x_m y_m yaw_rad> <drive 0 diff|1 mecanum> <wheel_radius_m> <wheel_base_m> <lx_m> <ly_m> <unix_s>
///   deadband <raises> <forward reverse rad/s> × 4 wheels
///   mount <swings> <status 0-6> <lateral_error_m> <rms_m> <sweep_rad> <detections> <mount x y yaw> <shift x_m y_m>
///   aim <dock_id> <lateral_m>          (one per dock with a remembered aim)
///   crc32 <hex>                        (over everything before it)
/// Returns its length, 0 when it does not fit in `size`. No heap. O(kDockIds).
std::size_t format_learned(const LearnedState& l, char* buf, std::size_t size);

/// Parses format_learned()'s text; false + reason ("line N: ...") when the checksum, the header or any line is wrong
/// or out of range (`out` untouched then). O(size).
bool parse_learned(const std::string& text, LearnedState& out, std::string& error);

enum class LearnedLoadStatus : std::uint8_t {
  kOk = 0,
  kMissing = 1,  ///< No file (first start, or removed to start afresh).
  kCorrupt = 2,  ///< Unreadable or wrong: moved to "<path>.corrupt"; `message` says why.
};

/// Loads `path` (at most kMaxLearnedFileBytes). May allocate (start-up).
LearnedLoadStatus load_learned(const std::string& path, LearnedState& out, std::string& message);

/// The paths save_learned() writes, made once at start-up so that a save allocates nothing.
struct LearnedPaths {
  std::string file, tmp, dir;
  static LearnedPaths beside(const std::string& state_file);
};

/// Writes `l` atomically to paths.file through paths.tmp, formatted in `buf` (`size` ≥ kMaxLearnedFileBytes for a
/// full file). False + reason in `error` (NUL-terminated, at most `error_size`) on any error; the previous file is
/// then untouched. No heap. O(file).
bool save_learned(const LearnedPaths& paths, const LearnedState& l, char* buf, std::size_t size, char* error,
                  std::size_t error_size);

}  // namespace dockd
