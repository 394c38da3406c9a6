// SocketCAN raw socket (hal::CanBus). Behaviour documented in docs/can.md "SocketCAN driver".
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include "dockcore/drivers/can_link.hpp"

namespace dockcore::drivers {

namespace {

constexpr std::uint64_t kBackoffMinUs = 100000;   // first reopen attempt 100 ms after the loss
constexpr std::uint64_t kBackoffMaxUs = 2000000;  // then doubling up to 2 s

std::uint64_t clock_us(clockid_t id) {
  timespec ts{};
  if (clock_gettime(id, &ts) != 0) return 0;
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000u + static_cast<std::uint64_t>(ts.tv_nsec) / 1000u;
}

std::string errno_text(const char* what, int err) {
  std::string s = what;
  s += ": ";
  s += std::strerror(err);
  return s;
}

// Interface state: 1 up, 0 down, -1 missing / error (message in `error`).
int interface_state(const std::string& name, std::string& error) {
  const int s = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (s < 0) {
    error = errno_text("socketcan: socket(AF_INET) for interface flags", errno);
    return -1;
  }
  ifreq ifr{};
  std::snprintf(ifr.ifr_name, IFNAMSIZ, "%s", name.c_str());
  const int rc = ioctl(s, SIOCGIFFLAGS, &ifr);
  const int err = errno;
  close(s);
  if (rc != 0) {
    error = "socketcan: interface '" + name + "': " + std::strerror(err);
    return -1;
  }
  return (ifr.ifr_flags & IFF_UP) ? 1 : 0;
}

class SocketCanBusImpl final : public SocketCanBus {
 public:
  SocketCanBusImpl(std::string iface, const std::uint32_t* ids, std::size_t n) : iface_(std::move(iface)) {
    for (std::size_t i = 0; i < n; ++i) ids_.push_back(ids[i]);
  }
  ~SocketCanBusImpl() override { close_socket(nullptr); }

