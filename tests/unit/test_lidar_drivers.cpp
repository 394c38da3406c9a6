// Lidar drivers against a real pty pair (openpty; the driver opens a symlink to the slave) and a UDP socket on
// 127.0.0.1: scans arrive with monotonic stamps, the device vanishing and coming back is survived (reconnect
// counted, RPLIDAR start request re-sent), bad options are refused.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <pty.h>
#include <asm/ioctls.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/drivers/lidar_driver.hpp"
#include "dockcore/protocols/lidar/lidar_lakibeam.hpp"
#include "dockcore/protocols/lidar/lidar_ld06.hpp"
#include "dockcore/protocols/lidar/lidar_rplidar.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using namespace dockcore::drivers;

namespace {

// The kernel's termios2 (asm/termbits.h clashes with <termios.h>), only to probe whether TCGETS2 exists here.
struct termios2 {
  tcflag_t c_iflag, c_oflag, c_cflag, c_lflag;
  cc_t c_line;
  cc_t c_cc[19];
  speed_t c_ispeed, c_ospeed;
};

struct Pty {
  int master = -1, slave = -1;
  std::string link;
  bool open(const std::string& path) {
    char name[128];
    if (::openpty(&master, &slave, name, nullptr, nullptr) != 0) return false;
    termios t{};
    ::tcgetattr(slave, &t);
    ::cfmakeraw(&t);
    ::tcsetattr(slave, TCSANOW, &t);
    ::fcntl(master, F_SETFL, ::fcntl(master, F_GETFL) | O_NONBLOCK);
    link = path;
    ::unlink(path.c_str());
    return ::symlink(name, path.c_str()) == 0;
  }
  void close() {
    if (master >= 0) ::close(master);
    if (slave >= 0) ::close(slave);
    master = slave = -1;
    ::unlink(link.c_str());
  }
  ~Pty() { close(); }
};

LaserScan test_scan(std::size_t n) {
  LaserScan s;
  s.reset(n, -kPi, kTwoPi / static_cast<Real>(n), 0);
  for (std::size_t i = 0; i < n; ++i) s.ranges_m[i] = 1.0 + 0.001 * static_cast<Real>(i);
  return s;
}

std::vector<std::uint8_t> ld06_turns(int turns) {
  auto scan = std::make_unique<LaserScan>(test_scan(450));
  Ld06StreamEncoder enc;
  enc.configure(LidarAngleConvention{true, 0}, 3600);
  std::vector<std::uint8_t> b(turns * 40 * 47 + 47);
  std::size_t n = 0;
  for (int t = 0; t < turns; ++t) n += enc.encode_scan(scan->view(), 0, b.data() + n, b.size() - n);
  b.resize(n);
  return b;
}

// Writes everything (the pty buffer is small) while servicing the driver so it drains it.
void pump(int fd, const std::vector<std::uint8_t>& bytes, LidarDriver& d, int* scans, LaserScan& out) {
  std::size_t off = 0;
  for (int guard = 0; off < bytes.size() && guard < 100000; ++guard) {
    const ssize_t w = ::write(fd, bytes.data() + off, std::min<std::size_t>(512, bytes.size() - off));
    if (w > 0) off += static_cast<std::size_t>(w);
    ::usleep(200);
    if (const LaserScan* sc = d.poll_scan()) {
      out = *sc;
      ++*scans;
    }
  }
  for (int i = 0; i < 20; ++i) {
    ::usleep(1000);
    if (const LaserScan* sc = d.poll_scan()) {
      out = *sc;
      ++*scans;
    }
  }
}

const std::string kLink = "/tmp/dockcore-test-lidar-" + std::to_string(::getpid());

}  // namespace

TEST_GROUP(LidarDrivers){};

