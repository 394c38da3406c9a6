#include "dockcore/drivers/udp_camera.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "dockcore/drivers/flat_json.hpp"

namespace dockcore::drivers {

const char* to_string(CameraDatagramError e) {
  switch (e) {
    case CameraDatagramError::kOk: return "ok";
    case CameraDatagramError::kTooLong: return "too_long";
    case CameraDatagramError::kMalformed: return "malformed";
    case CameraDatagramError::kMissingField: return "missing_field";
    case CameraDatagramError::kBadField: return "bad_field";
    case CameraDatagramError::kFuture: return "future";
    case CameraDatagramError::kStale: return "stale";
    case CameraDatagramError::kWrongId: return "wrong_id";
  }
  return "?";
}

CameraDatagramError parse_camera_datagram(const char* data, std::size_t len, std::uint64_t now_us,
                                          std::uint64_t max_age_us, std::int32_t expected_id, CameraTarget& out,
                                          std::uint16_t& id_out) {
  if (len > kMaxCameraDatagram) return CameraDatagramError::kTooLong;
  FlatJson j;
  if (j.parse(data, len) != FlatJsonError::kOk) return CameraDatagramError::kMalformed;
  for (std::size_t i = 0; i < j.size(); ++i) {
    const char* k = j.key(i);
    if (std::strcmp(k, "stamp_us") != 0 && std::strcmp(k, "u") != 0 && std::strcmp(k, "v") != 0 &&
        std::strcmp(k, "id") != 0 && std::strcmp(k, "confidence") != 0) {
      return CameraDatagramError::kBadField;
    }
  }
  if (!j.has("u") || !j.has("v") || !j.has("confidence")) return CameraDatagramError::kMissingField;
  double u = 0, v = 0, conf = 0;
  if (!j.get_number("u", u) || !j.get_number("v", v) || !j.get_number("confidence", conf)) {
    return CameraDatagramError::kBadField;
  }
  if (u < -1e5 || u > 1e5 || v < -1e5 || v > 1e5 || conf < 0 || conf > 1) return CameraDatagramError::kBadField;
  std::int64_t id = 0;
  if (j.has("id") && !j.get_int("id", 0, 65535, id)) return CameraDatagramError::kBadField;
  std::int64_t stamp = 0;
  // 2^53: every integer up to it is exact in the double the number passes through.
  if (j.has("stamp_us") && !j.get_int("stamp_us", 0, 9007199254740992LL, stamp)) return CameraDatagramError::kBadField;
  std::uint64_t t = stamp == 0 ? now_us : static_cast<std::uint64_t>(stamp);
  if (t > now_us + 100000u) return CameraDatagramError::kFuture;
  if (now_us > t && now_us - t > max_age_us) return CameraDatagramError::kStale;
  if (expected_id >= 0 && id != expected_id) return CameraDatagramError::kWrongId;
  out.valid = true;
  out.u_px = static_cast<Real>(u);
  out.v_px = static_cast<Real>(v);
  out.confidence = static_cast<Real>(conf);
  out.stamp_us = t;
  id_out = static_cast<std::uint16_t>(id);
  return CameraDatagramError::kOk;
}

namespace {

class UdpCameraImpl final : public UdpCamera {
 public:
  UdpCameraImpl(int fd, const UdpCameraOptions& o, std::uint16_t port) : fd_(fd), opt_(o), port_(port) {}
  ~UdpCameraImpl() override {
    if (fd_ >= 0) ::close(fd_);
  }

  void service(std::uint64_t now_us) override {
    for (int i = 0; i < 64; ++i) {
      char buf[kMaxCameraDatagram + 1];
      sockaddr_in from{};
      socklen_t fl = sizeof from;
      const ssize_t n = ::recvfrom(fd_, buf, sizeof buf, MSG_TRUNC, reinterpret_cast<sockaddr*>(&from), &fl);
      if (n < 0) return;
      if (from.sin_family != AF_INET || from.sin_addr.s_addr != htonl(INADDR_LOOPBACK)) {
        ++c_.not_allowed;
        continue;
      }
      ++c_.datagrams;
      CameraTarget t;
      std::uint16_t id = 0;
      const CameraDatagramError e =
          parse_camera_datagram(buf, static_cast<std::size_t>(n), now_us,
                                static_cast<std::uint64_t>(opt_.max_age_ms) * 1000u, opt_.target_id, t, id);
      switch (e) {
        case CameraDatagramError::kOk:
          ++c_.accepted;
          if (!have_ || t.stamp_us >= latest_.stamp_us) {
            latest_ = t;
            have_ = true;
          }
          break;
        case CameraDatagramError::kStale:
        case CameraDatagramError::kFuture: ++c_.stale; break;
        case CameraDatagramError::kWrongId: ++c_.wrong_id; break;
        default: ++c_.malformed; break;
      }
    }
  }

  bool poll_target(CameraTarget& out) override {
    timespec ts{};
    ::clock_gettime(CLOCK_MONOTONIC, &ts);
    service(static_cast<std::uint64_t>(ts.tv_sec) * 1000000u + static_cast<std::uint64_t>(ts.tv_nsec) / 1000u);
    if (!have_) return false;
    out = latest_;
    have_ = false;
    return true;
  }
  int fd() const override { return fd_; }
  const UdpCameraCounters& counters() const override { return c_; }
  std::uint16_t bound_port() const override { return port_; }

 private:
  int fd_;
  UdpCameraOptions opt_;
  std::uint16_t port_;
  UdpCameraCounters c_{};
  CameraTarget latest_{};
  bool have_ = false;
};

}  // namespace

std::unique_ptr<UdpCamera> open_udp_camera(const UdpCameraOptions& o, std::string& error) {
  in_addr a{};
  if (inet_pton(AF_INET, o.bind_address.c_str(), &a) != 1) {
    error = "camera: bind address '" + o.bind_address + "' is not an IPv4 address";
    return nullptr;
  }
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    error = std::string("camera: socket: ") + std::strerror(errno);
    return nullptr;
  }
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_addr = a;
  sa.sin_port = htons(o.port);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0) {
    error = "camera: bind " + o.bind_address + ":" + std::to_string(o.port) + ": " + std::strerror(errno);
    ::close(fd);
    return nullptr;
  }
  socklen_t sl = sizeof sa;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&sa), &sl);
  return std::make_unique<UdpCameraImpl>(fd, o, ntohs(sa.sin_port));
}

}  // namespace dockcore::drivers
