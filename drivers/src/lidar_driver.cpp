// Serial (termios) and UDP lidar drivers behind LidarDriver. Bytes go to core's parsers; the driver only moves
// bytes, stamps them with CLOCK_MONOTONIC and reopens vanished devices with exponential backoff.
#include "dockcore/drivers/lidar_driver.hpp"

#include <arpa/inet.h>
#include <asm/ioctls.h>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <vector>

#include "dockcore/protocols/lidar/lidar_lakibeam.hpp"
#include "dockcore/protocols/lidar/lidar_ld06.hpp"
#include "dockcore/protocols/lidar/lidar_rplidar.hpp"

// The kernel's termios2 (asm/termbits.h cannot be included together with <termios.h>): arbitrary baud rates via
// BOTHER for rates termios has no B constant for (RPLIDAR A2/A3's 256000).
struct termios2 {
  tcflag_t c_iflag;
  tcflag_t c_oflag;
  tcflag_t c_cflag;
  tcflag_t c_lflag;
  cc_t c_line;
  cc_t c_cc[19];
  speed_t c_ispeed;
  speed_t c_ospeed;
};

namespace dockcore::drivers {

std::optional<LidarProtocol> parse_lidar_protocol(std::string_view name) {
  if (name == "ld06" || name == "ld19") return LidarProtocol::kLd06;
  if (name == "rplidar") return LidarProtocol::kRplidar;
  if (name == "lakibeam") return LidarProtocol::kLakibeam;
  return std::nullopt;
}

const char* to_string(LidarProtocol p) {
  switch (p) {
    case LidarProtocol::kLd06: return "ld06";
    case LidarProtocol::kRplidar: return "rplidar";
    case LidarProtocol::kLakibeam: return "lakibeam";
  }
  return "?";
}

std::uint64_t monotonic_us() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);  // cannot fail for CLOCK_MONOTONIC with a valid pointer
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000u + static_cast<std::uint64_t>(ts.tv_nsec) / 1000u;
}

LidarDecoder::LidarDecoder(LidarProtocol protocol) : protocol_(protocol) {
  switch (protocol) {
    case LidarProtocol::kLd06:
      ld06_ = std::make_unique<Ld06Parser>();
      ld06_->configure(Ld06Config{});
      break;
    case LidarProtocol::kRplidar:
      rplidar_ = std::make_unique<RplidarParser>();
      rplidar_->configure(RplidarConfig{});
      break;
    case LidarProtocol::kLakibeam:
      lakibeam_ = std::make_unique<LakibeamParser>();
      lakibeam_->configure(LakibeamConfig{});
      break;
  }
}
LidarDecoder::~LidarDecoder() = default;

bool LidarDecoder::configure_grid(std::uint32_t bins_per_turn) {
  if (ld06_) {
    Ld06Config c = ld06_->config();
    c.bins_per_turn = bins_per_turn;
    return ld06_->configure(c);
  }
  if (rplidar_) {
    RplidarConfig c = rplidar_->config();
    c.bins_per_turn = bins_per_turn;
    return rplidar_->configure(c);
  }
  LakibeamConfig c = lakibeam_->config();
  c.bins_per_turn = bins_per_turn;
  return lakibeam_->configure(c);
}

void LidarDecoder::set_require_descriptor(bool require) {
  if (!rplidar_) return;
  RplidarConfig c = rplidar_->config();
  c.require_descriptor = require;
  rplidar_->configure(c);
}

std::size_t LidarDecoder::feed_bytes(const std::uint8_t* data, std::size_t n, std::uint64_t last_byte_us,
                                     std::uint32_t byte_period_us) {
  std::size_t scans = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t back = static_cast<std::uint64_t>(n - 1 - i) * byte_period_us;
    const std::uint64_t t = last_byte_us > back ? last_byte_us - back : 0;
    if (ld06_) {
      if (ld06_->feed(data[i], t)) ++scans;
    } else if (rplidar_) {
      if (rplidar_->feed(data[i], t)) ++scans;
    }
  }
  return scans;
}