TEST(LidarDrivers, SerialLd06ScansAndReconnect) {
  Pty pty;
  CHECK(pty.open(kLink));
  LidarDriverOptions o;
  o.device = kLink;
  o.reconnect_min_ms = 10;
  o.reconnect_max_ms = 40;
  std::string err;
  auto d = make_lidar_driver(o, err);
  CHECK(d != nullptr);
  CHECK(d->connected());
  CHECK(d->fd() >= 0);
  auto out = std::make_unique<LaserScan>();
  int scans = 0;
  const std::uint64_t t0 = monotonic_us();
  pump(pty.master, ld06_turns(3), *d, &scans, *out);
  CHECK(scans >= 1);
  CHECK_EQUAL(2u, d->counters().scans);
  CHECK_EQUAL(0u, d->counters().crc_errors);
  // Bytes are stamped back from their read at the wire rate (43 µs per byte at 230400); a pty delivers faster
  // than the wire, so a 4 KiB read can reach up to ~180 ms before t0.
  CHECK(out->stamp_us + 200000 >= t0 && out->stamp_us <= monotonic_us());
  DOUBLES_EQUAL(1.0, out->ranges_m[0], 0.0006);

  // Unplug: the driver sees the hang-up, closes, then reopens once the device is back.
  pty.close();
  for (int i = 0; i < 50 && d->connected(); ++i) {
    d->service(monotonic_us());
    ::usleep(2000);
  }
  CHECK_FALSE(d->connected());
  CHECK_EQUAL(-1, d->fd());
  CHECK(std::strlen(d->last_error()) > 0);
  Pty again;
  CHECK(again.open(kLink));
  for (int i = 0; i < 100 && !d->connected(); ++i) {
    d->service(monotonic_us());
    ::usleep(2000);
  }
  CHECK(d->connected());
  CHECK_EQUAL(1u, d->counters().reconnects);
  pump(again.master, ld06_turns(3), *d, &scans, *out);
  CHECK_EQUAL(4u, d->counters().scans);
}

TEST(LidarDrivers, SerialRplidarSendsStopAndScanAfterOpen) {
  Pty pty;
  CHECK(pty.open(kLink));
  LidarDriverOptions o;
  o.protocol = LidarProtocol::kRplidar;
  o.device = kLink;
  o.baud = 256000;  // no B constant: termios2 / BOTHER path
  {
    // qemu-user (the armhf stage of tools/test) does not translate the TCGETS2/TCSETS2 ioctls; a real ARM kernel
    // does. Where the platform lacks them the driver rightly refuses 256000, so the request path is tested at a
    // standard rate there, and the BOTHER path on the platforms that have it (x86-64 natively, aarch64).
    termios2 t2{};
    if (::ioctl(pty.slave, TCGETS2, &t2) != 0) {
      std::printf("\n  (TCGETS2 unsupported here (%s): testing the RPLIDAR requests at 115200)\n", std::strerror(errno));
      o.baud = 115200;
    }
  }
  std::string err;
  auto d = make_lidar_driver(o, err);
  CHECK(d != nullptr);
  CHECK(d->connected());
  std::uint8_t req[8] = {};
  ::usleep(2000);
  const ssize_t n = ::read(pty.master, req, sizeof req);
  CHECK_EQUAL(4, n);
  CHECK_EQUAL(0xA5, req[0]);
  CHECK_EQUAL(0x25, req[1]);
  CHECK_EQUAL(0xA5, req[2]);
  CHECK_EQUAL(0x20, req[3]);
  auto scan = std::make_unique<LaserScan>(test_scan(360));
  RplidarEncoder enc;
  enc.configure(LidarAngleConvention{true, kPi});
  std::vector<std::uint8_t> bytes(7 + 3 * 360 * 5 + 5);
  std::size_t k = RplidarEncoder::write_descriptor(bytes.data());
  for (int t = 0; t < 3; ++t) k += enc.encode_scan(scan->view(), bytes.data() + k, bytes.size() - k);
  bytes.resize(k);
  auto out = std::make_unique<LaserScan>();
  int scans = 0;
  pump(pty.master, bytes, *d, &scans, *out);
  CHECK_EQUAL(2u, d->counters().scans);
  CHECK_EQUAL(1u, d->parser_counters().descriptors);
}

namespace {

LidarDriverOptions udp_lakibeam_options() {
  LidarDriverOptions o;
  o.protocol = LidarProtocol::kLakibeam;
  o.transport = LidarTransport::kUdp;
  o.udp_bind_address = "127.0.0.1";
  o.udp_port = 0;
  return o;
}

/// A UDP socket bound to `addr` (any loopback address: all of 127/8 is local), or unbound for nullptr.
int udp_sender(const char* addr) {
  const int s = ::socket(AF_INET, SOCK_DGRAM, 0);
  if (addr != nullptr) {
    sockaddr_in b{};
    b.sin_family = AF_INET;
    ::inet_pton(AF_INET, addr, &b.sin_addr);
    CHECK_EQUAL(0, ::bind(s, reinterpret_cast<const sockaddr*>(&b), sizeof b));
  }
  return s;
}

/// Sends `turns` Lakibeam turns of a 1440-bin test scan from socket `s` to 127.0.0.1:port; returns the datagrams sent.
int send_lakibeam_turns(int s, std::uint16_t port, int turns) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  auto scan = std::make_unique<LaserScan>(test_scan(1440));
  LakibeamEncoder enc;
  enc.configure(LidarAngleConvention{false, -kPi});
  struct Ctx {
    int s;
    sockaddr_in a;
    int sent;
  } ctx{s, a, 0};
  for (int t = 0; t < turns; ++t)
    enc.encode_scan(scan->view(), 0, [](const std::uint8_t* p, std::size_t n, void* u) {
      auto* c = static_cast<Ctx*>(u);
      if (::sendto(c->s, p, n, 0, reinterpret_cast<const sockaddr*>(&c->a), sizeof c->a) == static_cast<ssize_t>(n))
        ++c->sent;
    }, &ctx);
  return ctx.sent;
}

}  // namespace

