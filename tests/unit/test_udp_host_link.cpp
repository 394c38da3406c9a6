// UDP host link on real 127.0.0.1 sockets (datagrams handed on with their sender, replies, allowlist, subscriber
// table), the flat JSON parser, and the camera datagram parser.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/drivers/flat_json.hpp"
#include "dockcore/drivers/udp_camera.hpp"
#include "dockcore/drivers/udp_host_link.hpp"

#include "CppUTest/TestHarness.h"

using namespace dockcore::drivers;

namespace {

struct Peer {
  int fd;
  explicit Peer(const char* bind_ip = "127.0.0.1") {
    fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    inet_pton(AF_INET, bind_ip, &a.sin_addr);
    ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  }
  ~Peer() { ::close(fd); }
  /// The bound port, host byte order.
  std::uint16_t port() const {
    sockaddr_in a{};
    socklen_t l = sizeof a;
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &l);
    return ntohs(a.sin_port);
  }
  void send(std::uint16_t port, const std::string& m) const {
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    to.sin_port = htons(port);
    ::sendto(fd, m.data(), m.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
  }
  std::string recv() const {
    char b[2048];
    const ssize_t n = ::recv(fd, b, sizeof b, MSG_DONTWAIT);
    return n > 0 ? std::string(b, static_cast<std::size_t>(n)) : std::string();
  }
};

std::unique_ptr<UdpHostLink> open_link(std::vector<std::string> allow = {}) {
  UdpHostLinkOptions o;
  o.port = 0;
  o.allowlist = std::move(allow);
  o.max_subscribers = 2;
  std::string err;
  auto l = open_udp_host_link(o, err);
  CHECK_TRUE(l != nullptr);
  return l;
}

}  // namespace

TEST_GROUP(FlatJson){};

TEST(FlatJson, ParsesFlatObjectsAndRefusesEverythingElse) {
  FlatJson j;
  const char ok[] = " {\"cmd\":\"dock\", \"dock_id\":3,\"x\":-1.5e2,\"b\":true,\"n\":null}\n";
  CHECK_EQUAL(static_cast<int>(FlatJsonError::kOk), static_cast<int>(j.parse(ok, sizeof ok - 1)));
  const char* s = nullptr;
  CHECK_TRUE(j.get_string("cmd", s));
  STRCMP_EQUAL("dock", s);
  std::int64_t v = 0;
  CHECK_TRUE(j.get_int("dock_id", 0, 10, v));
  CHECK_EQUAL(3, v);
  double x = 0;
  CHECK_TRUE(j.get_number("x", x));
  DOUBLES_EQUAL(-150.0, x, 1e-12);
  CHECK_FALSE(j.get_int("x", 0, 1000, v));
  bool b = false;
  CHECK_TRUE(j.get_bool("b", b) && b);
  struct Bad {
    const char* text;
    FlatJsonError e;
  } bad[] = {{"", FlatJsonError::kEmpty},
             {"{\"a\":{}}", FlatJsonError::kNested},
             {"{\"a\":[1]}", FlatJsonError::kNested},
             {"{\"a\":1,}", FlatJsonError::kSyntax},
             {"{\"a\":1", FlatJsonError::kSyntax},
             {"{\"a\":01}", FlatJsonError::kBadNumber},
             {"{\"a\":1.}", FlatJsonError::kBadNumber},
             {"{\"a\":tru}", FlatJsonError::kSyntax},
             {"{\"a\":\"\\u0041\"}", FlatJsonError::kBadEscape},
             {"{\"a\":1,\"a\":2}", FlatJsonError::kDuplicateKey},
             {"{\"a\":1} x", FlatJsonError::kSyntax},
             {"{\"aaaaaaaaaaaaaaaaaaaaaaaaaaaaa\":1}", FlatJsonError::kKeyTooLong}};
  for (const Bad& c : bad) {
    CHECK_EQUAL_TEXT(static_cast<int>(c.e), static_cast<int>(j.parse(c.text, std::strlen(c.text))), c.text);
    CHECK_EQUAL(0u, j.size());
  }
}

TEST_GROUP(UdpHostLink){};