  // Creates, configures and binds the socket. False with `error` set; the socket is closed again on failure.
  bool open_socket(std::string& error) {
    const int s = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (s < 0) {
      const int err = errno;
      if (err == EAFNOSUPPORT || err == EPROTONOSUPPORT) {
        error = "socketcan: kernel has no CAN support (socket(PF_CAN, SOCK_RAW, CAN_RAW): " +
                std::string(std::strerror(err)) + "); load the can and can-raw modules or use a kernel with CONFIG_CAN";
      } else {
        error = errno_text("socketcan: socket(PF_CAN, SOCK_RAW, CAN_RAW)", err);
      }
      return false;
    }
    fd_ = s;
    const unsigned idx = if_nametoindex(iface_.c_str());
    if (idx == 0) {
      error = "socketcan: no CAN interface '" + iface_ + "' (" + std::strerror(errno) + ")";
      close_socket(nullptr);
      return false;
    }
    if (!ids_.empty()) {
      std::vector<can_filter> f(ids_.size());
      for (std::size_t i = 0; i < ids_.size(); ++i) {
        f[i].can_id = ids_[i] & CAN_SFF_MASK;  // standard data frames only: EFF and RTR bits must be 0
        f[i].can_mask = CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG;
      }
      if (setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, f.data(), static_cast<socklen_t>(f.size() * sizeof(can_filter))) != 0) {
        error = errno_text("socketcan: setsockopt(CAN_RAW_FILTER)", errno);
        close_socket(nullptr);
        return false;
      }
    }
    const can_err_mask_t err_mask = CAN_ERR_TX_TIMEOUT | CAN_ERR_LOSTARB | CAN_ERR_CRTL | CAN_ERR_PROT | CAN_ERR_TRX |
                                    CAN_ERR_ACK | CAN_ERR_BUSOFF | CAN_ERR_BUSERROR | CAN_ERR_RESTARTED;
    if (setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask) != 0) {
      error = errno_text("socketcan: setsockopt(CAN_RAW_ERR_FILTER)", errno);
      close_socket(nullptr);
      return false;
    }
    const int one = 1;
    if (setsockopt(fd_, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof one) != 0) {
      error = errno_text("socketcan: setsockopt(SO_RXQ_OVFL)", errno);
      close_socket(nullptr);
      return false;
    }
    if (setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMP, &one, sizeof one) != 0) {
      error = errno_text("socketcan: setsockopt(SO_TIMESTAMP)", errno);
      close_socket(nullptr);
      return false;
    }
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = static_cast<int>(idx);
    if (bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
      error = errno_text(("socketcan: bind to '" + iface_ + "'").c_str(), errno);
      close_socket(nullptr);
      return false;
    }
    last_ovfl_ = 0;
    return true;
  }

  bool send(const CanFrame& frame) override {
    if (fd_ < 0 || frame.dlc > 8) {
      ++counters_.send_failures;
      return false;
    }
    can_frame cf{};
    cf.can_id = frame.extended ? ((frame.id & CAN_EFF_MASK) | CAN_EFF_FLAG) : (frame.id & CAN_SFF_MASK);
    cf.can_dlc = frame.dlc;
    std::memcpy(cf.data, frame.data, frame.dlc);
    const ssize_t n = write(fd_, &cf, sizeof cf);
    if (n == static_cast<ssize_t>(sizeof cf)) {
      ++counters_.frames_sent;
      return true;
    }
    ++counters_.send_failures;
    if (n < 0) {
      const int err = errno;
      if (err == ENOBUFS || err == EAGAIN) {
        ++enobufs_;  // queue full: the frame is dropped, the next tick sends a fresh one
      } else if (err == ENETDOWN || err == ENODEV || err == ENXIO) {
        lost(err);
      } else {
        error_ = errno_text("socketcan: write", err);
      }
    } else {
      error_ = "socketcan: short write";
    }
    return false;
  }

  bool receive(CanFrame& frame, std::uint64_t& stamp_us) override {
    while (fd_ >= 0) {
      can_frame cf{};
      iovec iov{&cf, sizeof cf};
      alignas(cmsghdr) char ctrl[CMSG_SPACE(sizeof(timeval)) + CMSG_SPACE(sizeof(std::uint32_t)) + 64];
      msghdr msg{};
      msg.msg_iov = &iov;
      msg.msg_iovlen = 1;
      msg.msg_control = ctrl;
      msg.msg_controllen = sizeof ctrl;
      const ssize_t n = recvmsg(fd_, &msg, MSG_DONTWAIT);
      if (n < 0) {
        const int err = errno;
        if (err == EAGAIN || err == EWOULDBLOCK || err == EINTR) return false;
        if (err == ENETDOWN || err == ENODEV || err == ENXIO) {
          lost(err);
        } else {
          error_ = errno_text("socketcan: recvmsg", err);
        }
        return false;
      }
      bool have_ts = false;
      timeval tv{};
      for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
        if (c->cmsg_level != SOL_SOCKET) continue;
        if (c->cmsg_type == SO_TIMESTAMP && c->cmsg_len >= CMSG_LEN(sizeof tv)) {
          std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
          have_ts = true;
        } else if (c->cmsg_type == SO_RXQ_OVFL && c->cmsg_len >= CMSG_LEN(sizeof(std::uint32_t))) {
          std::uint32_t drops = 0;  // cumulative count of frames the socket's queue dropped since it was opened
          std::memcpy(&drops, CMSG_DATA(c), sizeof drops);
          if (drops > last_ovfl_) counters_.rx_overflows += drops - last_ovfl_;
          last_ovfl_ = drops;
        }
      }
      if (n != static_cast<ssize_t>(sizeof cf)) continue;  // CAN FD or truncated: not ours, ignored
      const CanErrorReport err = decode_can_error_frame(cf.can_id, cf.data);
      if (err.error_frame) {
        ++counters_.bus_errors;
        if (err.bus_off) ++counters_.bus_off;
        error_ = err.message;
        continue;
      }
      if (cf.can_id & CAN_RTR_FLAG) continue;  // remote requests carry no data: no v1/AgileX frame uses them
      frame.extended = (cf.can_id & CAN_EFF_FLAG) != 0;
      frame.id = frame.extended ? (cf.can_id & CAN_EFF_MASK) : (cf.can_id & CAN_SFF_MASK);
      frame.dlc = cf.can_dlc > 8 ? 8 : cf.can_dlc;
      std::memset(frame.data, 0, sizeof frame.data);
      std::memcpy(frame.data, cf.data, frame.dlc);
      stamp_us = to_monotonic(have_ts, tv);
      ++counters_.frames_received;
      return true;
    }
    return false;
  }

  int fd() const override { return fd_; }
  const hal::CanBusCounters& counters() const override { return counters_; }

  void service(std::uint64_t now_us) override {
    if (fd_ >= 0) return;
    if (now_us < next_retry_us_) return;
    std::string err;
    const int st = interface_state(iface_, err);
    if (st == 1 && open_socket(err)) {
      ++counters_.reopens;
      backoff_us_ = kBackoffMinUs;
      error_.clear();
      return;
    }
    error_ = st == 0 ? "socketcan: interface '" + iface_ + "' is down" : err;
    next_retry_us_ = now_us + backoff_us_;
    backoff_us_ = backoff_us_ * 2 > kBackoffMaxUs ? kBackoffMaxUs : backoff_us_ * 2;
  }

  bool is_up() const override { return fd_ >= 0; }
  const char* last_error() const override { return error_.c_str(); }
  std::uint32_t enobufs() const { return enobufs_; }

 private:
  // The kernel stamps with CLOCK_REALTIME. The frame's age (realtime now - stamp) is subtracted from CLOCK_MONOTONIC
  // now; an age < 0 or > 10 s (wall clock stepped) falls back to monotonic now. The realtime reading sits between two
  // monotonic ones, and their midpoint is "now": a thread preempted between two clock reads (a loaded host) would
  // otherwise age the frame by the preemption. Frames leave one socket in order, so a stamp is never earlier than
  // the previous frame's.
  std::uint64_t to_monotonic(bool have_ts, const timeval& tv) {
    const std::uint64_t mono_before = clock_us(CLOCK_MONOTONIC);
    std::uint64_t mono = mono_before;
    if (have_ts) {
      const std::uint64_t real = clock_us(CLOCK_REALTIME);
      const std::uint64_t mono_after = clock_us(CLOCK_MONOTONIC);
      mono = mono_before + (mono_after - mono_before) / 2;
      const std::uint64_t stamp =
          static_cast<std::uint64_t>(tv.tv_sec) * 1000000u + static_cast<std::uint64_t>(tv.tv_usec);
      if (stamp <= real && real - stamp <= 10000000u && real - stamp <= mono) mono -= real - stamp;
    }
    if (mono < last_stamp_us_) mono = last_stamp_us_;
    last_stamp_us_ = mono;
    return mono;
  }

  void lost(int err) {
    error_ = errno_text(("socketcan: interface '" + iface_ + "' lost").c_str(), err);
    close_socket(nullptr);
    next_retry_us_ = 0;  // service() tries at once, then backs off
    backoff_us_ = kBackoffMinUs;
  }

  void close_socket(const char*) {
    if (fd_ >= 0) close(fd_);
    fd_ = -1;
  }

  std::string iface_;
  std::vector<std::uint32_t> ids_;
  int fd_ = -1;
  std::string error_;
  hal::CanBusCounters counters_{};
  std::uint32_t last_ovfl_ = 0;
  std::uint32_t enobufs_ = 0;
  std::uint64_t last_stamp_us_ = 0;  // the previous received frame's stamp (monotonic, µs)
  std::uint64_t next_retry_us_ = 0;
  std::uint64_t backoff_us_ = kBackoffMinUs;
};

}  // namespace