TEST(LidarDrivers, UdpLakibeamOnLoopback) {
  std::string err;
  auto d = make_lidar_driver(udp_lakibeam_options(), err);
  CHECK(d != nullptr);
  CHECK(d->bound_port() != 0);
  const int s = udp_sender(nullptr);
  CHECK(send_lakibeam_turns(s, d->bound_port(), 3) > 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(d->bound_port());
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const std::uint8_t junk[100] = {};
  ::sendto(s, junk, sizeof junk, 0, reinterpret_cast<const sockaddr*>(&a), sizeof a);
  ::close(s);
  const std::uint64_t sent_us = monotonic_us();
  // Read 150 ms late (a reader that stalled): the scans are stamped with the kernel's receive time, not the read.
  ::usleep(150000);
  auto out = std::make_unique<LaserScan>();
  const std::uint64_t read_us = monotonic_us();
  const LaserScan* got = d->poll_scan();
  CHECK(got != nullptr);
  *out = *got;
  CHECK_EQUAL(2u, d->counters().scans);
  CHECK_EQUAL(1u, d->parser_counters().bad_packets);
  CHECK_EQUAL(100u, d->counters().dropped_bytes);
  CHECK_EQUAL(1440u, out->count);
  if (d->receive_stamps()) {
    CHECK(out->stamp_us <= sent_us);
    CHECK(out->stamp_us + 100000 < read_us);
  } else {
    // qemu-user (the cross stages) implements neither SO_TIMESTAMPNS nor SO_TIMESTAMP: stamped when read.
    std::printf("\n  (no kernel receive stamps here: the UDP backlog stamp is not tested)\n");
    CHECK(out->stamp_us >= read_us);
  }
}

TEST(LidarDrivers, UdpSourceFilterDropsAndCountsForeignDatagrams) {
  LidarDriverOptions o = udp_lakibeam_options();
  o.udp_source_address = "127.0.0.1";
  std::string err;
  auto d = make_lidar_driver(o, err);
  CHECK_TEXT(d != nullptr, err.c_str());
  // Two senders on loopback: the sensor's address (127.0.0.1) and another host's (127.0.0.2).
  const int sensor = udp_sender("127.0.0.1"), intruder = udp_sender("127.0.0.2");
  // The intruder sends three whole turns first: none may become a scan.
  const int foreign = send_lakibeam_turns(intruder, d->bound_port(), 3);
  ::usleep(5000);
  CHECK(d->poll_scan() == nullptr);
  CHECK(foreign > 0);
  CHECK_EQUAL(static_cast<std::uint32_t>(foreign), d->counters().foreign_datagrams);
  CHECK_EQUAL(0u, d->parser_counters().bytes);  // dropped unread: the parser never saw them
  CHECK(send_lakibeam_turns(sensor, d->bound_port(), 3) > 0);
  ::usleep(5000);
  CHECK(d->poll_scan() != nullptr);
  CHECK_EQUAL(2u, d->counters().scans);
  CHECK_EQUAL(static_cast<std::uint32_t>(foreign), d->counters().foreign_datagrams);
  ::close(sensor);
  ::close(intruder);
  o.udp_source_address = "lidar.local";
  CHECK(make_lidar_driver(o, err) == nullptr);
  STRCMP_CONTAINS("bad UDP source address", err.c_str());
}

TEST(LidarDrivers, BadOptionsAreRefused) {
  std::string err;
  LidarDriverOptions o;
  o.protocol = LidarProtocol::kLakibeam;
  CHECK(make_lidar_driver(o, err) == nullptr);
  CHECK(!err.empty());
  o = LidarDriverOptions{};
  o.transport = LidarTransport::kUdp;
  o.udp_bind_address = "not-an-address";
  CHECK(make_lidar_driver(o, err) == nullptr);
  o = LidarDriverOptions{};
  o.device = "/nonexistent/tty";
  auto d = make_lidar_driver(o, err);
  CHECK(d != nullptr);  // retried later, not an error
  CHECK_FALSE(d->connected());
  CHECK(std::strstr(d->last_error(), "/nonexistent/tty") != nullptr);
  CHECK(parse_lidar_protocol("rplidar").has_value());
  CHECK_FALSE(parse_lidar_protocol("velodyne").has_value());
}
