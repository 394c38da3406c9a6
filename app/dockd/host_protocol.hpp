#pragma once
/// @file dockd's host protocol: what the host links bring (UDP JSON request datagrams, CAN host command frames) parsed
/// and turned into replies and queued core commands, and what goes back to the hosts. Every UDP request gets exactly
/// one reply, written with a JsonWriter into a fixed buffer: at once (status, subscriptions, refusals — a datagram
/// that does not parse among them), when the core takes its queued command (dock, undock, stop, test: the slot it
/// waits in is kept here) or when its teach ends. Also the status on both links (the CAN status frame, the UDP
/// stream) and the refusal counters. Refusal events are rate-limited. No allocation; every call is bounded (see each).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "config.hpp"
#include "counters.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/hal/host_link.hpp"
#include "events.hpp"
#include "json_writer.hpp"

namespace dockd {

/// Request kinds. 1-4 are the task manager's HostCommandType codes; 10+ are answered by dockd itself.
enum class HostRequestKind : std::uint8_t {
  kDock = 1,
  kStop = 2,  ///< "stop" or "cancel".
  kUndock = 3,
  kTest = 4,        ///< Recognition only (test mode).
  kStatus = 10,     ///< One status reply.
  kTeach = 11,      ///< Teach the docked-pose target of a dock (robot placed on the charger by hand).
  kSubscribe = 12,  ///< The peer receives the status stream until it expires.
  kUnsubscribe = 13,
};

/// Stable wire name ("dock", "stop", ...). Never null. O(1).
const char* to_string(HostRequestKind k);

/// Which part of the status a status request asks for.
enum class StatusPart : std::uint8_t {
  kMain = 0,      ///< The status object (task, inputs, detection, counters), as the stream carries it.
  kCamera = 1,    ///< The camera's and the tag fusion's fields, always whole (the main status drops them when full).
  kCounters = 2,  ///< The counters, always whole (the main status drops them when full).
};

/// One parsed UDP request.
struct HostRequest {
  HostRequestKind kind = HostRequestKind::kStatus;
  bool has_dock_id = false;
  std::uint16_t dock_id = 0;  ///< 0..65535 on the wire; the dock database decides which exist.
  bool has_seq = false;
  std::uint32_t seq = 0;           ///< Echoed in the reply; 0..2^32-1.
  std::uint16_t scans = 0;         ///< teach: scans to average (0 = teach_scans).
  StatusPart part = StatusPart::kMain;  ///< status: "part" ("main" when absent).
  dockcore::hal::HostPeer peer{};  ///< Who sent it (replies go there).
  std::uint64_t stamp_us = 0;      ///< Receive time, CLOCK_MONOTONIC µs.
};

/// Error codes in replies ("code" field). Stable numbers: hosts log them.
enum class HostErrorCode : std::uint16_t {
  kNone = 0,
  kMalformed = 1,        ///< Not a flat JSON object (see FlatJsonError), or no "cmd" string.
  kUnknownCommand = 2,   ///< "cmd" is not one of the documented commands.
  kBadField = 3,         ///< A field has the wrong type or is out of range, or an unknown field is present.
  kTooLong = 4,          ///< Datagram longer than hal::kMaxHostDatagram.
  kUnknownDockId = 5,    ///< dock_id is not in dockd's dock database.
  kRejected = 6,         ///< The task manager refused the command (busy, not docked, ...): see "result".
  kTeachFailed = 7,      ///< Teaching could not start or finish (not on the contacts, no dock seen, state file).
  kSubscribersFull = 8,  ///< The subscriber table is full.
  kBusy = 9,             ///< Another request of this kind is still running (teach), or the command queue is full.
  kReplyTooLong = 10,    ///< The reply (or a status stream object) did not fit one datagram: this error went instead.
};

/// Stable snake_case name ("malformed", ...). Never null. O(1).
const char* to_string(HostErrorCode e);

/// Parses one request datagram of `len` bytes (no I/O; `data` is read only when len ≤ hal::kMaxHostDatagram). On
/// error `out` is untouched except for seq (echoed when it could be read) and `detail` (static text naming the
/// offending field or reason). Fields: cmd (string, required), seq (integer 0..4294967295), dock_id (integer
/// 0..65535), scans (integer 1..1000, teach only); any other field is kBadField. O(len).
HostErrorCode parse_host_request(const char* data, std::size_t len, HostRequest& out, const char*& detail);

/// Writes {"ok":false,"seq":N,"code":C,"error":"name","message":"..."} (seq omitted when has_seq is false; the
/// message cut at 255 bytes) into `buf`; returns the length (0 when it does not fit). A non-null `type` goes first as
/// "type" (a status stream object: hosts tell the stream from replies by it). O(size).
std::size_t format_host_error(char* buf, std::size_t size, bool has_seq, std::uint32_t seq, HostErrorCode code,
                              const char* message, const char* type = nullptr);

/// What the host protocol asks of the daemon it answers for (Daemon implements it).
class HostActions {
 public:
  /// The status object's fields (the status reply and the stream).
  virtual void status_fields(JsonWriter& w, std::uint64_t now_us) const = 0;
  /// The camera part's fields: the tag fusion's counters, the stall flag and the capture counters, each group only
  /// when dockd has that input (none without a camera).
  virtual void camera_fields(JsonWriter& w) const = 0;
  /// The counters part's fields: every counter of the status.
  virtual void counter_fields(JsonWriter& w, std::uint64_t now_us) const = 0;
  /// The running configuration: the dock database and the default dock.
  virtual const DockdConfig& config() const = 0;
  /// The dock the core is configured for: undock and stop go to it.
  virtual std::uint16_t active_dock_id() const = 0;
  /// Queues `type` for `dock_id` in the core under `token` (0: no reply waits). When the command displaced the
  /// newest queued one (SubmitResult::kReplacedNewest), that one's token in `displaced`. O(1).
  virtual dockcore::SubmitResult submit(dockcore::HostCommandType type, std::uint16_t dock_id, std::uint32_t token,
                                        std::uint32_t& displaced) = 0;
  /// A teach request: starts the teach, or refuses it through HostProtocol::reply_error.
  virtual void start_teach(const HostRequest& r, std::uint64_t now_us) = 0;
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
  /// queue_overflows, status_sent and the UDP requests, `udp`, are counted there) must outlive the object.
  HostProtocol(dockcore::hal::HostRequestLink* udp, dockcore::hal::HostLink* can, HostActions& actions,
               DaemonCounters& counters);

