// core input watch: when the lidar and the chassis count as stale, late scans, the hold-then-fault timing, trips and
// the fresh-since time the watchdog resume waits on.
#include <cstdint>

#include "dockcore/task/input_watch.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;

namespace {

constexpr std::uint64_t kMs = 1000;
constexpr std::uint64_t kPeriodUs = 100 * kMs;  // a 10 Hz lidar

/// Scans stamped every 100 ms from `t0_us`, each read `latency_us` after its turn ended, `n` of them; the watch is
/// updated at each read (chassis fresh). Returns the last read time.
std::uint64_t feed_scans(InputWatch& w, std::uint64_t t0_us, int n, std::uint64_t latency_us) {
  std::uint64_t read_us = 0;
  for (int i = 0; i < n; ++i) {
    const std::uint64_t stamp = t0_us + static_cast<std::uint64_t>(i) * kPeriodUs;
    read_us = stamp + kPeriodUs + latency_us;
    CHECK(w.on_scan(stamp, read_us));
    w.update(read_us, true, read_us);
  }
  return read_us;
}

}  // namespace

TEST_GROUP(InputWatch){};

TEST(InputWatch, BothStartStaleAndTheFirstScanCountsFromItsReadTime) {
  InputWatch w;
  CHECK(w.lidar_stale() && w.chassis_stale() && w.hold());
  InputWatch::Change c = w.update(1000 * kMs, false, 0);
  CHECK(!c.lidar && !c.chassis);  // no change: still stale
  // The first scan: its turn's length is unknown, so its read time stands for the turn's end.
  CHECK(w.on_scan(1000 * kMs, 1050 * kMs));
  c = w.update(1050 * kMs, true, 1050 * kMs);
  CHECK(c.lidar && c.chassis);
  CHECK(!w.lidar_stale() && !w.chassis_stale() && !w.hold());
  LONGS_EQUAL(1050 * kMs, static_cast<long>(w.turn_end_us()));
  c = w.update(1050 * kMs, true, 1050 * kMs);  // the same again: nothing changes
  CHECK(!c.lidar && !c.chassis);
  // 200 ms after that read, with no second scan, it is stale.
  CHECK(!w.update(1250 * kMs, true, 1250 * kMs).lidar);
  CHECK(w.update(1250 * kMs + 1, true, 1250 * kMs).lidar);
  CHECK(w.lidar_stale());
}

TEST(InputWatch, TheTurnEndsOnePeriodAfterItsStampAndLateScansAreNotUsed) {
  InputWatch w;
  const std::uint64_t last_read = feed_scans(w, 1000 * kMs, 5, 30 * kMs);
  // Stamps 1.0..1.4 s: the last turn ended at 1.5 s, read at 1.53 s.
  LONGS_EQUAL(1500 * kMs, static_cast<long>(w.turn_end_us()));
  LONGS_EQUAL(static_cast<long>(last_read), static_cast<long>(w.scan_read_us()));
  CHECK(!w.update(1700 * kMs, true, 1700 * kMs).lidar);  // 200 ms after the turn's end: still fresh
  CHECK(w.update(1700 * kMs + 1, true, 1700 * kMs).lidar);
  // A backlog: the next turn (stamp 1.5 s, ended 1.6 s) read at 1.9 s, 300 ms after it ended: late, not used.
  CHECK_FALSE(w.on_scan(1500 * kMs, 1900 * kMs));
  LONGS_EQUAL(1, static_cast<long>(w.late_scans()));
  LONGS_EQUAL(1500 * kMs, static_cast<long>(w.turn_end_us()));
  CHECK(w.update(1900 * kMs, true, 1900 * kMs).lidar == false);
  CHECK(w.lidar_stale());
  // Read exactly 200 ms after its turn ended: still usable.
  CHECK(w.on_scan(1600 * kMs, 1900 * kMs));
  CHECK(w.update(1900 * kMs, true, 1900 * kMs).lidar);
  CHECK(!w.lidar_stale());
  LONGS_EQUAL(1, static_cast<long>(w.late_scans()));
}

TEST(InputWatch, HoldFirstThenTheTaskManagerIsToldAfterFaultAfter) {
  InputWatch w;
  WatchdogParams p;
  p.fault_after_ms = 500;
  w.configure(p);
  const std::uint64_t t = feed_scans(w, 1000 * kMs, 3, 10 * kMs);  // last turn ended 1.3 s
  CHECK(w.lidar_ok(t) && w.chassis_ok(t));
  // The lidar keeps delivering (a scan read just as its turn ends) while the chassis goes silent after its feedback
  // at t: stale (hold) 200 ms later, not yet a fault.
  auto scan_at = [&w](std::uint64_t now_us) { CHECK(w.on_scan(now_us - kPeriodUs, now_us)); };
  const std::uint64_t stale_at = t + 200 * kMs + 1;
  scan_at(stale_at);
  CHECK(w.update(stale_at, true, t).chassis);
  CHECK(w.chassis_stale() && !w.lidar_stale() && w.hold());
  CHECK(w.chassis_ok(stale_at + 499 * kMs));
  CHECK_FALSE(w.chassis_ok(stale_at + 500 * kMs));
  LONGS_EQUAL(1, static_cast<long>(w.chassis_trips()));
  LONGS_EQUAL(0, static_cast<long>(w.lidar_trips()));
  LONGS_EQUAL(static_cast<long>(stale_at), static_cast<long>(w.fresh_since_us()));
  // Feedback again: fresh; fresh_since stays at the last stale evaluation.
  const std::uint64_t back = stale_at + 100 * kMs;
  scan_at(back);
  CHECK(w.update(back, true, back).chassis);
  CHECK(!w.chassis_stale() && !w.hold());
  LONGS_EQUAL(static_cast<long>(stale_at), static_cast<long>(w.fresh_since_us()));
  // A feedback stamp after the evaluation time (read during the tick) is fresh.
  scan_at(back + 300 * kMs);
  CHECK(!w.update(back + 300 * kMs, true, back + 301 * kMs).chassis);
  // fault_after_ms 0: the task manager is told on the first stale tick.
  p.fault_after_ms = 0;
  w.configure(p);
  const std::uint64_t late = back + 900 * kMs;
  scan_at(late);
  CHECK(w.update(late, true, back).chassis);
  CHECK_FALSE(w.chassis_ok(late));
  CHECK(w.lidar_ok(late));
  LONGS_EQUAL(2, static_cast<long>(w.chassis_trips()));
  // reset(): both stale again, the counters kept.
  w.reset();
  CHECK(w.lidar_stale() && w.chassis_stale());
  LONGS_EQUAL(2, static_cast<long>(w.chassis_trips()));
}
