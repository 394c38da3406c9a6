#include "dockcore/drivers/udp_host_link.hpp"

#include "dockcore/drivers/json_writer.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "dockcore/drivers/flat_json.hpp"

namespace dockcore::drivers {

const char* to_string(HostErrorCode e) {
  switch (e) {
    case HostErrorCode::kNone: return "none";
    case HostErrorCode::kMalformed: return "malformed";
    case HostErrorCode::kUnknownCommand: return "unknown_command";
    case HostErrorCode::kBadField: return "bad_field";
    case HostErrorCode::kTooLong: return "too_long";
    case HostErrorCode::kUnknownDockId: return "unknown_dock_id";
    case HostErrorCode::kRejected: return "rejected";
    case HostErrorCode::kTeachFailed: return "teach_failed";
    case HostErrorCode::kSubscribersFull: return "subscribers_full";
    case HostErrorCode::kBusy: return "busy";
  }
  return "?";
}

HostErrorCode parse_host_request(const char* data, std::size_t len, HostRequest& out, const char*& detail) {
  detail = "";
  if (len > kMaxHostDatagram) {
    detail = "datagram longer than 512 bytes";
    return HostErrorCode::kTooLong;
  }
  FlatJson j;
  const FlatJsonError je = j.parse(data, len);
  if (je != FlatJsonError::kOk) {
    detail = to_string(je);
    return HostErrorCode::kMalformed;
  }
  HostRequest r;
  std::int64_t v = 0;
  if (j.has("seq")) {
    if (!j.get_int("seq", 0, 4294967295LL, v)) {
      detail = "seq must be an integer 0..4294967295";
      return HostErrorCode::kBadField;
    }
    r.has_seq = true;
    r.seq = static_cast<std::uint32_t>(v);
    out.has_seq = true;  // echoed in the error reply even when the rest is bad
    out.seq = r.seq;
  }
  const char* cmd = nullptr;
  if (!j.get_string("cmd", cmd)) {
    detail = "\"cmd\" (a string) is required";
    return HostErrorCode::kMalformed;
  }
  struct Name {
    const char* name;
    HostRequestKind kind;
  };
  static const Name kNames[] = {{"dock", HostRequestKind::kDock},         {"stop", HostRequestKind::kStop},
                                {"cancel", HostRequestKind::kStop},       {"undock", HostRequestKind::kUndock},
                                {"test", HostRequestKind::kTest},         {"status", HostRequestKind::kStatus},
                                {"teach", HostRequestKind::kTeach},       {"subscribe", HostRequestKind::kSubscribe},
                                {"unsubscribe", HostRequestKind::kUnsubscribe}};
  bool found = false;
  for (const Name& n : kNames) {
    if (std::strcmp(n.name, cmd) == 0) {
      r.kind = n.kind;
      found = true;
    }
  }
  if (!found) {
    detail = "cmd is not one of dock, undock, stop, cancel, test, status, teach, subscribe, unsubscribe";
    return HostErrorCode::kUnknownCommand;
  }
  for (std::size_t i = 0; i < j.size(); ++i) {
    const char* k = j.key(i);
    if (std::strcmp(k, "cmd") != 0 && std::strcmp(k, "seq") != 0 && std::strcmp(k, "dock_id") != 0 &&
        std::strcmp(k, "scans") != 0) {
      detail = "unknown field (expected cmd, seq, dock_id, scans)";
      return HostErrorCode::kBadField;
    }
  }
  if (j.has("dock_id")) {
    if (!j.get_int("dock_id", 0, 65535, v)) {
      detail = "dock_id must be an integer 0..65535";
      return HostErrorCode::kBadField;
    }
    r.has_dock_id = true;
    r.dock_id = static_cast<std::uint16_t>(v);
  }
  if (j.has("scans")) {
    if (r.kind != HostRequestKind::kTeach || !j.get_int("scans", 1, 1000, v)) {
      detail = "scans must be an integer 1..1000 and only with teach";
      return HostErrorCode::kBadField;
    }
    r.scans = static_cast<std::uint16_t>(v);
  }
  out = r;
  return HostErrorCode::kNone;
}

std::size_t format_host_error(char* buf, std::size_t size, bool has_seq, std::uint32_t seq, HostErrorCode code,
                              const char* message) {
  JsonWriter w(buf, size);
  w.boolean("ok", false);
  if (has_seq) w.uint("seq", seq);
  w.uint("code", static_cast<unsigned>(code)).str("error", to_string(code)).str_cut("message", message, 255);
  return w.finish();
}

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

