// dockd: builds the real drivers from the config and runs the epoll loop around dockd::Daemon (daemon.hpp).
// Exit codes: 0 stopped by SIGTERM/SIGINT (after zero-velocity frames) or --check-config OK; 1 runtime failure
// (event loop error; zero frames are sent first); 2 usage or config error (file:line:column: message);
// 3 a device could not be opened at start (CAN interface, lidar options, UDP ports).
#include <sys/epoll.h>
#include <sys/signalfd.h>
#include <sys/socket.h>
#include <sys/timerfd.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#ifdef DOCKD_HAVE_SYSTEMD
#include <systemd/sd-daemon.h>
#else
#include <sys/un.h>
#include <unistd.h>
#endif

#include "config.hpp"
#include "daemon.hpp"
#include "dockcore/drivers/can_link.hpp"
#include "dockcore/drivers/lidar_driver.hpp"
#include "dockcore/drivers/udp_camera.hpp"
#include "session_record.hpp"
#ifdef DOCKD_HAVE_VISION
#include "dockcore/drivers/camera_pipeline.hpp"
#include "dockcore/drivers/v4l2_camera.hpp"
#endif
#include "dockcore/drivers/udp_host_link.hpp"

namespace {

std::uint64_t mono_us() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000u + static_cast<std::uint64_t>(ts.tv_nsec) / 1000u;
}

// How the previous session in the record directory ended: its events.jsonl ends with a "shutdown" event when dockd
// stopped cleanly. Anything else (SIGKILL, power loss, a crash) is an interrupted session: dockd reports it at start
// (event previous_session, stderr) and, like after any start, stays idle until a new command. Reads the last 64 KiB.
struct PreviousSession {
  bool found = false;        // a non-empty event log exists
  bool interrupted = false;  // its last event is not "shutdown"
  bool torn = false;         // its last line has no newline (cut mid-write)
  std::string last_event, last_state;
};

std::string json_field(const std::string& line, const char* key) {
  const std::string k = std::string("\"") + key + "\":\"";
  const auto p = line.find(k);
  if (p == std::string::npos) return "";
  const auto b = p + k.size();
  const auto e = line.find('"', b);
  return e == std::string::npos ? "" : line.substr(b, e - b);
}

PreviousSession read_previous_session(const std::string& dir) {
  PreviousSession ps;
  std::FILE* f = std::fopen((dir + "/events.jsonl").c_str(), "rb");
  if (f == nullptr) return ps;
  std::string tail;
  if (std::fseek(f, 0, SEEK_END) == 0) {
    const long size = std::ftell(f);
    const long from = size > 65536 ? size - 65536 : 0;
    std::fseek(f, from, SEEK_SET);
    tail.resize(static_cast<std::size_t>(size - from));
    tail.resize(std::fread(&tail[0], 1, tail.size(), f));
  }
  std::fclose(f);
  if (tail.empty()) return ps;
  ps.found = true;
  ps.torn = tail.back() != '\n';
  std::size_t pos = 0;
  while (pos < tail.size()) {
    std::size_t nl = tail.find('\n', pos);
    if (nl == std::string::npos) break;  // a torn last line is not an event
    const std::string line = tail.substr(pos, nl - pos);
    pos = nl + 1;
    const std::string ev = json_field(line, "event");
    if (ev.empty()) continue;
    ps.last_event = ev;
    if (ev == "state") ps.last_state = json_field(line, "to");
  }
  ps.interrupted = ps.last_event != "shutdown";
  return ps;
}

class MonotonicClock final : public dockcore::hal::Clock {
 public:
  std::uint64_t now_us() const override { return mono_us(); }
};

// DEVELOPMENT ONLY ([can] interface = "fake" plus --allow-fake-can): a bus with nothing on it. Frames sent are
// accepted (and recorded) but no chassis ever answers, so the chassis watchdog holds the robot at zero velocity and
// any task faults with 184. It exists to run dockd's process-level tests on a kernel without CAN; it can never
// make dockd drive.
class NoChassisBus final : public dockcore::hal::CanBus {
 public:
  bool send(const dockcore::CanFrame&) override {
    ++c_.frames_sent;
    return true;
  }
  bool receive(dockcore::CanFrame&, std::uint64_t&) override { return false; }
  int fd() const override { return -1; }
  const dockcore::hal::CanBusCounters& counters() const override { return c_; }

