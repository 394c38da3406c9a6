// dockd's host protocol on its own: requests from an in-memory request link, a scripted daemon behind HostActions.
// Which reply each request gets, and when: at once (refusals), or once the core takes its queued command.
#include <cstdint>
#include <cstring>
#include <deque>
#include <string>
#include <vector>

#include "host_protocol.hpp"

#include "CppUTest/TestHarness.h"

namespace {

using dockcore::hal::HostRequest;
using dockcore::hal::HostRequestKind;

/// Requests handed out in order; every reply and status datagram kept as text.
struct FakeRequestLink final : dockcore::hal::HostRequestLink {
  std::deque<HostRequest> pending;
  std::vector<std::string> replies;
  std::vector<std::string> published;
  dockcore::hal::HostRequestCounters c{};
  std::size_t subscribers = 0;

  bool poll_request(HostRequest& out, std::uint64_t now_us) override {
    if (pending.empty()) return false;
    out = pending.front();
    out.stamp_us = now_us;
    pending.pop_front();
    return true;
  }
  bool reply(const dockcore::hal::HostPeer&, const char* json, std::size_t len) override {
    replies.emplace_back(json, len);
    return len > 0;
  }
  void publish(const char* json, std::size_t len, std::uint64_t) override { published.emplace_back(json, len); }
  std::size_t subscriber_count() const override { return subscribers; }
  const dockcore::hal::HostRequestCounters& counters() const override { return c; }
  void count_rejected() override { ++c.rejected_later; }
  bool set_allowlist(const std::vector<std::string>&, std::string&) override { return true; }
};

/// The daemon's side: a dock database with docks 1 and 3, a queue that answers what `next_result` says.
struct FakeActions final : dockd::HostActions {
  dockd::DockdConfig cfg;
  struct Submitted {
    dockcore::HostCommandType type;
    std::uint16_t dock_id;
    std::uint32_t token;
  };
  std::vector<Submitted> submitted;
  dockcore::SubmitResult next_result = dockcore::SubmitResult::kQueued;
  std::uint32_t next_displaced = 0;
  int teach_starts = 0;
  int teach_cancels = 0;
  std::vector<std::string> events;

  FakeActions() {
    dockd::DockEntry d;
    d.id = 1;
    cfg.docks.push_back(d);
    d.id = 3;
    cfg.docks.push_back(d);
    cfg.default_dock_id = 1;
  }
  void status_fields(dockcore::drivers::JsonWriter& w, std::uint64_t now_us) const override {
    w.str("type", "status").uint("stamp_us", now_us);
  }
  const dockd::DockdConfig& config() const override { return cfg; }
  std::uint16_t active_dock_id() const override { return 3; }
  dockcore::SubmitResult submit(dockcore::HostCommandType type, std::uint16_t dock_id, std::uint32_t token,
                                std::uint32_t& displaced) override {
    submitted.push_back({type, dock_id, token});
    displaced = next_displaced;
    return next_result;
  }
  void start_teach(const HostRequest&, std::uint64_t) override { ++teach_starts; }
  void cancel_teach(std::uint64_t) override { ++teach_cancels; }
  void log_event(dockd::EventLine& e, dockd::LogLevel) override {
    const std::size_t n = e.w.finish(true);
    events.emplace_back(e.buf, n);
  }
};

HostRequest request(HostRequestKind kind, std::uint32_t seq) {
  HostRequest r;
  r.kind = kind;
  r.has_seq = true;
  r.seq = seq;
  return r;
}

/// What the core's tick reports when it takes the command queued under `token`.
dockcore::TickOutput taken(std::uint32_t token, dockcore::HostCommandType type, std::uint16_t dock_id,
                           dockcore::CommandResult result, dockcore::TaskState after) {
  dockcore::TickOutput out;
  out.command_taken = true;
  out.command.command = dockcore::HostCommand{type, dock_id};
  out.command.token = token;
  out.command_result = result;
  out.status.state = after;
  return out;
}

}  // namespace

TEST_GROUP(DockdHostProtocol) {
  FakeRequestLink link;
  FakeActions actions;
  dockd::DaemonCounters counters;
};

TEST(DockdHostProtocol, AQueuedRequestIsAnsweredWhenTheCoreTakesItsCommand) {
  dockd::HostProtocol p(&link, nullptr, actions, counters);
  link.pending.push_back(request(HostRequestKind::kDock, 7));
  p.poll(1000);
  CHECK_EQUAL(1u, actions.submitted.size());
  CHECK_EQUAL(1u, actions.submitted[0].dock_id);  // the default dock
  CHECK(actions.submitted[0].token != 0u);
  CHECK_TRUE(link.replies.empty());  // nothing until the task manager has ruled

  p.command_taken(taken(actions.submitted[0].token, dockcore::HostCommandType::kDock, 1,
                        dockcore::CommandResult::kAccepted, dockcore::TaskState::kGetTaskingCmd),
                  dockcore::TaskState::kNotTasking, 21000);
  CHECK_EQUAL(1u, link.replies.size());
  STRCMP_EQUAL(
      "{\"ok\":true,\"cmd\":\"dock\",\"seq\":7,\"result\":\"accepted\",\"dock_id\":1,\"state\":\"GET_TASKING_CMD\"}",
      link.replies[0].c_str());
  CHECK_EQUAL(1u, counters.commands);
  CHECK_EQUAL(0u, counters.commands_rejected);

  // The slot is free again: the same token taken twice gets no second reply.
  p.command_taken(taken(actions.submitted[0].token, dockcore::HostCommandType::kDock, 1,
                        dockcore::CommandResult::kAccepted, dockcore::TaskState::kGetTaskingCmd),
                  dockcore::TaskState::kNotTasking, 41000);
  CHECK_EQUAL(1u, link.replies.size());
}