  bool poll_request(HostRequest& out, std::uint64_t now_us) override {
    expire(now_us);
    for (int i = 0; i < 64; ++i) {
      char buf[kMaxHostDatagram + 1];
      sockaddr_in from{};
      socklen_t fl = sizeof from;
      const ssize_t n = ::recvfrom(fd_, buf, sizeof buf, MSG_TRUNC, reinterpret_cast<sockaddr*>(&from), &fl);
      if (n < 0) return false;  // EAGAIN: nothing pending (other errors: nothing readable either)
      if (fl < static_cast<socklen_t>(sizeof from) || from.sin_family != AF_INET || !allowed(from.sin_addr.s_addr)) {
        ++c_.not_allowed;
        continue;
      }
      ++c_.datagrams;
      HostPeer peer{from.sin_addr.s_addr, from.sin_port};
      HostRequest r;
      const char* detail = "";
      const HostErrorCode e = parse_host_request(buf, static_cast<std::size_t>(n), r, detail);
      if (e != HostErrorCode::kNone) {
        switch (e) {
          case HostErrorCode::kTooLong: ++c_.too_long; break;
          case HostErrorCode::kUnknownCommand: ++c_.unknown_command; break;
          case HostErrorCode::kBadField: ++c_.bad_field; break;
          default: ++c_.malformed; break;
        }
        char reply_buf[512];
        const std::size_t len = format_host_error(reply_buf, sizeof reply_buf, r.has_seq, r.seq, e, detail);
        reply(peer, reply_buf, len);
        continue;
      }
      r.peer = peer;
      r.stamp_us = now_us;
      ++c_.requests;
      if (r.kind == HostRequestKind::kSubscribe || r.kind == HostRequestKind::kUnsubscribe) {
        handle_subscription(r, now_us);
        continue;
      }
      out = r;
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
  void count_rejected() override { ++c_.rejected_later; }
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

  // hal::HostLink.
  std::uint32_t host_commands_rejected() const override { return c_.refused(); }
  bool poll_command(hal::HostCommandMessage& out) override {
    HostRequest r;
    while (poll_request(r, last_now_us_)) {
      char buf[kMaxHostReply];
      if (r.kind == HostRequestKind::kStatus) {
        const int n = std::snprintf(buf, sizeof buf,
                                    "{\"ok\":true,\"cmd\":\"status\",\"seq\":%u,\"task_state\":%u,\"align_phase\":%u,"
                                    "\"fault\":%u,\"retries\":%u,\"dock_valid\":%s}",
                                    r.seq, last_.task_state, last_.align_phase, last_.fault_code, last_.retries,
                                    last_.dock_valid ? "true" : "false");
        if (n > 0) reply(r.peer, buf, static_cast<std::size_t>(n));
        continue;
      }
      if (r.kind == HostRequestKind::kTeach) {
        const std::size_t n = format_host_error(buf, sizeof buf, r.has_seq, r.seq, HostErrorCode::kTeachFailed,
                                                "teach is not supported by this consumer");
        reply(r.peer, buf, n);
        continue;
      }
      out.command = static_cast<std::uint8_t>(r.kind);
      out.dock_id = r.dock_id;
      out.sequence = static_cast<std::uint16_t>(r.seq);
      out.stamp_us = r.stamp_us;
      JsonWriter w(buf, sizeof buf);
      w.boolean("ok", true).str("cmd", to_string(r.kind)).uint("seq", r.seq).boolean("queued", true);
      reply(r.peer, buf, w.finish());
      return true;
    }
    return false;
  }

  bool send_status(const hal::StatusMessage& s) override {
    last_ = s;
    last_now_us_ = s.stamp_us;
    char buf[512];
    const int n = std::snprintf(buf, sizeof buf,
                                "{\"type\":\"status\",\"stamp_us\":%llu,\"task_state\":%u,\"align_phase\":%u,"
                                "\"fault\":%u,\"retries\":%u,\"dock_valid\":%s,\"dock_x_m\":%.4f,\"dock_y_m\":%.4f,"
                                "\"dock_yaw_rad\":%.4f}",
                                static_cast<unsigned long long>(s.stamp_us), s.task_state, s.align_phase, s.fault_code,
                                s.retries, s.dock_valid ? "true" : "false", static_cast<double>(s.dock_in_robot.x_m),
                                static_cast<double>(s.dock_in_robot.y_m), static_cast<double>(s.dock_in_robot.yaw_rad));
    if (n <= 0 || static_cast<std::size_t>(n) >= sizeof buf) return false;
    publish(buf, static_cast<std::size_t>(n), s.stamp_us);
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

  void handle_subscription(const HostRequest& r, std::uint64_t now_us) {
    Subscriber* slot = nullptr;
    for (Subscriber& s : subs_) {
      if (s.used && s.peer.addr_be == r.peer.addr_be && s.peer.port_be == r.peer.port_be) slot = &s;
    }
    char buf[256];
    if (r.kind == HostRequestKind::kUnsubscribe) {
      if (slot != nullptr) slot->used = false;
      JsonWriter w(buf, sizeof buf);
      w.boolean("ok", true).str("cmd", "unsubscribe").uint("seq", r.seq);
      reply(r.peer, buf, w.finish());
      return;
    }
    if (slot == nullptr) {
      for (Subscriber& s : subs_) {
        if (!s.used && slot == nullptr) slot = &s;
      }
    }
    if (slot == nullptr) {
      ++c_.subscribers_rejected;
      const std::size_t n = format_host_error(buf, sizeof buf, r.has_seq, r.seq, HostErrorCode::kSubscribersFull,
                                              "subscriber table full");
      reply(r.peer, buf, n);
      return;
    }
    slot->used = true;
    slot->peer = r.peer;
    slot->until_us = now_us + static_cast<std::uint64_t>(sub_ms_) * 1000u;
    JsonWriter w(buf, sizeof buf);
    w.boolean("ok", true).str("cmd", "subscribe").uint("seq", r.seq).uint("expires_ms", sub_ms_);
    reply(r.peer, buf, w.finish());
  }

  int fd_;
  std::vector<Cidr> allow_;
  std::vector<Subscriber> subs_;
  std::uint32_t sub_ms_;
  std::uint16_t port_;
  bool loopback_bind_;
  UdpHostCounters c_{};
  hal::StatusMessage last_{};
  std::uint64_t last_now_us_ = 0;
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
