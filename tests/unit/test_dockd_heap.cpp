// dockd's heap after start-up: the Daemon runs several dock -> charge -> undock cycles of a simulated
// robot (the default scenario, as test_dockd_daemon.cpp) with its event log open, a CAN host, and a UDP host link
// with a subscribed status stream and a status request per cycle; every malloc/calloc/realloc (operator new goes
// through malloc) made inside Daemon::on_tick / on_host_readable is counted. After the first cycle (lazy first-use
// set-up: stdio, the log file, the first subscriber) the count must be zero. The simulator around the daemon is not
// counted. Not built in sanitizer builds: their runtime owns malloc (tests/CMakeLists.txt, as core_alloc_trap).
#include <arpa/inet.h>
#include <malloc.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/drivers/udp_host_link.hpp"
#include "dockd_sim_rig.hpp"
#include "docksim/rng.hpp"
#include "../support/malloc_count.hpp"
#include "session_record.hpp"

#include "CppUTest/TestHarness.h"

using dockcore_test::g_allocs;
using dockcore_test::g_armed;

using dockcore::TaskState;

namespace {

/// Counts the heap calls made while it lives.
struct Armed {
  Armed() { g_armed = true; }
  ~Armed() { g_armed = false; }
};

long rss_kib() {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (f == nullptr) return -1;
  char line[256];
  long kib = -1;
  while (std::fgets(line, sizeof line, f) != nullptr) {
    if (std::strncmp(line, "VmRSS:", 6) == 0) kib = std::strtol(line + 6, nullptr, 10);
  }
  std::fclose(f);
  return kib;
}

using dockd_test::FakeHost;
using dockd_test::SimChassis;
using dockd_test::SimClock;
using dockd_test::SimLidar;

/// The default scenario's robot and dock around a Daemon with an event log, a CAN host and a UDP host link.
struct HeapRig {
  docksim::Scenario sc = docksim::load_scenario_file(dockd_test::default_scenario_path());
  dockd::DockdConfig cfg = dockd_test::scenario_config(sc);
  SimClock clock;
  std::unique_ptr<docksim::Chassis> chassis;
  SimChassis link;
  SimLidar lidar;
  FakeHost host;
  docksim::World world;
  docksim::Rng rng{7};
  std::string dir;
  dockd::RotatingLog log;
  std::unique_ptr<dockcore::drivers::UdpHostLink> udp;
  std::unique_ptr<dockd::Daemon> daemon;
  std::uint64_t next_scan_us = 0;
  int sock = -1;
  sockaddr_in to{};
  std::size_t on_tick_allocs = 0;  ///< Heap calls inside the daemon since construction.
  std::size_t ticks = 0;

  HeapRig() {
    dir = std::string("/tmp/dockd_heap_") + std::to_string(::getpid());
    ::mkdir(dir.c_str(), 0700);
    cfg.state_file = dir + "/state";
    chassis = dockd_test::scenario_chassis(sc, link, clock);
    world = docksim::scenario_world(sc, true);
    std::string err;
    // 1 KiB per file: the log rotates every cycle or so, so rotation runs inside the counted ticks too.
    CHECK_TRUE_TEXT(log.open(dir, "events.jsonl", 1024, 2, err), err.c_str());
    dockcore::drivers::UdpHostLinkOptions o;
    o.port = 0;
    udp = dockcore::drivers::open_udp_host_link(o, err);
    CHECK_TRUE_TEXT(udp != nullptr, err.c_str());
    dockd::DaemonIo io;
    io.lidar = &lidar;
    io.chassis = &link;
    io.can_host = &host;
    io.udp_host = udp.get();
    io.clock = &clock;
    io.event_log = &log;
    io.stderr_level = std::getenv("DOCKD_TEST_LOG") ? dockd::LogLevel::kDebug : dockd::LogLevel::kError;
    daemon = std::make_unique<dockd::Daemon>(cfg, io);
    CHECK_TRUE_TEXT(daemon->start(err), err.c_str());
    sock = ::socket(AF_INET, SOCK_DGRAM, 0);
    to.sin_family = AF_INET;
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    to.sin_port = htons(udp->bound_port());
  }
  ~HeapRig() {
    if (sock >= 0) ::close(sock);
    daemon.reset();
    std::remove(cfg.state_file.c_str());
    std::remove((cfg.state_file + ".bak").c_str());
    std::remove((cfg.state_file + ".learned").c_str());
    std::remove((dir + "/events.jsonl").c_str());
    std::remove((dir + "/events.jsonl.1").c_str());
    ::rmdir(dir.c_str());
  }

  void send_udp(const char* m) { ::sendto(sock, m, std::strlen(m), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to); }
  void drain_udp() {
    char buf[2048];
    while (::recv(sock, buf, sizeof buf, MSG_DONTWAIT) > 0) {
    }
  }

  /// One 20 ms tick: 4 chassis steps, a 10 Hz scan (simulator: not counted), then the daemon (counted).
  void tick() {
    for (int i = 0; i < 4; ++i) chassis->step();
    clock.t += 20000;
    if (clock.t >= next_scan_us) {
      next_scan_us = clock.t + 100000;
      docksim::simulate_scan(world, chassis->state().true_pose.compose(sc.lidar_mount), sc.lidar, rng, lidar.scan.get(),
                             clock.t);
      lidar.pending = true;
    }
    const std::size_t before = g_allocs;
    {
      Armed armed;
      daemon->on_host_readable(clock.t);
      daemon->on_tick(clock.t);
    }
    on_tick_allocs += g_allocs - before;
    ++ticks;
    drain_udp();
  }
  template <typename P>
  bool run_until(P pred, double max_s) {
    const int n = static_cast<int>(max_s / 0.02);
    for (int i = 0; i < n; ++i) {
      tick();
      if (pred()) return true;
    }
    return false;
  }
};

}  // namespace

