#pragma once
/// @file The host's UDP link to dockd (hal::HostLink): one JSON object per datagram, bound to 127.0.0.1 by default;
/// peers other than 127.0.0.1 only when they are on an explicit allowlist (others are dropped and counted). Requests: dock, undock,
/// stop/cancel, test, status, teach, subscribe, unsubscribe (docs/dockd.md, "Host UDP protocol"). Malformed JSON, an
/// unknown command or a bad field gets an error reply with a code and a message and changes nothing else; every
/// refusal is counted. Datagrams are bounded (kMaxHostDatagram bytes; longer ones are refused as too_long).
/// Subscribers get the status stream; their number is bounded and each subscription expires unless renewed.
/// Heap only at open; polling, replies and the stream use fixed buffers.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/hal/host_link.hpp"

namespace dockcore::drivers {

/// Largest accepted request datagram, bytes.
constexpr std::size_t kMaxHostDatagram = 512;
/// Most allowlist entries (each checked per datagram from a non-127.0.0.1 peer: the cost per datagram is bounded).
constexpr std::size_t kMaxHostAllowlist = 64;
/// Largest reply / status datagram dockd sends, bytes.
constexpr std::size_t kMaxHostReply = 1400;

/// Request kinds. 1-4 are the task manager's HostCommandType codes; 10+ are answered by dockd itself.
enum class HostRequestKind : std::uint8_t {
  kDock = 1,
  kStop = 2,       ///< "stop" or "cancel".
  kUndock = 3,
  kTest = 4,       ///< Recognition only (test mode).
  kStatus = 10,    ///< One status reply.
  kTeach = 11,     ///< Teach the docked-pose target of a dock (robot placed on the charger by hand).
  kSubscribe = 12, ///< Handled by the link: the peer receives the status stream until it expires.
  kUnsubscribe = 13,
};

/// Stable wire name ("dock", "stop", ...). Never null.
const char* to_string(HostRequestKind k);

/// Error codes in replies ("code" field). Stable numbers: hosts log them.
enum class HostErrorCode : std::uint16_t {
  kNone = 0,
  kMalformed = 1,        ///< Not a flat JSON object (see FlatJsonError), or no "cmd" string.
  kUnknownCommand = 2,   ///< "cmd" is not one of the documented commands.
  kBadField = 3,         ///< A field has the wrong type or is out of range, or an unknown field is present.
  kTooLong = 4,          ///< Datagram longer than kMaxHostDatagram.
  kUnknownDockId = 5,    ///< dock_id is not in dockd's dock database.
  kRejected = 6,         ///< The task manager refused the command (busy, not docked, ...): see "result".
  kTeachFailed = 7,      ///< Teaching could not start or finish (not on the contacts, no dock seen, state file).
  kSubscribersFull = 8,  ///< The subscriber table is full.
  kBusy = 9,             ///< Another request of this kind is still running (teach).
};

/// Stable snake_case name ("malformed", ...). Never null.
const char* to_string(HostErrorCode e);

/// An IPv4 peer, network byte order (as in sockaddr_in).
struct HostPeer {
  std::uint32_t addr_be = 0;
  std::uint16_t port_be = 0;
};

/// One parsed request.
struct HostRequest {
  HostRequestKind kind = HostRequestKind::kStatus;
  bool has_dock_id = false;
  std::uint16_t dock_id = 0;   ///< 0..65535 on the wire; dockd's database decides which exist.
  bool has_seq = false;
  std::uint32_t seq = 0;       ///< Echoed in the reply; 0..2^32-1.
  std::uint16_t scans = 0;     ///< teach: scans to average (0 = dockd's default).
  HostPeer peer{};             ///< Who sent it (replies go there).
  std::uint64_t stamp_us = 0;  ///< Receive time, CLOCK_MONOTONIC µs.
};

/// Parses one request datagram (no I/O). On error `out` is untouched except for seq (echoed when it could be read)
/// and `detail` (static text naming the offending field or reason). Fields: cmd (string, required), seq (integer
/// 0..4294967295), dock_id (integer 0..65535), scans (integer 1..1000, teach only); any other field is kBadField.
/// O(len).
HostErrorCode parse_host_request(const char* data, std::size_t len, HostRequest& out, const char*& detail);

/// Writes {"ok":false,"seq":N,"code":C,"error":"name","message":"..."} (seq omitted when has_seq is false) into
/// `buf`; returns the length (0 when it does not fit). O(size).
std::size_t format_host_error(char* buf, std::size_t size, bool has_seq, std::uint32_t seq, HostErrorCode code,
                              const char* message);

struct UdpHostLinkOptions {
  std::string bind_address = "127.0.0.1";  ///< IPv4 address to bind.
  std::uint16_t port = 7300;               ///< UDP port; 0 = any free port (tests; see bound_port()).
  /// IPv4 peers allowed besides 127.0.0.1 (always allowed): "a.b.c.d" or "a.b.c.d/prefix". Empty = 127.0.0.1 only. Binding a
  /// non-loopback address with an empty allowlist is refused at open (no accidental exposure).
  std::vector<std::string> allowlist;
  std::size_t max_subscribers = 8;         ///< Status stream receivers at most (1..64).
  std::uint32_t subscription_ms = 10000;   ///< A subscription lasts this long unless renewed.
};

struct UdpHostCounters {
  std::uint32_t datagrams = 0;           ///< Received from allowed peers.
  std::uint32_t requests = 0;            ///< Parsed and handed on (or handled: subscribe).
  std::uint32_t malformed = 0;
  std::uint32_t unknown_command = 0;
  std::uint32_t bad_field = 0;
  std::uint32_t too_long = 0;
  std::uint32_t not_allowed = 0;         ///< Datagrams from peers outside loopback + allowlist: dropped, no reply.
  std::uint32_t replies = 0;
  std::uint32_t send_failures = 0;
  std::uint32_t stream_sent = 0;         ///< Status datagrams sent to subscribers.
  std::uint32_t subscribers_rejected = 0;///< Subscribe refused: table full.
  std::uint32_t subscriptions_expired = 0;
  std::uint32_t rejected_later = 0;      ///< Counted by the consumer: unknown dock id, task manager refusals.
};

/// The UDP host link. poll_request() is what dockd uses (it answers every request itself, after the task manager
/// has ruled). The hal::HostLink side serves simpler consumers: poll_command() returns dock/stop/undock/test and
/// acknowledges them as queued, answers status with the last send_status() content and refuses teach.
class UdpHostLink : public hal::HostLink {
 public:
  virtual ~UdpHostLink() = default;
  /// Next request that needs the consumer, non-blocking; false when none is pending. Handles subscribe /
  /// unsubscribe and refuses malformed input itself (reply + counter). Reads at most 64 datagrams per call so a
  /// flood cannot stall the caller. `now_us`: CLOCK_MONOTONIC µs (stamps, subscription expiry).
  virtual bool poll_request(HostRequest& out, std::uint64_t now_us) = 0;
  /// Sends `json` (one object, no newline; a newline is appended) to `peer`. False when it could not be sent.
  virtual bool reply(const HostPeer& peer, const char* json, std::size_t len) = 0;
  /// Sends `json` to every live subscriber and drops expired ones. O(subscribers).
  virtual void publish(const char* json, std::size_t len, std::uint64_t now_us) = 0;
  virtual std::size_t subscriber_count() const = 0;
  virtual const UdpHostCounters& counters() const = 0;
  /// For refusals decided by the consumer (kept with the link's own counters in status output).
  virtual void count_rejected() = 0;
  /// The bound port (useful with port 0).
  virtual std::uint16_t bound_port() const = 0;
  /// Replaces the allowlist (dockd's config reload). The whole list is checked first: false + message in `error`
  /// and the old list kept when an entry is malformed, when there are more than kMaxHostAllowlist entries, or when
  /// the link is bound to a non-loopback address and the new list is empty. Allocates; not for the tick.
  virtual bool set_allowlist(const std::vector<std::string>& allowlist, std::string& error) = 0;
};

/// Opens the socket. nullptr + message in `error` for a bad address, a bad allowlist entry, a non-loopback bind
/// without allowlist, or a socket error (port in use).
std::unique_ptr<UdpHostLink> open_udp_host_link(const UdpHostLinkOptions& options, std::string& error);

/// Parses "a.b.c.d" or "a.b.c.d/prefix" into an address and mask (network byte order). False when malformed.
bool parse_ipv4_cidr(const std::string& text, std::uint32_t& addr_be, std::uint32_t& mask_be);

}  // namespace dockcore::drivers
