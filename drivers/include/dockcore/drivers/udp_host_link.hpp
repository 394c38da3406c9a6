#pragma once
/// @file The host's UDP link to dockd (hal::HostRequestLink, hal::HostLink): one JSON object per datagram, bound to
/// 127.0.0.1 by default; peers other than 127.0.0.1 only when they are on an explicit allowlist (others are dropped and
/// counted). Requests: dock, undock, stop/cancel, test, status, teach, subscribe, unsubscribe (docs/dockd.md, "Host UDP
/// protocol"). Malformed JSON, an unknown command or a bad field gets an error reply with a code and a message and
/// changes nothing else; every refusal is counted. Datagrams are bounded (kMaxHostDatagram bytes; longer ones are
/// refused as too_long). Subscribers get the status stream; their number is bounded and each subscription expires
/// unless renewed. Heap only at open; polling, replies and the stream use fixed buffers.

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

/// The request vocabulary is the HAL's (hal::HostRequestLink); these names keep the driver's spelling.
using HostRequestKind = hal::HostRequestKind;
using hal::to_string;

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

using HostPeer = hal::HostPeer;
using HostRequest = hal::HostRequest;

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

using UdpHostCounters = hal::HostRequestCounters;

/// The UDP host link. As a hal::HostRequestLink it is what dockd uses (dockd answers every request itself, after the
/// task manager has ruled); poll_request() reads at most 64 datagrams per call. The hal::HostLink side serves
/// simpler consumers: poll_command() returns dock/stop/undock/test and acknowledges them as queued, answers status
/// with the last send_status() content and refuses teach; its host_commands_rejected() are the parse refusals.
/// set_allowlist() refuses a list with a malformed entry, with more than kMaxHostAllowlist entries, or an empty one
/// while the link is bound to a non-loopback address.
class UdpHostLink : public hal::HostLink, public hal::HostRequestLink {
 public:
  virtual ~UdpHostLink() = default;
  /// The bound port (useful with port 0).
  virtual std::uint16_t bound_port() const = 0;
};

/// Opens the socket. nullptr + message in `error` for a bad address, a bad allowlist entry, a non-loopback bind
/// without allowlist, or a socket error (port in use).
std::unique_ptr<UdpHostLink> open_udp_host_link(const UdpHostLinkOptions& options, std::string& error);

/// Parses "a.b.c.d" or "a.b.c.d/prefix" into an address and mask (network byte order). False when malformed.
bool parse_ipv4_cidr(const std::string& text, std::uint32_t& addr_be, std::uint32_t& mask_be);

}  // namespace dockcore::drivers