TEST(UdpHostLink, HandsDatagramsOnWithTheirSenderAndRepliesToIt) {
  auto l = open_link();
  Peer p;
  p.send(l->bound_port(), "{\"cmd\":\"dock\",\"dock_id\":1,\"seq\":7}");
  dockcore::hal::HostDatagram d;
  CHECK_TRUE(l->poll_datagram(d, 1000));
  CHECK_EQUAL(std::strlen("{\"cmd\":\"dock\",\"dock_id\":1,\"seq\":7}"), d.len);
  CHECK_EQUAL(0, std::memcmp(d.data, "{\"cmd\":\"dock\",\"dock_id\":1,\"seq\":7}", d.len));
  CHECK_EQUAL(1000u, d.stamp_us);
  CHECK_EQUAL(htonl(INADDR_LOOPBACK), d.peer.addr_be);
  CHECK_TRUE(l->reply(d.peer, "{\"ok\":true}", 11));
  STRCMP_EQUAL("{\"ok\":true}\n", p.recv().c_str());
  // A longer datagram than the protocol takes: cut, with its real length, so the consumer can refuse it as such.
  p.send(l->bound_port(), std::string(600, ' '));
  CHECK_TRUE(l->poll_datagram(d, 2000));
  CHECK_EQUAL(600u, d.len);
  CHECK_FALSE(l->poll_datagram(d, 2000));
  CHECK_EQUAL(2u, l->counters().datagrams);
  CHECK_EQUAL(1u, l->counters().replies);
  // A reply that did not fit its writer (length 0) or leaves no room for the newline is a send failure.
  CHECK_FALSE(l->reply(d.peer, "", 0));
  const std::string big(kMaxHostReply, 'x');
  CHECK_FALSE(l->reply(d.peer, big.data(), big.size()));
  CHECK_EQUAL(2u, l->counters().send_failures);
}

TEST(UdpHostLink, DropsPeersOutsideTheAllowlistAndCountsThem) {
  auto l = open_link();
  Peer stranger("127.0.0.2");  // a different address of the loopback net: not 127.0.0.1, not allowlisted
  stranger.send(l->bound_port(), "{\"cmd\":\"stop\",\"seq\":1}");
  dockcore::hal::HostDatagram d;
  CHECK_FALSE(l->poll_datagram(d, 1000));
  CHECK_EQUAL(1u, l->counters().not_allowed);
  CHECK_EQUAL(0u, l->counters().datagrams);
  CHECK_EQUAL(0u, l->counters().replies);
  CHECK_TRUE(stranger.recv().empty());
  auto allowed = open_link({"127.0.0.2/32"});
  stranger.send(allowed->bound_port(), "{\"cmd\":\"stop\",\"seq\":2}");
  CHECK_TRUE(allowed->poll_datagram(d, 1000));
  CHECK_EQUAL(0, std::memcmp(d.data, "{\"cmd\":\"stop\",\"seq\":2}", d.len));
  CHECK_EQUAL(0u, allowed->counters().not_allowed);
}

TEST(UdpHostLink, RefusesNonLoopbackBindWithoutAllowlist) {
  UdpHostLinkOptions o;
  o.bind_address = "0.0.0.0";
  o.port = 0;
  std::string err;
  CHECK_TRUE(open_udp_host_link(o, err) == nullptr);
  STRCMP_CONTAINS("allowlist", err.c_str());
}

TEST(UdpHostLink, SubscriptionsAreBoundedAndExpire) {
  auto l = open_link();
  Peer a, b;
  const HostPeer pa{htonl(INADDR_LOOPBACK), htons(a.port())};
  const HostPeer pb{htonl(INADDR_LOOPBACK), htons(b.port())};
  const HostPeer pc{htonl(INADDR_LOOPBACK), 1};
  std::uint32_t ms = 0;
  CHECK_TRUE(l->subscribe(pa, 1000, ms));
  CHECK_EQUAL(10000u, ms);
  CHECK_TRUE(l->subscribe(pb, 1000, ms));
  CHECK_TRUE(l->subscribe(pa, 1000, ms));  // a renewal takes no second entry
  CHECK_FALSE(l->subscribe(pc, 1000, ms));
  CHECK_EQUAL(2u, l->subscriber_count());
  CHECK_EQUAL(1u, l->counters().subscribers_rejected);
  l->publish("{\"type\":\"status\"}", 17, 2000);
  STRCMP_EQUAL("{\"type\":\"status\"}\n", a.recv().c_str());
  STRCMP_EQUAL("{\"type\":\"status\"}\n", b.recv().c_str());
  CHECK_EQUAL(2u, l->counters().stream_sent);
  l->unsubscribe(pb);
  CHECK_EQUAL(1u, l->subscriber_count());
  l->publish("{\"type\":\"status\"}", 17, 1000 + 10000u * 1000u);  // past subscription_ms
  CHECK_EQUAL(0u, l->subscriber_count());
  CHECK_EQUAL(1u, l->counters().subscriptions_expired);
  CHECK_TRUE(b.recv().empty());
}

TEST_GROUP(UdpCamera){};