std::size_t LidarDecoder::feed_datagram(const std::uint8_t* data, std::size_t n, std::uint64_t stamp_us) {
  if (lakibeam_) return lakibeam_->feed_datagram(data, n, stamp_us);
  return feed_bytes(data, n, stamp_us, 0);
}

const LaserScan* LidarDecoder::take_scan() {
  if (ld06_) return ld06_->take_scan();
  if (rplidar_) return rplidar_->take_scan();
  return lakibeam_->take_scan();
}

void LidarDecoder::reset() {
  if (ld06_) ld06_->reset();
  if (rplidar_) rplidar_->reset();
  if (lakibeam_) lakibeam_->reset();
}

const LidarParserCounters& LidarDecoder::counters() const {
  if (ld06_) return ld06_->counters();
  if (rplidar_) return rplidar_->counters();
  return lakibeam_->counters();
}

namespace {

speed_t baud_constant(std::uint32_t baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 500000: return B500000;
    case 576000: return B576000;
    case 921600: return B921600;
    case 1000000: return B1000000;
    case 1500000: return B1500000;
    case 2000000: return B2000000;
    default: return 0;
  }
}

constexpr tcflag_t kBother = 0010000;
constexpr tcflag_t kCbaud = 0010017;

std::string errno_text(const char* what, const std::string& arg) {
  return std::string(what) + " " + arg + ": " + std::strerror(errno);
}

void copy_hal_counters(const LidarParserCounters& p, std::uint32_t reconnects, hal::LidarCounters& h) {
  h.scans = p.scans;
  h.crc_errors = p.crc_errors;
  h.resyncs = p.resyncs;
  h.dropped_bytes = p.dropped_bytes;
  h.reconnects = reconnects;
}

class SerialLidarDriver final : public LidarDriver {
 public:
  explicit SerialLidarDriver(const LidarDriverOptions& o) : opt_(o), decoder_(o.protocol) {
    byte_period_us_ = o.baud > 0 ? static_cast<std::uint32_t>(10000000u / o.baud) : 0;
    if (o.bins_per_turn > 0) decoder_.configure_grid(o.bins_per_turn);
    delay_ms_ = o.reconnect_min_ms;
  }
  ~SerialLidarDriver() override { close_fd(); }

  const LaserScan* poll_scan() override {
    service(monotonic_us());
    return decoder_.take_scan();
  }
  int fd() const override { return fd_; }
  const hal::LidarCounters& counters() const override {
    copy_hal_counters(decoder_.counters(), reconnects_, hal_);
    return hal_;
  }
  LidarParserCounters parser_counters() const override { return decoder_.counters(); }
  bool connected() const override { return fd_ >= 0; }
  const char* last_error() const override { return error_.c_str(); }