TEST(DockdHostProtocol, RefusalsAreAnsweredAtOnceAndCounted) {
  dockd::HostProtocol p(&link, nullptr, actions, counters);
  HostRequest unknown = request(HostRequestKind::kDock, 1);
  unknown.has_dock_id = true;
  unknown.dock_id = 9;
  link.pending.push_back(unknown);
  p.poll(1000);
  CHECK_TRUE(actions.submitted.empty());
  CHECK_EQUAL(1u, link.replies.size());
  STRCMP_CONTAINS("\"code\":5,\"error\":\"unknown_dock_id\"", link.replies[0].c_str());

  actions.next_result = dockcore::SubmitResult::kFull;
  link.pending.push_back(request(HostRequestKind::kUndock, 2));
  p.poll(2000);
  CHECK_EQUAL(1u, actions.submitted.size());
  CHECK_EQUAL(3u, actions.submitted[0].dock_id);  // undock goes to the active dock
  CHECK_EQUAL(2u, link.replies.size());
  STRCMP_CONTAINS("\"code\":9,\"error\":\"busy\"", link.replies[1].c_str());

  CHECK_EQUAL(2u, counters.commands_rejected);
  CHECK_EQUAL(1u, counters.queue_overflows);
  CHECK_EQUAL(2u, link.c.rejected_later);
  link.c.malformed = 4;  // the link's own refusals count too
  CHECK_EQUAL(6u, p.commands_rejected_total());
  CHECK_EQUAL(2u, actions.events.size());
  STRCMP_CONTAINS("\"event\":\"command_rejected\"", actions.events[0].c_str());
}

TEST(DockdHostProtocol, ARequestTheTaskManagerRefusesIsCountedOnce) {
  dockd::HostProtocol p(&link, nullptr, actions, counters);
  link.pending.push_back(request(HostRequestKind::kUndock, 5));
  p.poll(1000);
  CHECK_EQUAL(1u, actions.submitted.size());
  p.command_taken(taken(actions.submitted[0].token, dockcore::HostCommandType::kUndock, 3,
                        dockcore::CommandResult::kRejectedNotDocked, dockcore::TaskState::kNotTasking),
                  dockcore::TaskState::kNotTasking, 21000);
  CHECK_EQUAL(1u, link.replies.size());
  STRCMP_CONTAINS("\"seq\":5,\"code\":6,\"error\":\"rejected\"", link.replies[0].c_str());
  CHECK_EQUAL(1u, counters.commands);
  CHECK_EQUAL(1u, counters.commands_rejected);
  CHECK_EQUAL(1u, link.c.rejected_later);
  CHECK_EQUAL(1u, p.commands_rejected_total());

  // A CAN command (no UDP request waits for it) refused by the task manager: counted once too.
  p.command_taken(taken(0, dockcore::HostCommandType::kUndock, 3, dockcore::CommandResult::kRejectedNotDocked,
                        dockcore::TaskState::kNotTasking),
                  dockcore::TaskState::kNotTasking, 41000);
  CHECK_EQUAL(2u, counters.commands_rejected);
  CHECK_EQUAL(2u, p.commands_rejected_total());
}

TEST(DockdHostProtocol, AStopThatDisplacesAQueuedRequestLeavesThatOneUnanswered) {
  dockd::HostProtocol p(&link, nullptr, actions, counters);
  link.pending.push_back(request(HostRequestKind::kDock, 1));
  p.poll(1000);
  const std::uint32_t dock_token = actions.submitted[0].token;

  actions.next_result = dockcore::SubmitResult::kReplacedNewest;
  actions.next_displaced = dock_token;
  link.pending.push_back(request(HostRequestKind::kStop, 2));
  p.poll(2000);
  CHECK_EQUAL(1, actions.teach_cancels);  // a stop also ends a running teach
  CHECK_EQUAL(2u, actions.submitted.size());
  CHECK_TRUE(link.replies.empty());  // the stop waits for the core like any command
  CHECK_EQUAL(1u, counters.queue_overflows);

  p.command_taken(taken(dock_token, dockcore::HostCommandType::kDock, 1, dockcore::CommandResult::kAccepted,
                        dockcore::TaskState::kGetTaskingCmd),
                  dockcore::TaskState::kNotTasking, 21000);
  CHECK_TRUE(link.replies.empty());  // displaced: its slot was released
  p.command_taken(taken(actions.submitted[1].token, dockcore::HostCommandType::kCancel, 3,
                        dockcore::CommandResult::kAccepted, dockcore::TaskState::kNotTasking),
                  dockcore::TaskState::kNotTasking, 41000);
  CHECK_EQUAL(1u, link.replies.size());
  STRCMP_CONTAINS("\"cmd\":\"stop\",\"seq\":2", link.replies[0].c_str());
}

TEST(DockdHostProtocol, StatusGoesToSubscribersOnlyWhenThereAreAny) {
  dockd::HostProtocol p(&link, nullptr, actions, counters);
  dockcore::hal::StatusMessage m;
  p.publish_status(m, 5);
  CHECK_TRUE(link.published.empty());
  link.subscribers = 1;
  p.publish_status(m, 6);
  CHECK_EQUAL(1u, link.published.size());
  STRCMP_EQUAL("{\"type\":\"status\",\"stamp_us\":6}", link.published[0].c_str());
  CHECK_EQUAL(2u, counters.status_sent);

  link.pending.push_back(request(HostRequestKind::kStatus, 4));
  p.poll(7);
  CHECK_EQUAL(1u, link.replies.size());
  STRCMP_EQUAL("{\"ok\":true,\"cmd\":\"status\",\"seq\":4,\"type\":\"status\",\"stamp_us\":7}",
               link.replies[0].c_str());
}
