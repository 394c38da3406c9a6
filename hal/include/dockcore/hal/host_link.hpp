#pragma once
/// @file HAL: the host computer's command channels and dockcore's status stream.
///  - HostLink: fixed command codes in, a fixed status record out (the CAN host frames; any simple consumer);
///  - HostRequestLink: parsed requests in, each answered with one JSON reply to its sender, and a JSON status stream
///    to subscribers (the UDP JSON lines of docs/dockd.md, "Host UDP protocol").

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "dockcore/geometry.hpp"

namespace dockcore::hal {

/// A command from the host. Unknown commands are reported back with a rejection code, never silently dropped.
struct HostCommandMessage {
  std::uint8_t command = 0;    ///< 1 dock, 2 cancel, 3 undock, 4 test_mode (recognition only).
  std::uint16_t dock_id = 0;
  std::uint16_t sequence = 0;  ///< Replays and out-of-order sequences are rejected.
  std::uint64_t stamp_us = 0;
};

/// What dockcore reports on every status tick.
struct StatusMessage {
  std::uint8_t task_state = 0;
  std::uint8_t align_phase = 0;
  std::uint16_t fault_code = 0;
  std::uint8_t retries = 0;
  std::uint8_t last_result = 0;  ///< CommandResult of the last host command (CAN DockStatus.LastResult).
  bool dock_valid = false;
  Pose2 dock_in_robot{};
  std::uint64_t stamp_us = 0;
};

class HostLink {
 public:
  /// Next pending command, non-blocking; false when none.
  virtual bool poll_command(HostCommandMessage& out) = 0;
  virtual bool send_status(const StatusMessage& status) = 0;
  virtual int fd() const = 0;
  /// Commands the link refused itself and never handed out (replayed or out-of-order sequence, queue full,
  /// malformed). O(1).
  virtual std::uint32_t host_commands_rejected() const = 0;

 protected:
  ~HostLink() = default;
};

/// Request kinds. 1-4 are the task manager's HostCommandType codes; 10+ are answered by the consumer itself.
enum class HostRequestKind : std::uint8_t {
  kDock = 1,
  kStop = 2,  ///< "stop" or "cancel".
  kUndock = 3,
  kTest = 4,        ///< Recognition only (test mode).
  kStatus = 10,     ///< One status reply.
  kTeach = 11,      ///< Teach the docked-pose target of a dock (robot placed on the charger by hand).
  kSubscribe = 12,  ///< Handled by the link: the peer receives the status stream until it expires.
  kUnsubscribe = 13,
};

/// Stable wire name ("dock", "stop", ...). Never null.
inline const char* to_string(HostRequestKind k) {
  switch (k) {
    case HostRequestKind::kDock:
      return "dock";
    case HostRequestKind::kStop:
      return "stop";
    case HostRequestKind::kUndock:
      return "undock";
    case HostRequestKind::kTest:
      return "test";
    case HostRequestKind::kStatus:
      return "status";
    case HostRequestKind::kTeach:
      return "teach";
    case HostRequestKind::kSubscribe:
      return "subscribe";
    case HostRequestKind::kUnsubscribe:
      return "unsubscribe";
  }
  return "?";
}

/// An IPv4 peer, network byte order (as in sockaddr_in): where a request came from and its reply goes.
struct HostPeer {
  std::uint32_t addr_be = 0;
  std::uint16_t port_be = 0;
};

/// One parsed request.
struct HostRequest {
  HostRequestKind kind = HostRequestKind::kStatus;
  bool has_dock_id = false;
  std::uint16_t dock_id = 0;  ///< 0..65535 on the wire; the consumer's dock database decides which exist.
  bool has_seq = false;
  std::uint32_t seq = 0;       ///< Echoed in the reply; 0..2^32-1.
  std::uint16_t scans = 0;     ///< teach: scans to average (0 = the consumer's default).
  HostPeer peer{};             ///< Who sent it (replies go there).
  std::uint64_t stamp_us = 0;  ///< Receive time, CLOCK_MONOTONIC µs.
};

/// What a request link counts (status output).
struct HostRequestCounters {
  std::uint32_t datagrams = 0;  ///< Received from allowed peers.
  std::uint32_t requests = 0;   ///< Parsed and handed on (or handled: subscribe).
  std::uint32_t malformed = 0;
  std::uint32_t unknown_command = 0;
  std::uint32_t bad_field = 0;
  std::uint32_t too_long = 0;
  std::uint32_t not_allowed = 0;  ///< Datagrams from peers outside loopback + allowlist: dropped, no reply.
  std::uint32_t replies = 0;
  std::uint32_t send_failures = 0;
  std::uint32_t stream_sent = 0;           ///< Status datagrams sent to subscribers.
  std::uint32_t subscribers_rejected = 0;  ///< Subscribe refused: table full.
  std::uint32_t subscriptions_expired = 0;
  std::uint32_t rejected_later = 0;  ///< Counted by the consumer: unknown dock id, task manager refusals.

  /// Requests the link refused and answered itself (malformed, unknown command, bad field, too long). O(1).
  std::uint32_t refused() const { return malformed + unknown_command + bad_field + too_long; }
};

/// Requests that the consumer answers itself, after deciding on them, and a status stream. The link parses and
/// refuses malformed input (reply + counter) and handles subscribe / unsubscribe; every other request is handed out
/// by poll_request() and gets exactly one reply().
class HostRequestLink {
 public:
  /// Next request that needs the consumer, non-blocking; false when none is pending. Reads a bounded number of
  /// datagrams per call so a flood cannot stall the caller. `now_us`: CLOCK_MONOTONIC µs (stamps, subscription
  /// expiry).
  virtual bool poll_request(HostRequest& out, std::uint64_t now_us) = 0;
  /// Sends `json` (one object, no newline; a newline is appended) to `peer`. False when it could not be sent (a
  /// `len` of 0 is counted as a send failure).
  virtual bool reply(const HostPeer& peer, const char* json, std::size_t len) = 0;
  /// Sends `json` to every live subscriber and drops expired ones. O(subscribers).
  virtual void publish(const char* json, std::size_t len, std::uint64_t now_us) = 0;
  virtual std::size_t subscriber_count() const = 0;
  virtual const HostRequestCounters& counters() const = 0;
  /// For refusals decided by the consumer (kept with the link's own counters in status output).
  virtual void count_rejected() = 0;
  /// Replaces the allowlist of peers besides 127.0.0.1 ("a.b.c.d" or "a.b.c.d/prefix"). The whole list is checked
  /// first: false + message in `error` and the old list kept when it is refused. Allocates; not for the tick.
  virtual bool set_allowlist(const std::vector<std::string>& allowlist, std::string& error) = 0;

 protected:
  ~HostRequestLink() = default;
};

}  // namespace dockcore::hal