// The scenario parser's static name table is built on first use; build it before CppUTest's per-test checks.
static const bool kNamesWarm = !docksim::controller_names().empty();

TEST_GROUP(DockdHeap){};

// The counter itself must count, or a zero below would prove nothing.
TEST(DockdHeap, CounterCountsHeapCalls) {
  const std::size_t before = g_allocs;
  {
    Armed armed;
    // Through a volatile pointer: the compiler may not elide the call (it may elide a plain new/delete pair).
    void* (*volatile heap_call)(std::size_t) = std::malloc;
    void* p = heap_call(32);
    std::free(p);
    std::string s(200, 'x');  // operator new -> malloc
    CHECK_EQUAL('x', s[199]);
  }
  CHECK(g_allocs - before >= 2);
}

TEST(DockdHeap, NoAllocationPerTickAfterTheFirstCycle) {
  (void)kNamesWarm;
  HeapRig r;
  constexpr int kCycles = 5;
  const double starts[kCycles][3] = {{1.2, 0.2, 0.1}, {1.6, -0.4, 0.3}, {0.9, 0.5, -0.2}, {2.0, 0.0, 0.0}, {1.4, -0.6, -0.4}};
  std::vector<std::size_t> allocs, ticks;
  std::vector<long> rss;
  std::vector<std::size_t> heap;
  std::uint32_t saves_after_first_cycle = 0;
  CHECK_TRUE(r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0));
  for (int c = 0; c < kCycles; ++c) {
    const std::size_t a0 = r.on_tick_allocs, t0 = r.ticks;
    // The robot is carried to this cycle's start (truth only: odometry runs on).
    r.chassis->set_true_pose(docksim::start_from(r.sc, starts[c][0], starts[c][1], starts[c][2]).robot_world);
    r.run_until([] { return false; }, 0.5);
    char m[96];
    std::snprintf(m, sizeof m, "{\"cmd\":\"subscribe\",\"seq\":%d}", 100 + c);
    r.send_udp(m);
    r.host.command(1, 0);  // CAN host: dock at dock 0
    CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFinishTasking; }, 60.0));
    std::snprintf(m, sizeof m, "{\"cmd\":\"status\",\"seq\":%d}", 200 + c);
    r.send_udp(m);
    r.run_until([] { return false; }, 2.0);  // charging
    CHECK_EQUAL(static_cast<int>(TaskState::kFinishTasking), static_cast<int>(r.daemon->state()));
    std::snprintf(m, sizeof m, "{\"cmd\":\"undock\",\"seq\":%d}", 300 + c);
    r.send_udp(m);  // UDP host: undock
    CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kNotTasking; }, 40.0));
    CHECK_EQUAL(static_cast<int>(dockcore::TaskResult::kUndocked), static_cast<int>(r.daemon->last_status().last_result));
    r.run_until([] { return false; }, 0.5);
    if (c == 0) saves_after_first_cycle = r.daemon->counters().learned_saves;
    allocs.push_back(r.on_tick_allocs - a0);
    ticks.push_back(r.ticks - t0);
    rss.push_back(rss_kib());
    const struct mallinfo2 mi = mallinfo2();
    heap.push_back(mi.uordblks + mi.hblkhd);
  }
  std::size_t after_first = 0, ticks_after_first = 0;
  for (int c = 0; c < kCycles; ++c) {
    std::printf("\ndockd heap: cycle %d: %zu ticks, %zu heap calls in the daemon (%.4f per tick), VmRSS %ld KiB, "
                "malloc in use %zu B",
                c + 1, ticks[c], allocs[c], static_cast<double>(allocs[c]) / static_cast<double>(ticks[c]), rss[c],
                heap[c]);
    if (c > 0) {
      after_first += allocs[c];
      ticks_after_first += ticks[c];
    }
  }
  std::printf("\ndockd heap: after the first cycle: %zu heap calls in %zu ticks; VmRSS %ld -> %ld KiB\n", after_first,
              ticks_after_first, rss[1], rss[kCycles - 1]);
  std::printf("dockd heap: event log rotations %u, status datagrams streamed %u\n", r.log.rotations(),
              r.udp->counters().stream_sent);
  CHECK(r.udp->counters().stream_sent > 0);
  CHECK(r.log.rotations() > 0);
  // The learned file is written from the loop when a task's end changed what was learned: it was, with no heap.
  saves_after_first_cycle = r.daemon->counters().learned_saves - saves_after_first_cycle;
  std::printf("dockd heap: learned file written %u times after the first cycle\n", saves_after_first_cycle);
  CHECK(saves_after_first_cycle > 0);
  CHECK_EQUAL(0u, r.daemon->counters().learned_save_failures);
  CHECK_EQUAL(0u, after_first);
  // No heap call means nothing can grow; the malloc heap (simulator and test included) must not creep either.
  CHECK(heap[kCycles - 1] <= heap[1] + 4096);
}
