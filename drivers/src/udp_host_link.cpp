#include "dockcore/drivers/udp_host_link.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace dockcore::drivers {

bool parse_ipv4_cidr(const std::string& text, std::uint32_t& addr_be, std::uint32_t& mask_be) {
  std::string ip = text;
  int prefix = 32;
  const std::size_t slash = text.find('/');
  if (slash != std::string::npos) {
    ip = text.substr(0, slash);
    const std::string p = text.substr(slash + 1);
    if (p.empty() || p.size() > 2) return false;
    prefix = 0;
    for (char c : p) {
      if (c < '0' || c > '9') return false;
      prefix = prefix * 10 + (c - '0');
    }
    if (prefix > 32) return false;
  }
  in_addr a{};
  if (inet_pton(AF_INET, ip.c_str(), &a) != 1) return false;
  const std::uint32_t mask_h = prefix == 0 ? 0u : (0xFFFFFFFFu << (32 - prefix));
  mask_be = htonl(mask_h);
  addr_be = a.s_addr & mask_be;
  return true;
}

namespace {

struct Cidr {
  std::uint32_t addr_be;
  std::uint32_t mask_be;
};

bool parse_allowlist(const std::vector<std::string>& list, std::vector<Cidr>& out, std::string& error) {
  if (list.size() > kMaxHostAllowlist) {
    error = "host link: allowlist has " + std::to_string(list.size()) + " entries (at most " +
            std::to_string(kMaxHostAllowlist) + ")";
    return false;
  }
  out.clear();
  for (const std::string& a : list) {
    Cidr c{};
    if (!parse_ipv4_cidr(a, c.addr_be, c.mask_be)) {
      error = "host link: allowlist entry '" + a + "' is not an IPv4 address or a.b.c.d/prefix";
      return false;
    }
    out.push_back(c);
  }
  return true;
}

struct Subscriber {
  HostPeer peer{};
  std::uint64_t until_us = 0;
  bool used = false;
};

class UdpHostLinkImpl final : public UdpHostLink {
 public:
  UdpHostLinkImpl(int fd, std::vector<Cidr> allow, const UdpHostLinkOptions& o, std::uint16_t port, bool loopback)
      : fd_(fd), allow_(std::move(allow)), subs_(o.max_subscribers), sub_ms_(o.subscription_ms), port_(port),
        loopback_bind_(loopback) {}
  ~UdpHostLinkImpl() override {
    if (fd_ >= 0) ::close(fd_);
  }

  bool poll_datagram(hal::HostDatagram& out, std::uint64_t now_us) override {
    expire(now_us);
    for (int i = 0; i < 64; ++i) {
      sockaddr_in from{};
      socklen_t fl = sizeof from;
      // MSG_TRUNC: the datagram's real length, so a longer one is known as such (and refused by the parser).
      const ssize_t n = ::recvfrom(fd_, out.data, sizeof out.data, MSG_TRUNC, reinterpret_cast<sockaddr*>(&from), &fl);
      if (n < 0) return false;  // EAGAIN: nothing pending (other errors: nothing readable either)
      if (fl < static_cast<socklen_t>(sizeof from) || from.sin_family != AF_INET || !allowed(from.sin_addr.s_addr)) {
        ++c_.not_allowed;
        continue;
      }
      ++c_.datagrams;
      out.len = static_cast<std::size_t>(n);
      out.peer = HostPeer{from.sin_addr.s_addr, from.sin_port};
      out.stamp_us = now_us;
      return true;
    }
    return false;
  }

  bool reply(const HostPeer& peer, const char* json, std::size_t len) override {
    if (len == 0 || len + 1 > kMaxHostReply) {
      ++c_.send_failures;
      return false;
    }
    char buf[kMaxHostReply];
    std::memcpy(buf, json, len);
    buf[len] = '\n';
    if (!send_to(peer, buf, len + 1)) {
      ++c_.send_failures;
      return false;
    }
    ++c_.replies;
    return true;
  }

  void publish(const char* json, std::size_t len, std::uint64_t now_us) override {
    expire(now_us);
    if (len == 0 || len + 1 > kMaxHostReply) return;
    char buf[kMaxHostReply];
    std::memcpy(buf, json, len);
    buf[len] = '\n';
    for (Subscriber& s : subs_) {
      if (!s.used) continue;
      if (send_to(s.peer, buf, len + 1)) {
        ++c_.stream_sent;
      } else {
        ++c_.send_failures;
      }
    }
  }