  /// Reads the links: at most 64 UDP requests for the daemon, each after at most 64 datagrams read by the link since
  /// the one before (those that need nothing of the daemon — refused, subscriptions — and foreign ones it drops; its
  /// last read may drop up to 63 more), so a flood is answered over several calls instead of stalling one; and 16 CAN
  /// host commands. Each datagram is parsed here: one that does not parse gets its error reply and is
  /// counted (counters().udp), a subscription is answered with the link's table, status and refusals are answered at
  /// once, teach handed to HostActions::start_teach, task commands queued in the core (full queue: a `busy` reply; a
  /// stop replaces the newest queued command).
  void poll(std::uint64_t now_us);
  /// The core took a queued command on this tick (`out.command_taken`): counts it, answers the UDP request that waits
  /// for it (refused: the task manager's reason and `before`, the task state before the tick) and logs
  /// command_result. O(slots).
  void command_taken(const dockcore::TickOutput& out, dockcore::TaskState before, std::uint64_t now_us);
  /// Logs how many refusal events the rate limit held back, once their window has ended. O(1).
  void report_held_events(std::uint64_t now_us);
  /// The status: `can_status` to the CAN host link, the status object to the UDP subscribers (when there are any); a
  /// status object that does not fit one datagram goes as a reply_too_long error object, counted.
  void publish_status(const dockcore::hal::StatusMessage& can_status, std::uint64_t now_us);

  /// Sends `json` (one object, no newline) to the sender of `r`. A reply that did not fit its buffer (len 0) or one
  /// datagram is replaced by a reply_too_long error, counted in counters().replies_too_long.
  void reply(const HostRequest& r, const char* json, std::size_t len);
  /// Refuses `r`: the error reply ({"ok":false,…,"code","error","message"}), counted, a command_rejected event.
  void reply_error(const HostRequest& r, HostErrorCode code, const char* message);

  /// Every host command refused, whatever refused it: dockd and the task manager (counters().commands_rejected)
  /// plus the UDP datagrams that did not parse (counters().udp.refused()). O(1).
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
    HostRequest request{};
  };
  /// More than the core's queue holds plus the request being submitted: a waiting request always keeps its slot.
  static constexpr std::size_t kSlots = dockcore::CommandQueue::kCapacity + 2;

  /// Parses `d` and answers or hands on the request. True when it was a request for the daemon (not refused, not a
  /// subscription). O(datagram).
  bool handle_datagram(const dockcore::hal::HostDatagram& d, std::uint64_t now_us);
  void handle_udp(const HostRequest& r, std::uint64_t now_us);
  /// subscribe / unsubscribe: the link's subscriber table, and the reply.
  void handle_subscription(const HostRequest& r, std::uint64_t now_us);
  /// Keeps `r` in a free slot for its answer; returns its token. O(kSlots).
  std::uint32_t hold(const HostRequest& r);
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