  void service(std::uint64_t now_us) override {
    if (fd_ < 0) {
      if (now_us >= next_open_us_) try_open(now_us);
      if (fd_ < 0) return;
    }
    std::uint8_t buf[4096];
    for (int rounds = 0; rounds < 64; ++rounds) {
      const ssize_t n = ::read(fd_, buf, sizeof buf);
      if (n > 0) {
        if (opt_.raw_tap) opt_.raw_tap(buf, static_cast<std::size_t>(n));
        // The bytes still queued behind this chunk arrived after its last byte: stamp that byte as far back as
        // they take on the wire, so a reader running late still stamps scans with (about) the sensor's time.
        const std::uint64_t t = monotonic_us();
        const std::uint64_t behind = static_cast<std::uint64_t>(queued_bytes()) * byte_period_us_;
        decoder_.feed_bytes(buf, static_cast<std::size_t>(n), t > behind ? t - behind : 0, byte_period_us_);
        continue;
      }
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
      if (n < 0 && errno == EINTR) continue;
      // EOF, EIO (pty master closed, USB adapter unplugged) or any other error: the device vanished.
      error_ = n == 0 ? "end of file on " + opt_.device : errno_text("read", opt_.device);
      vanish(now_us);
      return;
    }
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, 0) > 0 && (p.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0 && (p.revents & POLLIN) == 0) {
      error_ = "hang-up on " + opt_.device;
      vanish(now_us);
    }
  }

  bool try_open(std::uint64_t now_us) {
    const int fd = ::open(opt_.device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
      error_ = errno_text("open", opt_.device);
      backoff(now_us);
      return false;
    }
    if (!configure_tty(fd)) {
      ::close(fd);
      backoff(now_us);
      return false;
    }
    fd_ = fd;
    if (ever_opened_) ++reconnects_;
    ever_opened_ = true;
    delay_ms_ = opt_.reconnect_min_ms;
    decoder_.reset();
    if (opt_.protocol == LidarProtocol::kRplidar) send_rplidar_start();
    return true;
  }

 private:
  /// Bytes waiting in the tty's line-discipline buffer (at most 4 KiB: n_tty's; more may wait in the kernel's flip
  /// buffers, which no ioctl reports); 0 when the driver cannot tell (stamps then fall back to the read time).
  std::size_t queued_bytes() const {
    int q = 0;
    if (::ioctl(fd_, FIONREAD, &q) != 0 || q < 0) return 0;
    return static_cast<std::size_t>(q);
  }

  bool configure_tty(int fd) {
    termios t{};
    if (::tcgetattr(fd, &t) != 0) {
      error_ = errno_text("tcgetattr", opt_.device);
      return false;
    }
    ::cfmakeraw(&t);
    t.c_cflag |= CLOCAL | CREAD;
    t.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | CRTSCTS);
    // VMIN 1 with O_NONBLOCK: an empty tty gives EAGAIN, so read() == 0 really means hang-up (VMIN 0 would return
    // 0 for "no data" and hide an unplugged adapter).
    t.c_cc[VMIN] = 1;
    t.c_cc[VTIME] = 0;
    const speed_t sp = baud_constant(opt_.baud);
    if (sp != 0) {
      if (::cfsetispeed(&t, sp) != 0 || ::cfsetospeed(&t, sp) != 0) {
        error_ = errno_text("cfsetspeed", opt_.device);
        return false;
      }
    }
    if (::tcsetattr(fd, TCSANOW, &t) != 0) {
      error_ = errno_text("tcsetattr", opt_.device);
      return false;
    }
    if (sp == 0) {  // non-standard rate: termios2 + BOTHER
      termios2 t2{};
      if (::ioctl(fd, TCGETS2, &t2) != 0) {
        error_ = errno_text("TCGETS2", opt_.device);
        return false;
      }
      t2.c_cflag = (t2.c_cflag & ~kCbaud) | kBother;
      t2.c_ispeed = t2.c_ospeed = opt_.baud;
      if (::ioctl(fd, TCSETS2, &t2) != 0) {
        error_ = errno_text("TCSETS2", opt_.device) + " (baud " + std::to_string(opt_.baud) + ")";
        return false;
      }
    }
    if (::tcflush(fd, TCIFLUSH) != 0) {
      error_ = errno_text("tcflush", opt_.device);
      return false;
    }
    return true;
  }

  void send_rplidar_start() {
    // STOP first: a sensor still scanning from a previous session must restart with a fresh descriptor.
    std::uint8_t req[4];
    rplidar_encode_request(kRplidarCmdStop, req);
    rplidar_encode_request(kRplidarCmdScan, req + 2);
    const ssize_t w = ::write(fd_, req, sizeof req);
    if (w != static_cast<ssize_t>(sizeof req)) {
      error_ = w < 0 ? errno_text("write SCAN request", opt_.device) : "short write of SCAN request";
      ++start_request_failures_;
    }
  }

  void backoff(std::uint64_t now_us) {
    next_open_us_ = now_us + static_cast<std::uint64_t>(delay_ms_) * 1000u;
    delay_ms_ = std::min(opt_.reconnect_max_ms, std::max<std::uint32_t>(1, delay_ms_) * 2);
  }
  void vanish(std::uint64_t now_us) {
    close_fd();
    decoder_.reset();
    delay_ms_ = opt_.reconnect_min_ms;
    backoff(now_us);
  }
  void close_fd() {
    if (fd_ >= 0) ::close(fd_);  // close errors leave nothing to recover on a read-only lidar tty
    fd_ = -1;
  }

  LidarDriverOptions opt_;
  LidarDecoder decoder_;
  mutable hal::LidarCounters hal_{};
  int fd_ = -1;
  bool ever_opened_ = false;
  std::uint32_t reconnects_ = 0;
  std::uint32_t start_request_failures_ = 0;
  std::uint32_t byte_period_us_ = 0;
  std::uint32_t delay_ms_ = 100;
  std::uint64_t next_open_us_ = 0;
  std::string error_;
};

