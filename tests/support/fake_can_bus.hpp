#pragma once
// FakeCanBus: an in-memory hal::CanBus for tests (header-only; any test or tool may include it).
//
//   FakeCanBus bus;
//   bus.inject(frame, stamp_us);      // queue a frame for receive() (as if another node sent it)
//   bus.inject_error(bus_off);        // an error frame: counted in bus_errors (and bus_off), never returned
//   link.poll();                      // the code under test drains it
//   bus.sent()                        // every frame the code under test queued, in order; clear_sent() empties it
//   bus.fail_sends(n)                 // the next n send() calls fail as ENOBUFS would (counted in send_failures)
//   bus.drop_every(k)                 // every k-th injected frame is lost (counted in rx_overflows, like SO_RXQ_OVFL)
//   bus.set_rx_capacity(n)            // receive queue bound; injecting into a full queue drops (rx_overflows)
//   FakeCanBus::connect(a, b)         // frames sent on a are received on b and vice versa (two-node bus)
//
// Deterministic; no threads; fd() is -1 (nothing to wait on). Cost: O(1) per call (amortised).
#include <cstddef>
#include <cstdint>
#include <deque>
#include <utility>
#include <vector>

#include "dockcore/hal/can_bus.hpp"

namespace dockcore::testing {

class FakeCanBus final : public hal::CanBus {
 public:
  bool send(const CanFrame& frame) override {
    if (fail_sends_ > 0) {
      --fail_sends_;
      ++counters_.send_failures;
      return false;
    }
    ++counters_.frames_sent;
    sent_.push_back(frame);
    if (peer_ != nullptr) peer_->inject(frame, now_us_);
    return true;
  }

  bool receive(CanFrame& frame, std::uint64_t& stamp_us) override {
    while (!rx_.empty()) {
      const Entry e = rx_.front();
      rx_.pop_front();
      if (e.error) continue;  // counted at injection
      frame = e.frame;
      stamp_us = e.stamp_us;
      ++counters_.frames_received;
      return true;
    }
    return false;
  }

  int fd() const override { return -1; }
  const hal::CanBusCounters& counters() const override { return counters_; }

  /// Queues `f` for receive() with receive time `stamp_us`. Subject to drop_every / rx capacity.
  void inject(const CanFrame& f, std::uint64_t stamp_us = 0) {
    ++injected_;
    if (drop_every_ > 0 && injected_ % drop_every_ == 0) {
      ++counters_.rx_overflows;
      return;
    }
    if (rx_.size() >= rx_capacity_) {
      ++counters_.rx_overflows;
      return;
    }
    rx_.push_back(Entry{f, stamp_us, false});
  }
  /// An error frame: counted at once in bus_errors (and bus_off when `bus_off`).
  void inject_error(bool bus_off = false) {
    ++counters_.bus_errors;
    if (bus_off) ++counters_.bus_off;
  }
  const std::vector<CanFrame>& sent() const { return sent_; }
  void clear_sent() { sent_.clear(); }
  std::size_t pending() const { return rx_.size(); }
  void fail_sends(std::uint32_t n) { fail_sends_ = n; }
  void drop_every(std::uint32_t k) { drop_every_ = k; }
  void set_rx_capacity(std::size_t n) { rx_capacity_ = n; }
  /// Stamp given to frames this bus forwards to a connected peer.
  void set_now(std::uint64_t now_us) { now_us_ = now_us; }
  static void connect(FakeCanBus& a, FakeCanBus& b) {
    a.peer_ = &b;
    b.peer_ = &a;
  }

 private:
  struct Entry {
    CanFrame frame;
    std::uint64_t stamp_us;
    bool error;
  };
  std::deque<Entry> rx_;
  std::vector<CanFrame> sent_;
  hal::CanBusCounters counters_{};
  std::uint32_t fail_sends_ = 0;
  std::uint32_t drop_every_ = 0;
  std::uint64_t injected_ = 0;
  std::size_t rx_capacity_ = 4096;
  std::uint64_t now_us_ = 0;
  FakeCanBus* peer_ = nullptr;
};

}  // namespace dockcore::testing
