#pragma once
/// @file dockd's host protocol: what the host links bring (UDP JSON requests, CAN host command frames) turned into
/// replies and queued core commands, and what goes back to the hosts. Every UDP request gets exactly one reply,
/// written with a JsonWriter into a fixed buffer: at once (status, refusals), when the core takes its queued command
/// (dock, undock, stop, test: the slot it waits in is kept here) or when its teach ends. Also the status on both
/// links (the CAN status frame, the UDP stream) and the links' refusal counters. Refusal events are rate-limited.
/// No allocation; every call is bounded (see each).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "config.hpp"
#include "counters.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/drivers/json_writer.hpp"
#include "dockcore/drivers/udp_host_link.hpp"
#include "dockcore/hal/host_link.hpp"
#include "events.hpp"

namespace dockd {

/// What the host protocol asks of the daemon it answers for (Daemon implements it).
class HostActions {
 public:
  /// The status object's fields (the status reply and the stream).
  virtual void status_fields(dockcore::drivers::JsonWriter& w, std::uint64_t now_us) const = 0;
  /// The running configuration: the dock database and the default dock.
  virtual const DockdConfig& config() const = 0;
  /// The dock the core is configured for: undock and stop go to it.
  virtual std::uint16_t active_dock_id() const = 0;
  /// Queues `type` for `dock_id` in the core under `token` (0: no reply waits). When the command displaced the
  /// newest queued one (SubmitResult::kReplacedNewest), that one's token in `displaced`. O(1).
  virtual dockcore::SubmitResult submit(dockcore::HostCommandType type, std::uint16_t dock_id, std::uint32_t token,
                                        std::uint32_t& displaced) = 0;
  /// A teach request: starts the teach, or refuses it through HostProtocol::reply_error.
  virtual void start_teach(const dockcore::hal::HostRequest& r, std::uint64_t now_us) = 0;
  /// A stop (UDP) or cancel (CAN): ends a running teach as failed; nothing when none runs.
  virtual void cancel_teach(std::uint64_t now_us) = 0;
  /// Writes the event (EventLine) to the event log and, at or above the configured level, stderr.
  virtual void log_event(EventLine& e, LogLevel level) = 0;

 protected:
  ~HostActions() = default;
};

class HostProtocol {
 public:
  /// `udp` and `can` may be null (no such link). `actions` and `counters` (commands, commands_rejected,
  /// queue_overflows, status_sent are counted there) must outlive the object.
  HostProtocol(dockcore::hal::HostRequestLink* udp, dockcore::hal::HostLink* can, HostActions& actions,
               DaemonCounters& counters);

  /// Reads the links: at most 64 UDP requests (a flood is answered over several calls instead of stalling one) and
  /// 16 CAN host commands. Status and refusals are answered at once, teach handed to HostActions::start_teach, task
  /// commands queued in the core (full queue: a `busy` reply; a stop replaces the newest queued command).
  void poll(std::uint64_t now_us);
  /// The core took a queued command on this tick (`out.command_taken`): counts it, answers the UDP request that waits
  /// for it (refused: the task manager's reason and `before`, the task state before the tick) and logs
  /// command_result. O(slots).
  void command_taken(const dockcore::TickOutput& out, dockcore::TaskState before, std::uint64_t now_us);
  /// Logs how many refusal events the rate limit held back, once their window has ended. O(1).
  void report_held_events(std::uint64_t now_us);
  /// The status: `can_status` to the CAN host link, the status object to the UDP subscribers (when there are any).
  void publish_status(const dockcore::hal::StatusMessage& can_status, std::uint64_t now_us);

  /// Sends `json` (one object, no newline) to the sender of `r`. A reply that did not fit its buffer (len 0) reaches
  /// the link too, which counts it as a send failure.
  void reply(const dockcore::hal::HostRequest& r, const char* json, std::size_t len);
  /// Refuses `r`: the error reply ({"ok":false,…,"code","error","message"}), counted, a command_rejected event.
  void reply_error(const dockcore::hal::HostRequest& r, dockcore::drivers::HostErrorCode code, const char* message);

  /// Every host command refused, whatever refused it: dockd and the task manager (counters().commands_rejected)
  /// plus the UDP link's parse refusals. O(1).
  std::uint32_t commands_rejected_total() const;
  /// Datagrams from peers outside 127.0.0.1 + allowlist (0 without a UDP link). O(1).
  std::uint32_t udp_not_allowed() const;
  /// CAN host command frames the CAN link refused (0 without one). O(1).
  std::uint32_t can_rejected() const;
  /// Replaces the UDP link's allowlist (config reload); true without a UDP link. Allocates.
  bool set_allowlist(const std::vector<std::string>& allowlist, std::string& error);

 private:
  /// A UDP request whose command waits in the core's queue: answered when the core takes the command.
  struct Slot {
    std::uint32_t token = 0;  ///< 0: free.
    dockcore::hal::HostRequest request{};
  };
  /// More than the core's queue holds plus the request being submitted: a waiting request always keeps its slot.
  static constexpr std::size_t kSlots = dockcore::CommandQueue::kCapacity + 2;

  void handle_udp(const dockcore::hal::HostRequest& r, std::uint64_t now_us);
  /// Keeps `r` in a free slot for its answer; returns its token. O(kSlots).
  std::uint32_t hold(const dockcore::hal::HostRequest& r);
  /// The request held under `token` (nullptr for 0 or one no longer held), released. O(kSlots).
  const Slot* take(std::uint32_t token);
  /// Queues a command in the core (counted as an overflow unless queued; a refused or displaced request's slot is
  /// released). O(kSlots).
  dockcore::SubmitResult submit(dockcore::HostCommandType type, std::uint16_t dock_id, std::uint32_t token);

  dockcore::hal::HostRequestLink* udp_;
  dockcore::hal::HostLink* can_;
  HostActions& actions_;
  DaemonCounters& counters_;
  Slot slots_[kSlots];
  std::uint32_t next_token_ = 0;
  EventRateLimit refusal_log_{};  ///< command_rejected and refused command_result events (one per refused request).
};

}  // namespace dockd