class UdpLidarDriver final : public LidarDriver {
 public:
  explicit UdpLidarDriver(const LidarDriverOptions& o) : opt_(o), decoder_(o.protocol) {
    if (o.bins_per_turn > 0) decoder_.configure_grid(o.bins_per_turn);
  }
  ~UdpLidarDriver() override {
    if (fd_ >= 0) ::close(fd_);
  }
  bool open_socket(std::string& error) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(opt_.udp_port);
    if (::inet_pton(AF_INET, opt_.udp_bind_address.c_str(), &a.sin_addr) != 1) {
      error = "bad UDP bind address '" + opt_.udp_bind_address + "'";
      return false;
    }
    if (!opt_.udp_source_address.empty() && ::inet_pton(AF_INET, opt_.udp_source_address.c_str(), &source_) != 1) {
      error = "bad UDP source address '" + opt_.udp_source_address + "'";
      return false;
    }
    fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd_ < 0) {
      error = errno_text("socket", "udp");
      return false;
    }
    const int one = 1;
    if (::setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0) {
      error = errno_text("setsockopt SO_REUSEADDR", "udp");
      return false;
    }
    // The kernel's receive time of each datagram: a backlog that waited in the socket while dockd did not run is
    // stamped when it arrived, not when it was read, so dockd's watchdog does not take it for fresh data. A kernel
    // (or emulator: qemu-user) without SO_TIMESTAMPNS gets SO_TIMESTAMP; without either, the time of reading.
    receive_stamps_ = ::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof one) == 0 ||
                      ::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMP, &one, sizeof one) == 0;
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
      error = errno_text("bind", opt_.udp_bind_address + ":" + std::to_string(opt_.udp_port));
      return false;
    }
    sockaddr_in bound{};
    socklen_t len = sizeof bound;
    if (::getsockname(fd_, reinterpret_cast<sockaddr*>(&bound), &len) != 0) {
      error = errno_text("getsockname", "udp");
      return false;
    }
    port_ = ntohs(bound.sin_port);
    return true;
  }
  const LaserScan* poll_scan() override {
    service(monotonic_us());
    return decoder_.take_scan();
  }
  int fd() const override { return fd_; }
  const hal::LidarCounters& counters() const override {
    copy_hal_counters(decoder_.counters(), 0, hal_);
    hal_.foreign_datagrams = foreign_;
    return hal_;
  }
  LidarParserCounters parser_counters() const override { return decoder_.counters(); }
  bool connected() const override { return fd_ >= 0; }
  const char* last_error() const override { return error_.c_str(); }
  std::uint16_t bound_port() const override { return port_; }
  bool receive_stamps() const override { return receive_stamps_; }

  void service(std::uint64_t) override {
    if (fd_ < 0) return;
    for (int rounds = 0; rounds < 256; ++rounds) {
      sockaddr_in from{};
      iovec iov{buf_.data(), buf_.size()};
      alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec)) + CMSG_SPACE(sizeof(timeval))];
      msghdr msg{};
      msg.msg_name = &from;
      msg.msg_namelen = sizeof from;
      msg.msg_iov = &iov;
      msg.msg_iovlen = 1;
      msg.msg_control = control;
      msg.msg_controllen = sizeof control;
      const ssize_t n = ::recvmsg(fd_, &msg, 0);
      if (n < 0) {
        if (errno == EAGAIN || errno == EWOULDBLOCK) break;
        if (errno == EINTR) continue;
        error_ = errno_text("recvmsg", "udp");
        break;
      }
      if (!opt_.udp_source_address.empty() && (from.sin_family != AF_INET || from.sin_addr.s_addr != source_.s_addr)) {
        ++foreign_;
        continue;
      }
      // buf_ holds the largest UDP payload, so n is the datagram's true size and a wrong-size Lakibeam datagram
      // is rejected (and counted) by the parser.
      const std::size_t len = std::min(static_cast<std::size_t>(n), buf_.size());
      if (opt_.raw_tap) opt_.raw_tap(buf_.data(), len);
      decoder_.feed_datagram(buf_.data(), len, arrival_us(msg));
    }
  }

 private:
  LidarDriverOptions opt_;
  LidarDecoder decoder_;
  mutable hal::LidarCounters hal_{};
  /// The datagram's kernel receive time (SCM_TIMESTAMPNS or SCM_TIMESTAMP, CLOCK_REALTIME) on the monotonic clock;
  /// the time of reading when the kernel gave none or it lies in the future (a wall-clock step).
  static std::uint64_t arrival_us(const msghdr& msg) {
    const std::uint64_t now_mono = monotonic_us();
    for (const cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(const_cast<msghdr*>(&msg), const_cast<cmsghdr*>(c))) {
      if (c->cmsg_level != SOL_SOCKET) continue;
      timespec rx{};
      if (c->cmsg_type == SCM_TIMESTAMPNS) {
        std::memcpy(&rx, CMSG_DATA(c), sizeof rx);
      } else if (c->cmsg_type == SCM_TIMESTAMP) {
        timeval tv{};
        std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
        rx.tv_sec = tv.tv_sec;
        rx.tv_nsec = static_cast<long>(tv.tv_usec) * 1000;
      } else {
        continue;
      }
      timespec now{};
      clock_gettime(CLOCK_REALTIME, &now);
      const std::int64_t age_ns = (static_cast<std::int64_t>(now.tv_sec) - static_cast<std::int64_t>(rx.tv_sec)) *
                                      1000000000 + (now.tv_nsec - rx.tv_nsec);
      if (age_ns <= 0) return now_mono;
      const std::uint64_t age_us = static_cast<std::uint64_t>(age_ns / 1000);
      return now_mono > age_us ? now_mono - age_us : 0;
    }
    return now_mono;
  }

  int fd_ = -1;
  std::uint16_t port_ = 0;
  bool receive_stamps_ = false;  // the kernel stamps each datagram (SO_TIMESTAMPNS / SO_TIMESTAMP)
  in_addr source_{};            // opt_.udp_source_address, parsed (when set)
  std::uint32_t foreign_ = 0;   // datagrams from another source, dropped
  std::vector<std::uint8_t> buf_ = std::vector<std::uint8_t>(65536);
  std::string error_;
};

}  // namespace

std::unique_ptr<LidarDriver> make_lidar_driver(const LidarDriverOptions& options, std::string& error) {
  if (options.bins_per_turn > kMaxScanPoints) {
    error = "bins_per_turn must be <= " + std::to_string(kMaxScanPoints);
    return nullptr;
  }
  if (options.transport == LidarTransport::kSerial) {
    if (options.protocol == LidarProtocol::kLakibeam) {
      error = "Lakibeam1 speaks UDP only";
      return nullptr;
    }
    if (options.baud == 0 || options.baud > 4000000) {
      error = "unsupported baud rate " + std::to_string(options.baud);
      return nullptr;
    }
    auto d = std::make_unique<SerialLidarDriver>(options);
    d->try_open(monotonic_us());  // a missing device is retried by service()
    return d;
  }
  if (options.protocol == LidarProtocol::kRplidar) {
    error = "RPLIDAR A1/A2 speak serial only";
    return nullptr;
  }
  auto d = std::make_unique<UdpLidarDriver>(options);
  if (!d->open_socket(error)) return nullptr;
  return d;
}

}  // namespace dockcore::drivers