 private:
  dockcore::hal::CanBusCounters c_{};
};

#ifndef DOCKD_HAVE_SYSTEMD
// Without libsystemd (e.g. a cross build whose sysroot lacks it) dockd still speaks the notify protocol itself, so
// the Type=notify unit works on every target: one datagram to $NOTIFY_SOCKET (a path, or '@' for the abstract
// namespace), as sd_notify(3) documents.
void sd_notify_fallback(const char* what) {
  const char* path = std::getenv("NOTIFY_SOCKET");
  if (path == nullptr || (path[0] != '/' && path[0] != '@') || std::strlen(path) >= sizeof(sockaddr_un::sun_path))
    return;
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return;
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  const std::size_t n = std::strlen(path);
  std::memcpy(addr.sun_path, path, n);
  if (addr.sun_path[0] == '@') addr.sun_path[0] = '\0';
  const socklen_t len = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + n);
  if (::sendto(fd, what, std::strlen(what), MSG_NOSIGNAL, reinterpret_cast<const sockaddr*>(&addr), len) < 0) {
    std::fprintf(stderr, "dockd: sd_notify to %s: %s\n", path, std::strerror(errno));
  }
  ::close(fd);
}

// sd_watchdog_enabled(3) without libsystemd: WATCHDOG_USEC, and WATCHDOG_PID when set must be this process.
std::uint64_t watchdog_usec_from_env() {
  const char* usec = std::getenv("WATCHDOG_USEC");
  if (usec == nullptr) return 0;
  const char* pid = std::getenv("WATCHDOG_PID");
  if (pid != nullptr && std::strtol(pid, nullptr, 10) != static_cast<long>(::getpid())) return 0;
  return std::strtoull(usec, nullptr, 10);
}
#endif

void notify(const char* what) {
#ifdef DOCKD_HAVE_SYSTEMD
  sd_notify(0, what);
#else
  sd_notify_fallback(what);
#endif
}

enum Tag : std::uint64_t { kTimer = 1, kSignal, kLidar, kCan, kHost, kCamera, kCameraOwn };

struct Registration {
  int fd = -1;
};

