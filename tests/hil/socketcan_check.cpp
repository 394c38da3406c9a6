// socketcan_check: SocketCanBus on a real (v)can interface. Not a ctest on the build host (no CAN in its kernel):
// the HIL VM runs it as root with vcan0 up. Prints one "PASS <name>" / "FAIL <name>: why" line per check, exits 1
// on any failure (2 when vcan0 cannot even be opened).
//   socketcan_check [IFACE]     (default vcan0; uses `ip link set IFACE down/up`)
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <thread>
#include <chrono>

#include "dockcore/drivers/can_link.hpp"

using dockcore::CanFrame;
using dockcore::drivers::open_socketcan;

namespace {

int failures = 0;

void report(bool ok, const char* name, const std::string& why = "") {
  if (ok) {
    std::printf("PASS %s\n", name);
  } else {
    std::printf("FAIL %s: %s\n", name, why.c_str());
    ++failures;
  }
  std::fflush(stdout);
}

std::uint64_t mono_us() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000u + static_cast<std::uint64_t>(ts.tv_nsec) / 1000u;
}

// Waits up to timeout_ms for one frame on `bus`.
template <class Bus>
bool wait_frame(Bus& bus, CanFrame& f, std::uint64_t& stamp, int timeout_ms) {
  const std::uint64_t end = mono_us() + static_cast<std::uint64_t>(timeout_ms) * 1000u;
  while (mono_us() < end) {
    if (bus.receive(f, stamp)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

CanFrame frame(std::uint32_t id, std::uint8_t b0) {
  CanFrame f;
  f.id = id;
  f.dlc = 8;
  f.data[0] = b0;
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string iface = argc > 1 ? argv[1] : "vcan0";
  std::string err;
  const std::uint32_t rx_ids[2] = {0x110, 0x180};
  auto rx = open_socketcan(iface, rx_ids, 2, err);
  if (!rx) {
    std::printf("FAIL open_rx: %s\n", err.c_str());
    return 2;
  }
  auto tx = open_socketcan(iface, nullptr, 0, err);
  if (!tx) {
    std::printf("FAIL open_tx: %s\n", err.c_str());
    return 2;
  }
  report(true, "open_two_sockets");

  // 1. Send and receive, bytes intact.
  CanFrame f;
  std::uint64_t stamp = 0;
  CanFrame out = frame(0x110, 0xA5);
  for (int i = 1; i < 8; ++i) out.data[i] = static_cast<std::uint8_t>(i * 17);
  const std::uint64_t t_send = mono_us();
  report(tx->send(out), "send", tx->last_error());
  bool got = wait_frame(*rx, f, stamp, 500);
  bool same = got && f.id == 0x110 && f.dlc == 8 && !f.extended;
  for (int i = 0; got && i < 8; ++i) same = same && f.data[i] == out.data[i];
  report(same, "receive_bytes", got ? "bytes differ" : "nothing received");

  // 2. Timestamps on the monotonic clock, between send and now, and increasing.
  const std::uint64_t t_now = mono_us();
  report(got && stamp + 1000 >= t_send && stamp <= t_now + 1000, "timestamp_monotonic_clock",
         "stamp " + std::to_string(stamp) + " not in [" + std::to_string(t_send) + ", " + std::to_string(t_now) + "]");
  std::uint64_t last = stamp;
  bool increasing = true;
  for (int i = 0; i < 20; ++i) tx->send(frame(0x180, static_cast<std::uint8_t>(i)));
  int n = 0;
  while (n < 20 && wait_frame(*rx, f, stamp, 200)) {
    increasing = increasing && stamp >= last;
    last = stamp;
    ++n;
  }
  report(n == 20 && increasing, "timestamps_increasing", std::to_string(n) + " of 20 frames, increasing=" +
                                                              std::to_string(increasing));

  // 3. The id filter: 0x111 and an extended 0x110 are not delivered; 0x180 is.
  tx->send(frame(0x111, 1));
  CanFrame ext = frame(0x110, 2);
  ext.extended = true;
  tx->send(ext);
  tx->send(frame(0x180, 3));
  got = wait_frame(*rx, f, stamp, 300);
  report(got && f.id == 0x180 && f.data[0] == 3 && !f.extended, "id_filter",
         got ? "received id " + std::to_string(f.id) : "nothing received");
  report(!wait_frame(*rx, f, stamp, 100), "id_filter_nothing_else");

  // 4. Counters.
  report(tx->counters().frames_sent >= 24 && rx->counters().frames_received >= 22, "counters",
         "sent " + std::to_string(tx->counters().frames_sent) + " received " +
             std::to_string(rx->counters().frames_received));

  // 5. Interface down: the bus notices (read or write error), then service() reopens once it is up again.
  if (std::system(("ip link set " + iface + " down").c_str()) != 0) report(false, "link_down", "ip link failed");
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  tx->send(frame(0x110, 4));
  rx->receive(f, stamp);
  tx->service(mono_us());
  rx->service(mono_us());
  report(!tx->is_up() && !rx->is_up(), "down_detected",
         std::string("tx up=") + (tx->is_up() ? "1" : "0") + " rx up=" + (rx->is_up() ? "1" : "0") + " tx: " +
             tx->last_error() + " rx: " + rx->last_error());
  if (std::system(("ip link set " + iface + " up").c_str()) != 0) report(false, "link_up", "ip link failed");
  const std::uint64_t end = mono_us() + 5000000u;
  while ((!tx->is_up() || !rx->is_up()) && mono_us() < end) {
    tx->service(mono_us());
    rx->service(mono_us());
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  report(tx->is_up() && rx->is_up(), "reopened_by_service",
         std::string("tx: ") + tx->last_error() + " rx: " + rx->last_error());
  report(tx->counters().reopens >= 1 && rx->counters().reopens >= 1, "reopens_counted");
  tx->send(frame(0x110, 5));
  got = wait_frame(*rx, f, stamp, 500);
  report(got && f.data[0] == 5, "traffic_after_recovery", got ? "wrong frame" : "nothing received");

  // 6. Missing interface: a clear message.
  auto none = open_socketcan("nosuchcan9", nullptr, 0, err);
  report(none == nullptr && err.find("no CAN interface") != std::string::npos, "missing_interface_message", err);

  std::printf("%s socketcan_check (%d failures)\n", failures ? "FAIL" : "PASS", failures);
  return failures ? 1 : 0;
}