CanErrorReport decode_can_error_frame(std::uint32_t can_id, const std::uint8_t* data) {
  CanErrorReport r;
  if ((can_id & CAN_ERR_FLAG) == 0) return r;
  r.error_frame = true;
  r.bus_off = (can_id & CAN_ERR_BUSOFF) != 0;
  r.restarted = (can_id & CAN_ERR_RESTARTED) != 0;
  const std::uint8_t ctrl = data != nullptr ? data[1] : static_cast<std::uint8_t>(0);
  if (r.bus_off) {
    r.message = "socketcan: bus-off (the controller left the bus)";
  } else if (can_id & CAN_ERR_CRTL) {
    if (ctrl & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) {
      r.message = "socketcan: controller error passive";
    } else if (ctrl & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) {
      r.message = "socketcan: controller error warning";
    } else if (ctrl & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) {
      r.message = "socketcan: controller buffer overflow";
    } else {
      r.message = "socketcan: controller problem";
    }
  } else if (can_id & (CAN_ERR_PROT | CAN_ERR_BUSERROR)) {
    r.message = "socketcan: protocol violation / bus error";
  } else if (can_id & (CAN_ERR_TRX | CAN_ERR_ACK)) {
    r.message = "socketcan: transceiver problem or no ACK (nobody else on the bus?)";
  } else if (can_id & CAN_ERR_TX_TIMEOUT) {
    r.message = "socketcan: transmit timeout";
  } else if (can_id & CAN_ERR_LOSTARB) {
    r.message = "socketcan: lost arbitration";
  } else if (r.restarted) {
    r.message = "socketcan: controller restarted after bus-off";
  } else {
    r.message = "socketcan: error frame";
  }
  return r;
}

std::unique_ptr<SocketCanBus> open_socketcan(const std::string& interface, const std::uint32_t* rx_ids,
                                             std::size_t rx_id_count, std::string& error) {
  if (interface.empty() || interface.size() >= IFNAMSIZ) {
    error = "socketcan: bad interface name '" + interface + "'";
    return nullptr;
  }
  auto bus = std::make_unique<SocketCanBusImpl>(interface, rx_ids, rx_id_count);
  if (!bus->open_socket(error)) return nullptr;
  return bus;
}

}  // namespace dockcore::drivers