bool epoll_set(int ep, Registration& reg, int fd, Tag tag) {
  if (reg.fd == fd) return true;
  if (reg.fd >= 0) ::epoll_ctl(ep, EPOLL_CTL_DEL, reg.fd, nullptr);  // may already be closed: harmless
  reg.fd = -1;
  if (fd < 0) return true;
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.u64 = tag;
  if (::epoll_ctl(ep, EPOLL_CTL_ADD, fd, &ev) != 0) return false;
  reg.fd = fd;
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"dockd: autonomous docking daemon (lidar + CAN chassis + host link). docs/dockd.md"};
  std::string config_path, log_level, record_dir;
  bool check_only = false, foreground = false, allow_fake_can = false;
  app.add_option("--config,-c", config_path, "TOML configuration file")->required();
  app.add_flag("--check-config", check_only, "validate the configuration and exit (0 valid, 2 invalid)");
  app.add_option("--log-level", log_level, "error | warn | info | debug (overrides [log] level)")
      ->check(CLI::IsMember({"error", "warn", "info", "debug"}));
  app.add_option("--record-dir", record_dir, "session record directory (overrides [record] dir)");
  bool record_loop = false;
  app.add_flag("--record-loop", record_loop,
               "also record every call into the core to DIR/loop.rec, for dock-sim replay (sets [record] loop)");
  app.add_flag("--foreground", foreground, "stay in the foreground (dockd never forks; accepted for init scripts)");
  app.add_flag("--allow-fake-can", allow_fake_can,
               "DEVELOPMENT ONLY: permit [can] interface = \"fake\" (no chassis; the robot never moves)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }

  dockd::DockdConfig cfg;
  try {
    cfg = dockd::load_config_file(config_path);
  } catch (const dockd::ConfigError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  if (!log_level.empty()) dockd::parse_log_level(log_level, cfg.log_level);
  if (!record_dir.empty()) cfg.record_dir = record_dir;
  if (record_loop) cfg.record_loop = true;
  if (cfg.can_interface == "fake" && !allow_fake_can) {
    std::fprintf(stderr, "%s: [can] interface = \"fake\" is for development only and needs --allow-fake-can\n",
                 config_path.c_str());
    return 2;
  }
  if (check_only) {
    std::string cam;
    if (cfg.camera_device.enabled) {
      const auto& d = cfg.camera_device;
      cam = ", camera " + d.capture.device + " " + std::to_string(d.capture.width_px) + "x" +
            std::to_string(d.capture.height_px) + " " + dockcore::drivers::to_string(d.capture.format) + " " +
            d.tag.family;
    }
    std::printf("%s: valid (%zu dock(s), controller %s, CAN %s %s, lidar %s%s)\n", config_path.c_str(),
                cfg.docks.size(), cfg.controller.c_str(), cfg.can_interface.c_str(),
                dockcore::drivers::to_string(cfg.can.protocol), dockcore::drivers::to_string(cfg.lidar.protocol),
                cam.c_str());
    return 0;
  }

  // Signals go through signalfd: block them before any thread or fd exists.
  sigset_t sigs;
  sigemptyset(&sigs);
  sigaddset(&sigs, SIGTERM);
  sigaddset(&sigs, SIGINT);
  sigaddset(&sigs, SIGHUP);
  sigprocmask(SIG_BLOCK, &sigs, nullptr);
  std::signal(SIGPIPE, SIG_IGN);

  // Session record.
  dockd::RotatingLog can_log, event_log;
  PreviousSession previous;
  if (!cfg.record_dir.empty()) {
    previous = read_previous_session(cfg.record_dir);
    std::string err;
    if (!can_log.open(cfg.record_dir, "can.log", cfg.record_max_bytes, cfg.record_max_files, err) ||
        !event_log.open(cfg.record_dir, "events.jsonl", cfg.record_max_bytes, cfg.record_max_files, err)) {
      std::fprintf(stderr, "dockd: session record: %s\n", err.c_str());
      return 3;
    }
  }

  // CAN.
  std::unique_ptr<dockcore::drivers::SocketCanBus> socketcan;
  NoChassisBus fake_bus;
  dockcore::hal::CanBus* raw_bus = nullptr;
  if (cfg.can_interface == "fake") {
    std::fprintf(stderr,
                 "dockd: WARNING: [can] interface = \"fake\": DEVELOPMENT ONLY, no chassis attached; the "
                 "robot will not move and every task faults (184)\n");
    raw_bus = &fake_bus;
  } else {
    std::uint32_t ids[64];
    const std::size_t n = dockcore::drivers::can_link_rx_ids(cfg.can, ids, 64);
    std::string err;
    socketcan = dockcore::drivers::open_socketcan(cfg.can_interface, ids, n, err);
    if (!socketcan) {
      std::fprintf(stderr, "dockd: cannot open CAN interface '%s': %s\n", cfg.can_interface.c_str(), err.c_str());
      return 3;
    }
    raw_bus = socketcan.get();
  }
  dockd::RecordingCanBus bus(*raw_bus, can_log, cfg.can_interface);
  std::unique_ptr<dockcore::drivers::CanLink> can = dockcore::drivers::make_can_link(bus, cfg.can);

  // Lidar.
  std::string err;
  std::unique_ptr<dockcore::drivers::LidarDriver> lidar = dockcore::drivers::make_lidar_driver(cfg.lidar, err);
  if (!lidar) {
    std::fprintf(stderr, "dockd: lidar: %s\n", err.c_str());
    return 3;
  }
  if (!lidar->connected()) {
    std::fprintf(stderr, "dockd: lidar %s not connected yet (%s); retrying\n", cfg.lidar.device.c_str(),
                 lidar->last_error());
  }

  // Host and camera.
  std::unique_ptr<dockcore::drivers::UdpHostLink> host;
  if (cfg.host_enabled) {
    host = dockcore::drivers::open_udp_host_link(cfg.host, err);
    if (!host) {
      std::fprintf(stderr, "dockd: %s\n", err.c_str());
      return 3;
    }
  }
  std::unique_ptr<dockcore::drivers::UdpCamera> camera;
  if (cfg.camera_enabled) {
    camera = dockcore::drivers::open_udp_camera(cfg.camera, err);
    if (!camera) {
      std::fprintf(stderr, "dockd: %s\n", err.c_str());
      return 3;
    }
  }

  // dockd's own camera (docs/camera.md): V4L2 capture and the AprilTag detector on their own thread (created here,
  // after the signals were blocked, so it inherits the mask), feeding the same camera target as the datagram.
#ifdef DOCKD_HAVE_VISION
  std::unique_ptr<dockcore::drivers::TagDetector> tag_detector;
  std::unique_ptr<dockcore::drivers::V4l2Camera> v4l2;
  std::unique_ptr<dockcore::drivers::CameraPipeline> camera_own;
  if (cfg.camera_device.enabled) {
    tag_detector = dockcore::drivers::TagDetector::create(cfg.camera_device.tag, err);
    if (!tag_detector) {
      std::fprintf(stderr, "%s: camera.tag: %s\n", config_path.c_str(), err.c_str());
      return 2;
    }
    v4l2 = dockcore::drivers::open_v4l2_camera(cfg.camera_device.capture, err);
    if (!v4l2) {
      std::fprintf(stderr, "dockd: %s\n", err.c_str());
      return 3;
    }
    if (!v4l2->connected()) {
      std::fprintf(stderr, "dockd: %s; retrying\n", v4l2->last_error());
    }
    dockcore::drivers::CameraPipelineOptions po;
    po.target_id = cfg.camera.target_id;
    po.max_age_ms = cfg.camera.max_age_ms;
    po.full_confidence_margin = cfg.camera_device.full_confidence_margin;
    camera_own = dockcore::drivers::CameraPipeline::start(*v4l2, *tag_detector, po, err);
    if (!camera_own) {
      std::fprintf(stderr, "dockd: %s\n", err.c_str());
      return 3;
    }
  }
#else
  if (cfg.camera_device.enabled) {
    std::fprintf(stderr,
                 "%s: [camera.device]: this dockd was built without libapriltag (tools/setup-deps installs "
                 "libapriltag-dev)\n",
                 config_path.c_str());
    return 2;
  }
#endif

  MonotonicClock clock;
  dockd::DaemonIo io;
  io.lidar = lidar.get();
  io.chassis = can.get();
  io.can_host = can.get();
  io.udp_host = host.get();
  io.camera = camera.get();
#ifdef DOCKD_HAVE_VISION
  io.camera_own = camera_own.get();
  io.tags = camera_own.get();
  io.camera_frames = camera_own.get();
  io.camera_status = camera_own.get();
#endif
  io.clock = &clock;
  io.event_log = &event_log;
  io.stderr_level = cfg.log_level;
  auto daemon = std::make_unique<dockd::Daemon>(cfg, io);
  if (!daemon->start(err)) {
    std::fprintf(stderr, "dockd: %s\n", err.c_str());
    return 2;
  }
  if (previous.found && previous.interrupted) {
    // Reported, never resumed: the robot waits for a new host command.
    dockd::EventLine e(mono_us(), "previous_session");
    e.w.boolean("clean", false)
        .str_cut("last_event", previous.last_event.c_str(), 40)
        .str_cut("last_state", previous.last_state.c_str(), 40)
        .boolean("torn_line", previous.torn)
        .str("action", "idle until a new command");
    daemon->log_event(e, dockd::LogLevel::kWarn);
  }

  // Event loop.
  const int ep = ::epoll_create1(EPOLL_CLOEXEC);
  const int tfd = ::timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
  const int sfd = ::signalfd(-1, &sigs, SFD_NONBLOCK | SFD_CLOEXEC);
  if (ep < 0 || tfd < 0 || sfd < 0) {
    std::fprintf(stderr, "dockd: epoll/timerfd/signalfd: %s\n", std::strerror(errno));
    daemon->send_zero(mono_us(), 5);
    return 1;
  }
  itimerspec its{};
  its.it_interval.tv_nsec = 20 * 1000 * 1000;  // 50 Hz
  its.it_value.tv_nsec = 20 * 1000 * 1000;
  ::timerfd_settime(tfd, 0, &its, nullptr);
  Registration r_timer, r_sig, r_lidar, r_can, r_host, r_cam;
  bool ok = epoll_set(ep, r_timer, tfd, kTimer) && epoll_set(ep, r_sig, sfd, kSignal) &&
            epoll_set(ep, r_can, bus.fd(), kCan) && epoll_set(ep, r_lidar, lidar->fd(), kLidar);
  if (host) ok = ok && epoll_set(ep, r_host, host->fd(), kHost);
  if (camera) ok = ok && epoll_set(ep, r_cam, camera->fd(), kCamera);
#ifdef DOCKD_HAVE_VISION
  Registration r_cam_own;
  if (camera_own) ok = ok && epoll_set(ep, r_cam_own, camera_own->fd(), kCameraOwn);
#endif
  if (!ok) {
    std::fprintf(stderr, "dockd: epoll_ctl: %s\n", std::strerror(errno));
    daemon->send_zero(mono_us(), 5);
    return 1;
  }

  std::uint64_t watchdog_usec = 0;
#ifdef DOCKD_HAVE_SYSTEMD
  if (sd_watchdog_enabled(0, &watchdog_usec) <= 0) watchdog_usec = 0;
#else
  watchdog_usec = watchdog_usec_from_env();
#endif
  const std::uint64_t watchdog_every = watchdog_usec / cfg.systemd_watchdog_divider;
  std::uint64_t next_watchdog = mono_us();
  notify("READY=1\nSTATUS=docking daemon running");
  std::fprintf(stderr, "dockd: running (CAN %s, lidar %s %s, host udp %s:%u)\n", cfg.can_interface.c_str(),
               dockcore::drivers::to_string(cfg.lidar.protocol),
               cfg.lidar.transport == dockcore::drivers::LidarTransport::kSerial ? cfg.lidar.device.c_str() : "udp",
               cfg.host.bind_address.c_str(), host ? host->bound_port() : 0);

  int exit_code = 0;
  const char* stop_reason = nullptr;
  while (stop_reason == nullptr) {
    epoll_event evs[8];
    const int n = ::epoll_wait(ep, evs, 8, 100);
    if (n < 0) {
      if (errno == EINTR) continue;
      std::fprintf(stderr, "dockd: epoll_wait: %s\n", std::strerror(errno));
      stop_reason = "epoll_failure";
      exit_code = 1;
      break;
    }
    for (int i = 0; i < n && stop_reason == nullptr; ++i) {
      const std::uint64_t now = mono_us();
      switch (evs[i].data.u64) {
        case kTimer: {
          std::uint64_t expirations = 0;
          if (::read(tfd, &expirations, sizeof expirations) < 0) break;
          if (socketcan) socketcan->service(now);
          can->service(now);
          lidar->service(now);
          daemon->on_tick(now);
          // Drivers may have reopened their devices: follow the new descriptors.
          epoll_set(ep, r_lidar, lidar->fd(), kLidar);
          epoll_set(ep, r_can, bus.fd(), kCan);
          if (watchdog_every > 0 && now >= next_watchdog) {
            notify("WATCHDOG=1");
            next_watchdog = now + watchdog_every;
          }
          break;
        }
        case kSignal: {
          signalfd_siginfo si{};
          while (::read(sfd, &si, sizeof si) == static_cast<ssize_t>(sizeof si)) {
            if (si.ssi_signo == SIGTERM)
              stop_reason = "SIGTERM";
            else if (si.ssi_signo == SIGINT)
              stop_reason = "SIGINT";
            else if (si.ssi_signo == SIGHUP) {
              // Config reload (docs/dockd.md, "Config reload"): validated like --check-config, all or nothing,
              // applied only while the task is idle. The command-line overrides stay in force.
              std::string msg;
              daemon->reload_from_file(config_path, now, msg, [&](dockd::DockdConfig& next) {
                if (!log_level.empty()) dockd::parse_log_level(log_level, next.log_level);
                if (!record_dir.empty()) next.record_dir = record_dir;
                if (record_loop) next.record_loop = true;
              });
            }
          }
          break;
        }
        case kLidar:
          daemon->on_lidar_readable(now);
          break;
        case kCan:
          daemon->on_chassis_readable(now);
          break;
        case kHost:
          daemon->on_host_readable(now);
          break;
        case kCamera:
        case kCameraOwn:
          daemon->on_camera_readable(now);
          break;
        default:
          break;
      }
    }
  }

  // Every exit path from the loop commands zero: several frames, one tick apart, so a base that misses one (bus
  // load, its own filtering of duplicates) still sees the stop.
  notify("STOPPING=1");
  daemon->log_shutdown(mono_us(), stop_reason);
  for (int i = 0; i < 5; ++i) {
    daemon->send_zero(mono_us(), 1);
    timespec ts{0, 20 * 1000 * 1000};
    ::nanosleep(&ts, nullptr);
  }
  std::fprintf(stderr, "dockd: stopped (%s), zero velocity sent\n", stop_reason);
  ::close(tfd);
  ::close(sfd);
  ::close(ep);
  return exit_code;
}