TEST(UdpCamera, ParsesDatagramsAndRejectsBadOnes) {
  dockcore::CameraTarget t;
  std::uint16_t id = 0;
  const char ok[] = "{\"stamp_us\":990000,\"u\":321.5,\"v\":240,\"id\":3,\"confidence\":0.9}";
  CHECK_EQUAL(static_cast<int>(CameraDatagramError::kOk),
              static_cast<int>(parse_camera_datagram(ok, sizeof ok - 1, 1000000, 500000, -1, t, id)));
  CHECK_TRUE(t.valid);
  DOUBLES_EQUAL(321.5, static_cast<double>(t.u_px), 1e-9);
  CHECK_EQUAL(990000u, t.stamp_us);
  CHECK_EQUAL(3, id);
  struct Bad {
    const char* text;
    CameraDatagramError e;
  } bad[] = {{"{\"u\":1,\"v\":2}", CameraDatagramError::kMissingField},
             {"{\"u\":1,\"v\":2,\"confidence\":1.5}", CameraDatagramError::kBadField},
             {"{\"u\":\"1\",\"v\":2,\"confidence\":1}", CameraDatagramError::kBadField},
             {"{\"u\":1,\"v\":2,\"confidence\":1,\"w\":0}", CameraDatagramError::kBadField},
             {"{\"u\":1,\"v\":2,\"confidence\":1,\"stamp_us\":1200000}", CameraDatagramError::kFuture},
             {"{\"u\":1,\"v\":2,\"confidence\":1,\"stamp_us\":100}", CameraDatagramError::kStale},
             {"u=1", CameraDatagramError::kMalformed}};
  for (const Bad& c : bad) {
    dockcore::CameraTarget u;
    CHECK_EQUAL_TEXT(static_cast<int>(c.e),
                     static_cast<int>(parse_camera_datagram(c.text, std::strlen(c.text), 1000000, 500000, -1, u, id)),
                     c.text);
    CHECK_FALSE(u.valid);
  }
  CHECK_EQUAL(static_cast<int>(CameraDatagramError::kWrongId),
              static_cast<int>(parse_camera_datagram(ok, sizeof ok - 1, 1000000, 500000, 4, t, id)));
}

TEST(UdpCamera, SocketKeepsNewestValidTargetAndCountsGarbage) {
  UdpCameraOptions o;
  o.port = 0;
  std::string err;
  auto cam = open_udp_camera(o, err);
  CHECK_TRUE(cam != nullptr);
  Peer p;
  p.send(cam->bound_port(), "{\"u\":100,\"v\":2,\"confidence\":0.5}");
  p.send(cam->bound_port(), "garbage");
  p.send(cam->bound_port(), "{\"u\":200,\"v\":2,\"confidence\":0.5}");
  dockcore::CameraTarget t;
  CHECK_TRUE(cam->poll_target(t));
  DOUBLES_EQUAL(200.0, static_cast<double>(t.u_px), 1e-9);
  CHECK_EQUAL(1u, cam->counters().malformed);
  CHECK_EQUAL(2u, cam->counters().accepted);
  CHECK_FALSE(cam->poll_target(t));
}

// the allowlist can change at runtime (config reload), checked as a whole and bounded.
TEST(UdpHostLink, AllowlistReplacedAtRuntimeAllOrNothingAndBounded) {
  auto l = open_link();
  Peer stranger("127.0.0.2");
  dockcore::hal::HostDatagram d;
  std::string err;
  CHECK_FALSE(l->set_allowlist({"127.0.0.2", "10.0.0.300"}, err));  // one bad entry: the old list stays
  STRCMP_CONTAINS("10.0.0.300", err.c_str());
  stranger.send(l->bound_port(), "{\"cmd\":\"stop\",\"seq\":1}");
  CHECK_FALSE(l->poll_datagram(d, 1000));
  CHECK_EQUAL(1u, l->counters().not_allowed);
  std::vector<std::string> many(kMaxHostAllowlist + 1, "10.0.0.1");
  CHECK_FALSE(l->set_allowlist(many, err));
  STRCMP_CONTAINS("at most 64", err.c_str());
  CHECK_TRUE(l->set_allowlist({"127.0.0.2/32"}, err));
  stranger.send(l->bound_port(), "{\"cmd\":\"stop\",\"seq\":2}");
  CHECK_TRUE(l->poll_datagram(d, 1000));
  CHECK_EQUAL(0, std::memcmp(d.data, "{\"cmd\":\"stop\",\"seq\":2}", d.len));
  CHECK_TRUE(l->set_allowlist({}, err));  // loopback bind: back to 127.0.0.1 only
  stranger.send(l->bound_port(), "{\"cmd\":\"stop\",\"seq\":3}");
  CHECK_FALSE(l->poll_datagram(d, 1000));
  CHECK_EQUAL(2u, l->counters().not_allowed);
  CHECK_EQUAL(0u, l->counters().replies);  // dropped peers never get a reply (no amplification)
}
