#pragma once
/// @file The loop record: every call a host makes into one Dockcore — configure, chassis feedback, scans, tag poses,
/// queued commands, input checks and ticks — with its arguments, and a digest of each tick's output, so that
/// `dock-sim replay` can run the same calls through a fresh core and show that it reproduces every output bit for
/// bit, or where it first does not (docs/dockd.md, "Session record").
///
/// Format: the 8-byte magic "DCLOOP1\n", a layout line (the sizes of Real and of every recorded struct: a record is
/// replayed only by a build with the same layout, i.e. the same dockcore version, Real type and ABI), then records of
/// [u8 kind][u32 payload length, little-endian][payload]. Payloads are the structs' bytes; a scan carries its ranges
/// and intensities. Host-side code: the writer buffers in memory and writes with one write(2) per flush.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "dockcore/control/controllers.hpp"
#include "dockcore/dockcore.hpp"

namespace dockcore::drivers {

/// Record kinds.
enum class LoopRecordKind : std::uint8_t {
  kConfigure = 1,    ///< LoopConfig: controller, its parameters, profile, DockcoreConfig.
  kWheels = 2,       ///< WheelSpeeds + stamp.
  kOdometry = 3,     ///< Pose2 + Twist2 + stamp.
  kScan = 4,         ///< stamp, read time, geometry, then count ranges and count intensities.
  kTag = 5,          ///< TagObservation.
  kSubmit = 6,       ///< QueuedCommand.
  kCheckInputs = 7,  ///< now_us.
  kTick = 8,         ///< TickInput + the TickDigest of its output.
  kRescan = 9,       ///< (no payload)
  kTakeInputs = 10,  ///< A rebuilt core continues this one's inputs: the next kConfigure builds it (no payload).
  /// DockcoreBase::Learned handed to the core: what dockd carries into each new configuration, or restores from its
  /// learned file. A replay applies it as recorded; a configure alone starts afresh.
  kRestoreLearned = 11,
};

/// Which controller a configure uses and its parameters (the other three keep their defaults).
struct LoopController {
  char name[16] = {};  ///< "seed000", "seed004", "seed003" or "smooth".
  Seed000Params seed000{};
  Seed004Params seed004{};
  Seed003Params seed003{};
  SmoothParams smooth{};
};

/// The outputs of one tick that replay compares: everything the drive, the host and the status get.
struct TickDigest {
  Real wheels[kMaxDriveWheels] = {0, 0, 0, 0};
  std::uint32_t wheel_count = 0;
  Real drive_cmd[3] = {0, 0, 0};  ///< vx, vy, wz.
  Real cmd[3] = {0, 0, 0};
  Real dock_pose[3] = {0, 0, 0};  ///< status.dock_pose x, y, yaw.
  std::uint8_t state = 0, phase = 0, command_result = 0, command_taken = 0, resume = 0, charge_enable = 0;
  std::uint16_t fault = 0;
  std::uint32_t token = 0;

  /// The digest of `o`. O(1).
  static TickDigest of(const TickOutput& o);
  /// The first field in which `a` and `b` differ ("" when none). O(1).
  static const char* first_difference(const TickDigest& a, const TickDigest& b);
};

/// Buffers records and writes them to a file. Not thread-safe; one per core.
class LoopRecordWriter {
 public:
  LoopRecordWriter() = default;
  ~LoopRecordWriter();
  LoopRecordWriter(const LoopRecordWriter&) = delete;
  LoopRecordWriter& operator=(const LoopRecordWriter&) = delete;

  /// Creates (truncates) `path` and writes the header. `max_bytes`: the file stops growing past this (full()).
  /// False + reason when it cannot be created. Allocates its buffer (start-up).
  bool open(const std::string& path, std::uint64_t max_bytes, std::string& error);
  bool is_open() const { return fd_ >= 0; }
  /// True once a record did not fit under max_bytes: nothing more is written (a replay of a cut record stops there).
  bool full() const { return full_; }
  std::uint32_t write_errors() const { return write_errors_; }

  void configure(const LoopController& ctl, const DockProfile& profile, const DockcoreConfig& config);
  void wheels(const WheelSpeeds& w, std::uint64_t stamp_us);
  void odometry(const Pose2& pose, const Twist2& twist, std::uint64_t stamp_us);
  void scan(const ScanView& scan, std::uint64_t stamp_us, std::uint64_t now_us);
  void tag(const TagObservation& obs);
  void submit(const QueuedCommand& c);
  void check_inputs(std::uint64_t now_us);
  void tick(const TickInput& in, const TickOutput& out);
  void rescan();
  void take_inputs();
  void restore_learned(const DockcoreBase::Learned& learned);
  /// Writes what is buffered (one write(2)); the host calls it once per control tick. O(buffered bytes).
  void flush();

 private:
  void put(LoopRecordKind kind, const void* a, std::size_t na, const void* b = nullptr, std::size_t nb = 0,
           const void* c = nullptr, std::size_t nc = 0);
  int fd_ = -1;
  std::vector<unsigned char> buf_;
  std::size_t len_ = 0;
  std::uint64_t written_ = 0, max_bytes_ = 0;
  bool full_ = false;
  std::uint32_t write_errors_ = 0;
};

/// What a replay found.
struct ReplayResult {
  bool ok = false;    ///< Read to the end and every tick reproduced.
  std::string error;  ///< A bad file: "FILE: offset N: reason". Empty otherwise.
  std::uint64_t records = 0, ticks = 0, scans = 0, commands = 0;
  bool diverged = false;  ///< A tick's output differed: the fields below say where.
  std::uint64_t diverged_tick = 0, diverged_now_us = 0;
  std::string diverged_field;
  TickDigest recorded{}, replayed{};
  bool truncated = false;  ///< The file ended inside a record (a killed writer): replayed up to there.
};

/// Replays the record at `path` through a fresh core (of kMaxScanPoints beams) and compares every tick. Allocates
/// (host-side). O(file size).
ReplayResult replay_loop_record(const std::string& path);

}  // namespace dockcore::drivers
