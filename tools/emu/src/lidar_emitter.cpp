#include "dockcore/emu/lidar_emitter.hpp"

#include <arpa/inet.h>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <deque>
#include <fcntl.h>
#include <netinet/in.h>
#include <pty.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include "dockcore/protocols/lidar/lidar_lakibeam.hpp"
#include "dockcore/protocols/lidar/lidar_ld06.hpp"
#include "dockcore/protocols/lidar/lidar_rplidar.hpp"

namespace dockcore::emu {

struct LidarEmitter::Impl {
  Ld06StreamEncoder ld06;
  RplidarEncoder rplidar;
  LakibeamEncoder lakibeam;
  std::vector<std::uint8_t> bytes;
  struct Queued {
    std::uint64_t due_us;
    std::vector<std::uint8_t> bytes;
    bool last_of_turn;
  };
  std::deque<Queued> queue;  ///< Paced mode: packets not yet due.
};

bool parse_emu_protocol(const std::string& name, EmuProtocol* out) {
  if (name == "ld06" || name == "ld19") *out = EmuProtocol::kLd06;
  else if (name == "rplidar") *out = EmuProtocol::kRplidar;
  else if (name == "lakibeam") *out = EmuProtocol::kLakibeam;
  else return false;
  return true;
}

namespace {
std::string sys_error(const char* what) { return std::string(what) + ": " + std::strerror(errno); }
}  // namespace

LidarEmitter::LidarEmitter(const LidarEmitterOptions& options) : opt_(options), impl_(std::make_unique<Impl>()) {
  rng_state_ = options.seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull;
  const double dps = std::round(360.0 * options.rate_hz);
  impl_->ld06.configure(LidarAngleConvention{true, 0},
                        static_cast<std::uint16_t>(dps < 0 ? 0 : (dps > 65535 ? 65535 : dps)));
  impl_->rplidar.configure(LidarAngleConvention{true, kPi});
  impl_->lakibeam.configure(LidarAngleConvention{false, -kPi});
  impl_->bytes.reserve(64 * 1024);
}

std::unique_ptr<LidarEmitter> LidarEmitter::open(const LidarEmitterOptions& options, std::string& error) {
  if (options.corrupt_fraction < 0 || options.corrupt_fraction > 1 || options.corrupt_packet_fraction < 0 ||
      options.corrupt_packet_fraction > 1 || options.drop_fraction < 0 ||
      options.drop_fraction > 1) {
    error = "corrupt/drop fractions must be in [0, 1]";
    return nullptr;
  }
  if (!(options.rate_hz > 0)) {
    error = "rate_hz must be > 0";
    return nullptr;
  }
  std::unique_ptr<LidarEmitter> e(new LidarEmitter(options));
  if (options.udp_port != 0) {
    if (options.protocol == EmuProtocol::kRplidar) {
      error = "RPLIDAR is emulated on a pty only";
      return nullptr;
    }
    if (!e->open_udp(error)) return nullptr;
  } else {
    if (options.protocol == EmuProtocol::kLakibeam) {
      error = "Lakibeam is emulated over UDP only (give a UDP destination)";
      return nullptr;
    }
    if (!e->open_pty(error)) return nullptr;
  }
  if (options.protocol == EmuProtocol::kRplidar && !options.rplidar_wait_for_scan_request) {
    e->rplidar_scanning_ = true;
    e->rplidar_need_descriptor_ = true;
  }
  return e;
}

LidarEmitter::~LidarEmitter() {
  unplug();
  if (udp_fd_ >= 0) ::close(udp_fd_);
}

bool LidarEmitter::open_pty(std::string& error) {
  int m = -1, s = -1;
  char name[256] = {};
  if (::openpty(&m, &s, name, nullptr, nullptr) != 0) {
    error = sys_error("openpty");
    return false;
  }
  termios t{};
  if (::tcgetattr(s, &t) != 0) {
    error = sys_error("tcgetattr on pty slave");
    ::close(m);
    ::close(s);
    return false;
  }
  ::cfmakeraw(&t);
  if (::tcsetattr(s, TCSANOW, &t) != 0) {
    error = sys_error("tcsetattr on pty slave");
    ::close(m);
    ::close(s);
    return false;
  }
  const int fl = ::fcntl(m, F_GETFL);
  if (fl < 0 || ::fcntl(m, F_SETFL, fl | O_NONBLOCK) != 0 || ::fcntl(m, F_SETFD, FD_CLOEXEC) != 0 ||
      ::fcntl(s, F_SETFD, FD_CLOEXEC) != 0) {
    error = sys_error("fcntl on pty");
    ::close(m);
    ::close(s);
    return false;
  }
  if (!opt_.pty_link.empty()) {
    struct stat st {};
    if (::lstat(opt_.pty_link.c_str(), &st) == 0) {
      if (!S_ISLNK(st.st_mode)) {
        error = opt_.pty_link + " exists and is not a symlink";
        ::close(m);
        ::close(s);
        return false;
      }
      if (::unlink(opt_.pty_link.c_str()) != 0) {
        error = sys_error(("unlink " + opt_.pty_link).c_str());
        ::close(m);
        ::close(s);
        return false;
      }
    }
    if (::symlink(name, opt_.pty_link.c_str()) != 0) {
      error = sys_error(("symlink " + opt_.pty_link).c_str());
      ::close(m);
      ::close(s);
      return false;
    }
  }
  master_fd_ = m;
  // Keeping the slave open means writes never fail with EIO while no reader is attached (bytes then just fill the
  // pty buffer and overflow into bytes_unwritten, like a sensor talking to nobody).
  slave_fd_ = s;
  slave_path_ = name;
  return true;
}

bool LidarEmitter::open_udp(std::string& error) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(opt_.udp_port);
  if (::inet_pton(AF_INET, opt_.udp_host.c_str(), &a.sin_addr) != 1) {
    error = "bad UDP host '" + opt_.udp_host + "' (IPv4 literal expected)";
    return false;
  }
  udp_fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (udp_fd_ < 0) {
    error = sys_error("socket");
    return false;
  }
  if (::connect(udp_fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    error = sys_error("connect");
    ::close(udp_fd_);
    udp_fd_ = -1;
    return false;
  }
  return true;
}

void LidarEmitter::unplug() {
  if (master_fd_ >= 0) ::close(master_fd_);
  if (slave_fd_ >= 0) ::close(slave_fd_);
  master_fd_ = slave_fd_ = -1;
  slave_path_.clear();
  if (!opt_.pty_link.empty()) ::unlink(opt_.pty_link.c_str());  // may already be gone
  if (opt_.protocol == EmuProtocol::kRplidar && opt_.rplidar_wait_for_scan_request) rplidar_scanning_ = false;
}

bool LidarEmitter::replug(std::string& error) {
  if (udp_fd_ >= 0) return true;
  unplug();
  return open_pty(error);
}

double LidarEmitter::uniform() {
  // splitmix64: deterministic for the seed, independent of the simulator's RNG streams.
  std::uint64_t z = (rng_state_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-53;
}

void LidarEmitter::service_requests() {
  if (opt_.protocol != EmuProtocol::kRplidar || master_fd_ < 0) return;
  std::uint8_t in[256];
  for (;;) {
    const ssize_t n = ::read(master_fd_, in, sizeof in);
    if (n <= 0) break;  // EAGAIN (nothing pending) or EIO (no reader): nothing to answer
    for (ssize_t i = 0; i + 1 < n; ++i) {
      if (in[i] != kRplidarSync) continue;
      ++stats_.requests_seen;
      const std::uint8_t cmd = in[i + 1];
      if (cmd == kRplidarCmdScan) {
        rplidar_scanning_ = true;
        rplidar_need_descriptor_ = true;
      } else if (cmd == kRplidarCmdStop || cmd == kRplidarCmdReset) {
        rplidar_scanning_ = false;
      } else if (cmd == kRplidarCmdGetHealth) {
        std::vector<std::uint8_t> h(kRplidarDescriptorBytes + kRplidarHealthBytes);
        RplidarEncoder::write_health(RplidarHealth{}, h.data());
        write_bytes(h);
      }
      ++i;
    }
  }
}

bool LidarEmitter::emit_scan(const ScanView& scan) {
  service_requests();
  const bool rp_idle = opt_.protocol == EmuProtocol::kRplidar && !rplidar_scanning_;
  // The sensor's clock: the scan's own stamp when it has one (chassis-sim stamps a scan with the time it renders it;
  // a simulator that runs late renders late, and its sensor clock must say so, or dockd would take the late turn
  // for a backlog), else one turn period per scan. It runs on while nothing is sent (stall, unplugged).
  if (scan.stamp_us != 0) {
    ms_ = scan.stamp_us / 1000u;
  } else {
    ms_ += static_cast<std::uint64_t>(std::llround(1000.0 / opt_.rate_hz));
  }
  if (stalled_ || !plugged() || rp_idle) {
    ++stats_.scans_suppressed;
    return false;
  }
  std::vector<std::uint8_t>& b = impl_->bytes;
  switch (opt_.protocol) {
    case EmuProtocol::kLd06: {
      b.resize(static_cast<std::size_t>(scan_points_per_turn(scan) / 12 + 2) * kLd06PacketBytes);
      const std::size_t n = impl_->ld06.encode_scan(scan, static_cast<std::uint16_t>(ms_ % 30000u), b.data(), b.size());
      send_stream_packets(b.data(), n, kLd06PacketBytes, scan.stamp_us);
      break;
    }
    case EmuProtocol::kRplidar: {
      std::vector<std::uint8_t> out;
      if (rplidar_need_descriptor_) {
        out.resize(kRplidarDescriptorBytes);
        RplidarEncoder::write_descriptor(out.data());
        write_bytes(out);
        rplidar_need_descriptor_ = false;
      }
      b.resize(static_cast<std::size_t>(scan_points_per_turn(scan)) * kRplidarNodeBytes);
      const std::size_t n = impl_->rplidar.encode_scan(scan, b.data(), b.size());
      send_stream_packets(b.data(), n, kRplidarNodeBytes, scan.stamp_us);
      break;
    }
    case EmuProtocol::kLakibeam: {
      impl_->lakibeam.encode_scan(
          scan, static_cast<std::uint32_t>(ms_ * 1000u),
          [](const std::uint8_t* d, std::size_t n, void* user) { static_cast<LidarEmitter*>(user)->send_datagram(d, n); },
          this);
      break;
    }
  }
  ++stats_.scans;
  return true;
}

void LidarEmitter::send_stream_packets(const std::uint8_t* data, std::size_t n, std::size_t packet_bytes,
                                       std::uint64_t stamp_us) {
  std::vector<std::uint8_t> out;
  out.reserve(n);
  const bool paced = opt_.paced && stamp_us != 0 && udp_fd_ < 0 && n >= packet_bytes;
  const std::size_t count = n / packet_bytes;
  const double turn_us = 1e6 / opt_.rate_hz;
  for (std::size_t off = 0, k = 0; off + packet_bytes <= n; off += packet_bytes, ++k) {
    ++stats_.packets;
    if (opt_.drop_fraction > 0 && uniform() < opt_.drop_fraction) {
      ++stats_.packets_dropped;
      continue;
    }
    out.insert(out.end(), data + off, data + off + packet_bytes);
    if (opt_.corrupt_packet_fraction > 0 && uniform() < opt_.corrupt_packet_fraction) {
      auto& x = out[out.size() - packet_bytes + static_cast<std::size_t>(uniform() * static_cast<double>(packet_bytes))];
      x = static_cast<std::uint8_t>(x ^ (1u << static_cast<unsigned>(uniform() * 8)));
      ++stats_.bytes_corrupted;
    }
    if (paced) {
      const auto due = stamp_us + static_cast<std::uint64_t>(turn_us * static_cast<double>(k + 1) / static_cast<double>(count));
      impl_->queue.push_back({due, std::move(out), k + 1 == count});
      out = std::vector<std::uint8_t>();
    }
  }
  if (paced) return;
  if (udp_fd_ >= 0) {
    // LD06 over UDP: ten packets per datagram.
    const std::size_t chunk = 10 * packet_bytes;
    for (std::size_t off = 0; off < out.size(); off += chunk) {
      std::vector<std::uint8_t> d(out.begin() + static_cast<long>(off),
                                  out.begin() + static_cast<long>(std::min(out.size(), off + chunk)));
      for (auto& x : d)
        if (opt_.corrupt_fraction > 0 && uniform() < opt_.corrupt_fraction) {
          x = static_cast<std::uint8_t>(x ^ (1u << static_cast<unsigned>(uniform() * 8)));
          ++stats_.bytes_corrupted;
        }
      const ssize_t w = ::send(udp_fd_, d.data(), d.size(), 0);
      if (w == static_cast<ssize_t>(d.size())) stats_.bytes_written += d.size();
      else stats_.bytes_unwritten += d.size();
    }
    note_turn_written();
    return;
  }
  write_bytes(out);
  note_turn_written();
}

void LidarEmitter::note_turn_written() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  stats_.last_turn_written_wall_us = static_cast<std::int64_t>(ts.tv_sec) * 1000000 + ts.tv_nsec / 1000;
}

void LidarEmitter::pump(std::uint64_t now_us) {
  auto& q = impl_->queue;
  if (q.empty()) return;
  if (stalled_ || !plugged()) {
    stats_.paced_packets_discarded += q.size();
    q.clear();
    return;
  }
  std::vector<std::uint8_t> out;
  bool turn_done = false;
  while (!q.empty() && q.front().due_us <= now_us) {
    if (now_us - q.front().due_us > 30000u) ++stats_.paced_packets_late;
    out.insert(out.end(), q.front().bytes.begin(), q.front().bytes.end());
    turn_done = turn_done || q.front().last_of_turn;
    q.pop_front();
  }
  if (!out.empty()) write_bytes(out);
  if (turn_done) note_turn_written();
}

void LidarEmitter::write_bytes(std::vector<std::uint8_t>& bytes) {
  if (master_fd_ < 0) {
    stats_.bytes_unwritten += bytes.size();
    return;
  }
  for (auto& x : bytes)
    if (opt_.corrupt_fraction > 0 && uniform() < opt_.corrupt_fraction) {
      x = static_cast<std::uint8_t>(x ^ (1u << static_cast<unsigned>(uniform() * 8)));
      ++stats_.bytes_corrupted;
    }
  if (line_filter_) line_filter_(bytes);
  std::size_t off = 0;
  while (off < bytes.size()) {
    const ssize_t w = ::write(master_fd_, bytes.data() + off, bytes.size() - off);
    if (w > 0) {
      off += static_cast<std::size_t>(w);
      continue;
    }
    if (w < 0 && errno == EINTR) continue;
    break;  // EAGAIN: pty buffer full (nobody reading fast enough); anything else: treat the same, never block
  }
  stats_.bytes_written += off;
  stats_.bytes_unwritten += bytes.size() - off;
}

void LidarEmitter::send_datagram(const std::uint8_t* data, std::size_t n) {
  ++stats_.packets;
  if (opt_.drop_fraction > 0 && uniform() < opt_.drop_fraction) {
    ++stats_.packets_dropped;
    return;
  }
  std::vector<std::uint8_t> d(data, data + n);
  if (opt_.corrupt_packet_fraction > 0 && uniform() < opt_.corrupt_packet_fraction) {
    auto& x = d[static_cast<std::size_t>(uniform() * static_cast<double>(n))];
    x = static_cast<std::uint8_t>(x ^ (1u << static_cast<unsigned>(uniform() * 8)));
    ++stats_.bytes_corrupted;
  }
  for (auto& x : d)
    if (opt_.corrupt_fraction > 0 && uniform() < opt_.corrupt_fraction) {
      x = static_cast<std::uint8_t>(x ^ (1u << static_cast<unsigned>(uniform() * 8)));
      ++stats_.bytes_corrupted;
    }
  const ssize_t w = ::send(udp_fd_, d.data(), d.size(), 0);
  if (w == static_cast<ssize_t>(n)) stats_.bytes_written += n;
  else stats_.bytes_unwritten += n;
}

}  // namespace dockcore::emu
