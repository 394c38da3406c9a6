#pragma once
/// @file The host's UDP link to dockd (hal::HostRequestLink): one JSON object per datagram, bound to 127.0.0.1 by
/// default; peers other than 127.0.0.1 only when they are on an explicit allowlist (others are dropped and counted,
/// never answered). The link moves bytes: it hands each datagram from an allowed peer on with its sender (dockd's
/// host protocol parses it and replies, docs/dockd.md "Host UDP protocol"), sends the replies, and keeps the status
/// stream's subscriber table, bounded, each subscription expiring unless renewed. Datagrams are bounded
/// (hal::kMaxHostDatagram bytes are handed on; a longer one is handed on cut, with its real length). Heap only at
/// open; polling, replies and the stream use fixed buffers.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/hal/host_link.hpp"

namespace dockcore::drivers {

using hal::kMaxHostDatagram;
using hal::kMaxHostReply;
/// Most allowlist entries (each checked per datagram from a non-127.0.0.1 peer: the cost per datagram is bounded).
constexpr std::size_t kMaxHostAllowlist = 64;

using HostPeer = hal::HostPeer;

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

/// The UDP host link, a hal::HostRequestLink: poll_datagram() reads at most 64 datagrams per call (those from
/// peers outside the allowlist are dropped there). set_allowlist() refuses a list with a malformed entry, with more
/// than kMaxHostAllowlist entries, or an empty one while the link is bound to a non-loopback address.
class UdpHostLink : public hal::HostRequestLink {
 public:
  virtual ~UdpHostLink() = default;
  /// The bound port (useful with port 0).
  virtual std::uint16_t bound_port() const = 0;
  /// The socket, readable when a datagram may be waiting (epoll).
  virtual int fd() const = 0;
};

/// Opens the socket. nullptr + message in `error` for a bad address, a bad allowlist entry, a non-loopback bind
/// without allowlist, or a socket error (port in use).
std::unique_ptr<UdpHostLink> open_udp_host_link(const UdpHostLinkOptions& options, std::string& error);

/// Parses "a.b.c.d" or "a.b.c.d/prefix" into an address and mask (network byte order). False when malformed.
bool parse_ipv4_cidr(const std::string& text, std::uint32_t& addr_be, std::uint32_t& mask_be);

}  // namespace dockcore::drivers
