#pragma once
/// @file HAL: the host computer's command channels and dockcore's status stream.
///  - HostLink: fixed command codes in, a fixed status record out (the CAN host frames; any simple consumer);
///  - HostRequestLink: request datagrams in (the consumer parses them), each answered with one JSON reply to its
///    sender, and a JSON status stream to subscribers (the UDP JSON lines of docs/dockd.md, "Host UDP protocol").

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

/// An IPv4 peer, network byte order (as in sockaddr_in): where a request came from and its reply goes.
struct HostPeer {
  std::uint32_t addr_be = 0;
  std::uint16_t port_be = 0;
};

/// Largest request datagram a HostRequestLink hands on whole, bytes.
constexpr std::size_t kMaxHostDatagram = 512;
/// Largest reply or status datagram a HostRequestLink sends, bytes, its newline included: the largest UDP payload an
/// Ethernet frame (MTU 1500, less 20 bytes of IPv4 and 8 of UDP header) carries unfragmented.
constexpr std::size_t kMaxHostReply = 1472;

/// One request datagram as received: bytes only, the consumer parses them.
struct HostDatagram {
  char data[kMaxHostDatagram];  ///< The first min(len, kMaxHostDatagram) bytes.
  /// The datagram's length on the wire. More than kMaxHostDatagram: it was cut, and only its first kMaxHostDatagram
  /// bytes are in data.
  std::size_t len = 0;
  HostPeer peer{};             ///< Who sent it (replies go there).
  std::uint64_t stamp_us = 0;  ///< Receive time, CLOCK_MONOTONIC µs (the poll's now_us).
};

/// What a request link counts of its socket (the consumer counts what the requests were).
struct HostRequestCounters {
  std::uint32_t datagrams = 0;    ///< Received from allowed peers and handed on.
  std::uint32_t not_allowed = 0;  ///< Datagrams from peers outside loopback + allowlist: dropped, no reply.
  std::uint32_t replies = 0;
  std::uint32_t send_failures = 0;
  std::uint32_t stream_sent = 0;           ///< Status datagrams sent to subscribers.
  std::uint32_t subscribers_rejected = 0;  ///< Subscribe refused: table full.
  std::uint32_t subscriptions_expired = 0;
};

/// A datagram link to the host: request datagrams in (bytes and sender; the consumer parses them and sends exactly
/// one reply() to each), and a status stream to the peers the consumer subscribed. The link only decides which
/// peers may talk to it (others are dropped and counted, never answered).
class HostRequestLink {
 public:
  /// Next datagram from an allowed peer, non-blocking; false when none is pending. Reads a bounded number of
  /// datagrams per call so a flood of foreign ones cannot stall the caller. `now_us`: CLOCK_MONOTONIC µs (the
  /// stamp, subscription expiry).
  virtual bool poll_datagram(HostDatagram& out, std::uint64_t now_us) = 0;
  /// Sends `json` (one object, no newline; a newline is appended) to `peer`. False when it could not be sent (a
  /// `len` of 0 or one that leaves no room for the newline in kMaxHostReply is counted as a send failure).
  virtual bool reply(const HostPeer& peer, const char* json, std::size_t len) = 0;
  /// Sends `json` (as reply()) to every live subscriber and drops expired ones. O(subscribers).
  virtual void publish(const char* json, std::size_t len, std::uint64_t now_us) = 0;
  /// Adds `peer` to the status stream's receivers, or renews its subscription, until now_us + the link's
  /// subscription time, returned in `expires_ms`. False when the table is full (counted). O(subscribers).
  virtual bool subscribe(const HostPeer& peer, std::uint64_t now_us, std::uint32_t& expires_ms) = 0;
  /// Removes `peer` from the receivers (nothing when it is none). O(subscribers).
  virtual void unsubscribe(const HostPeer& peer) = 0;
  virtual std::size_t subscriber_count() const = 0;
  virtual const HostRequestCounters& counters() const = 0;
  /// Replaces the allowlist of peers besides 127.0.0.1 ("a.b.c.d" or "a.b.c.d/prefix"). The whole list is checked
  /// first: false + message in `error` and the old list kept when it is refused. Allocates; not for the tick.
  virtual bool set_allowlist(const std::vector<std::string>& allowlist, std::string& error) = 0;

 protected:
  ~HostRequestLink() = default;
};

}  // namespace dockcore::hal
