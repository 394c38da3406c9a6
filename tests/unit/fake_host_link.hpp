#pragma once
// A HostRequestLink for the dockd host-protocol suites: datagrams from a list, replies and stream objects kept as text.
// Include after the standard headers and before CppUTest's (its new macros).
#include <algorithm>
#include <cstring>
#include <deque>
#include <string>
#include <vector>

#include "dockcore/hal/host_link.hpp"

namespace dockd_test {

/// Datagrams handed out in order, all from one peer ("!" stands for one from a foreign peer: dropped and counted, at
/// most 64 per call, as the UDP link does); every reply and status datagram kept as text; a subscriber table of two.
struct FakeRequestLink final : dockcore::hal::HostRequestLink {
  std::deque<std::string> pending;
  std::vector<std::string> replies;
  std::vector<std::string> published;
  dockcore::hal::HostRequestCounters c{};
  std::size_t subscribers = 0;

  bool poll_datagram(dockcore::hal::HostDatagram& out, std::uint64_t now_us) override {
    for (int i = 0; i < 64 && !pending.empty() && pending.front() == "!"; ++i) {
      pending.pop_front();
      ++c.not_allowed;
    }
    if (pending.empty() || pending.front() == "!") return false;
    const std::string& d = pending.front();
    out.len = d.size();
    std::memcpy(out.data, d.data(), std::min(d.size(), sizeof out.data));
    out.peer = dockcore::hal::HostPeer{0x0100007fu, 0x3930u};
    out.stamp_us = now_us;
    pending.pop_front();
    ++c.datagrams;
    return true;
  }
  bool reply(const dockcore::hal::HostPeer&, const char* json, std::size_t len) override {
    replies.emplace_back(json, len);
    return len > 0;
  }
  void publish(const char* json, std::size_t len, std::uint64_t) override { published.emplace_back(json, len); }
  bool subscribe(const dockcore::hal::HostPeer&, std::uint64_t, std::uint32_t& expires_ms) override {
    if (subscribers == 2) {
      ++c.subscribers_rejected;
      return false;
    }
    ++subscribers;
    expires_ms = 10000;
    return true;
  }
  void unsubscribe(const dockcore::hal::HostPeer&) override {
    if (subscribers > 0) --subscribers;
  }
  std::size_t subscriber_count() const override { return subscribers; }
  const dockcore::hal::HostRequestCounters& counters() const override { return c; }
  bool set_allowlist(const std::vector<std::string>&, std::string&) override { return true; }
};

}  // namespace dockd_test
