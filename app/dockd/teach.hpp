#pragma once
/// @file dockd's teach: with the robot placed on the charger by hand, the dock's detections are averaged into the
/// docked-pose target of that dock and stored (docs/dockd.md, "Teach"), with the reflector code the scans read on
/// the dock at each detected pose. Teacher keeps the running teach (its request,
/// its samples, its deadline); what it needs of the daemon — the core's configuration, the state file, the reply to
/// the request, the event log — it asks through TeachHooks. No allocation after construction; every call is bounded
/// (see each).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "config.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/perception/reflector_read.hpp"
#include "events.hpp"
#include "host_protocol.hpp"
#include "state_file.hpp"

namespace dockd {

/// What a teach asks of the daemon (Daemon implements it).
class TeachHooks {
 public:
  /// Configures the core for `dock_id`: its own profile as it is (`raw_profile`: what a teach measures) or corrected
  /// by its taught or configured target. Resets the task manager. False when the core refuses the profile.
  virtual bool configure_core(std::uint16_t dock_id, bool raw_profile) = 0;
  /// The dock the core was configured for before the teach: a teach that cannot finish goes back to it.
  virtual std::uint16_t active_dock_id() const = 0;
  /// Stores `t` as the taught target of t.dock_id (the state file). False + reason in `error` when it could not be
  /// saved; nothing changed then. May allocate and write a file (once per teach).
  virtual bool store_target(const TaughtTarget& t, std::string& error) = 0;
  /// Sends `json` (one object, no newline) to the sender of `r`.
  virtual void reply(const HostRequest& r, const char* json, std::size_t len) = 0;
  /// Refuses `r` with an error reply (counted by the host protocol).
  virtual void reply_error(const HostRequest& r, HostErrorCode code, const char* message) = 0;
  /// Writes the event to the event log.
  virtual void log_event(EventLine& e, LogLevel level) = 0;

 protected:
  ~TeachHooks() = default;
};

/// The robot's condition when a teach request arrives, as the daemon sees it.
struct TeachConditions {
  dockcore::TaskState state = dockcore::TaskState::kNotTasking;  ///< The task manager's state.
  bool on_charger = false;   ///< Fresh chassis feedback with the charging contacts closed.
  bool lidar_fresh = false;  ///< Scans arriving (the core's input watch: not stale).
};

/// One teach at a time: started by a request, fed with the detections, finished by progress() (enough scans, or the
/// timeout) or cancel(). The request gets exactly one reply: a refusal at start(), or the result at the end.
class Teacher {
 public:
  /// Most detections one teach averages (the request's `scans` is 1..this).
  static constexpr std::uint16_t kMaxScans = 1000;

  /// `config` (dock database, teach_scans, teach_timeout_s, the pads for the nominal target) and `hooks` must outlive
  /// the object; `config` is read at each start() and finish. Allocates the sample buffer (kMaxScans poses) once.
  Teacher(const DockdConfig& config, TeachHooks& hooks);
  ~Teacher();
  Teacher(const Teacher&) = delete;
  Teacher& operator=(const Teacher&) = delete;

  /// Starts a teach for `r` (its dock_id, else the default dock; its scans, else teach_scans) with the core
  /// configured for the dock's raw profile. Refused with an error reply when the dock is unknown, a teach runs
  /// already, the robot is not idle (NOT_TASKING, FINISH_TASKING or FAULT), not on the charger, the lidar is stale
  /// or the core refuses the profile. O(1) plus the core's configuration.
  void start(const HostRequest& r, const TeachConditions& c, std::uint64_t now_us);
  /// A detection of the dock (robot frame) while a teach runs; ignored when none runs or it has its scans. The
  /// stripes of `scan` (the detection's scan) are read at the detected pose when `intensity_usable` (the lidar's
  /// intensity check says usable) and tallied by pattern. O(1) without intensity, else O(beams on the dock).
  void sample(const dockcore::DockEstimate& e, const dockcore::ScanView& scan, bool intensity_usable);
  /// Once per tick: finishes the teach when it has its scans (the target stored and replied, or refused when the
  /// detections spread over 20 mm or the state file cannot be written), or fails it when teach_timeout_s has passed.
  /// O(1) while it runs; O(scans) plus one state-file write when it ends.
  void progress(std::uint64_t now_us);
  /// A stop or cancel: fails the running teach ("cancelled by stop"); nothing when none runs. O(1).
  void cancel(std::uint64_t now_us);
  /// A teach runs (the core's commands are held meanwhile).
  bool active() const { return active_; }

 private:
  void finish(bool ok, const char* why, std::uint64_t now_us);

  /// The scans that read one stripe count: the pattern of the first (segments), the others' edges summed and their
  /// extremes, edge by edge.
  struct PatternVote {
    std::uint16_t scans = 0;
    std::uint8_t segments[dockcore::kMaxReflectors] = {};
    double sum_m[dockcore::kMaxReflectors][2] = {};
    double min_m[dockcore::kMaxReflectors][2] = {};
    double max_m[dockcore::kMaxReflectors][2] = {};
  };
  /// One vote per stripe count 0..kMaxReflectors; a scan whose segments differ from its count's first is unread.
  PatternVote votes_[dockcore::kMaxReflectors + 1];
  std::uint16_t intensity_unusable_ = 0;  ///< Samples taken while the lidar's intensity was not usable.

  const DockdConfig& cfg_;
  TeachHooks& hooks_;
  bool active_ = false;
  std::uint16_t dock_id_ = 0;
  std::uint16_t wanted_ = 0;
  std::uint16_t have_ = 0;
  double sx_ = 0, sy_ = 0, sc_ = 0, ss_ = 0;    // sums of x, y, cos yaw, sin yaw
  std::unique_ptr<dockcore::Pose2[]> samples_;  ///< kMaxScans poses (24 KiB in double): not inside the daemon.
  std::uint64_t deadline_us_ = 0;
  HostRequest request_{};
};

}  // namespace dockd