  std::size_t subscriber_count() const override {
    std::size_t n = 0;
    for (const Subscriber& s : subs_) n += s.used ? 1u : 0u;
    return n;
  }
  const UdpHostCounters& counters() const override { return c_; }
  bool subscribe(const HostPeer& peer, std::uint64_t now_us, std::uint32_t& expires_ms) override {
    Subscriber* slot = find(peer);
    if (slot == nullptr) {
      for (Subscriber& s : subs_) {
        if (!s.used && slot == nullptr) slot = &s;
      }
    }
    if (slot == nullptr) {
      ++c_.subscribers_rejected;
      return false;
    }
    slot->used = true;
    slot->peer = peer;
    slot->until_us = now_us + static_cast<std::uint64_t>(sub_ms_) * 1000u;
    expires_ms = sub_ms_;
    return true;
  }
  void unsubscribe(const HostPeer& peer) override {
    Subscriber* slot = find(peer);
    if (slot != nullptr) slot->used = false;
  }
  std::uint16_t bound_port() const override { return port_; }
  bool set_allowlist(const std::vector<std::string>& list, std::string& error) override {
    std::vector<Cidr> next;
    if (!parse_allowlist(list, next, error)) return false;
    if (!loopback_bind_ && next.empty()) {
      error = "host link: bound to a non-loopback address: the allowlist cannot become empty";
      return false;
    }
    allow_ = std::move(next);
    return true;
  }

  int fd() const override { return fd_; }

 private:
  bool allowed(std::uint32_t addr_be) const {
    if (addr_be == htonl(INADDR_LOOPBACK)) return true;  // the local host itself (127.0.0.1)
    for (const Cidr& c : allow_) {
      if ((addr_be & c.mask_be) == c.addr_be) return true;
    }
    return false;
  }

  bool send_to(const HostPeer& peer, const char* buf, std::size_t len) {
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_addr.s_addr = peer.addr_be;
    to.sin_port = peer.port_be;
    const ssize_t n = ::sendto(fd_, buf, len, MSG_DONTWAIT, reinterpret_cast<const sockaddr*>(&to), sizeof to);
    return n == static_cast<ssize_t>(len);
  }

  void expire(std::uint64_t now_us) {
    for (Subscriber& s : subs_) {
      if (s.used && now_us >= s.until_us) {
        s.used = false;
        ++c_.subscriptions_expired;
      }
    }
  }

  Subscriber* find(const HostPeer& peer) {
    for (Subscriber& s : subs_) {
      if (s.used && s.peer.addr_be == peer.addr_be && s.peer.port_be == peer.port_be) return &s;
    }
    return nullptr;
  }

  int fd_;
  std::vector<Cidr> allow_;
  std::vector<Subscriber> subs_;
  std::uint32_t sub_ms_;
  std::uint16_t port_;
  bool loopback_bind_;
  UdpHostCounters c_{};
};

}  // namespace

std::unique_ptr<UdpHostLink> open_udp_host_link(const UdpHostLinkOptions& o, std::string& error) {
  in_addr bind_addr{};
  if (inet_pton(AF_INET, o.bind_address.c_str(), &bind_addr) != 1) {
    error = "host link: bind address '" + o.bind_address + "' is not an IPv4 address";
    return nullptr;
  }
  std::vector<Cidr> allow;
  if (!parse_allowlist(o.allowlist, allow, error)) return nullptr;
  const bool loopback = (ntohl(bind_addr.s_addr) >> 24) == 127u;
  if (!loopback && allow.empty()) {
    error = "host link: binding " + o.bind_address + " (not loopback) needs an explicit allowlist";
    return nullptr;
  }
  if (o.max_subscribers < 1 || o.max_subscribers > 64) {
    error = "host link: max_subscribers must be 1..64";
    return nullptr;
  }
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    error = std::string("host link: socket: ") + std::strerror(errno);
    return nullptr;
  }
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_addr = bind_addr;
  sa.sin_port = htons(o.port);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0) {
    error = "host link: bind " + o.bind_address + ":" + std::to_string(o.port) + ": " + std::strerror(errno);
    ::close(fd);
    return nullptr;
  }
  socklen_t sl = sizeof sa;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&sa), &sl);
  return std::make_unique<UdpHostLinkImpl>(fd, std::move(allow), o, ntohs(sa.sin_port), loopback);
}

}  // namespace dockcore::drivers
