// dockd's host protocol on its own: request datagrams from an in-memory request link, a scripted daemon behind
// HostActions. How each datagram is parsed, which reply each request gets, and when: at once (refusals, status,
// subscriptions), or once the core takes its queued command.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <deque>
#include <string>
#include <vector>

#include "fake_host_link.hpp"
#include "host_protocol.hpp"

#include "CppUTest/TestHarness.h"

namespace {

using dockd_test::FakeRequestLink;

using dockd::HostRequest;
using dockd::HostRequestKind;

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
  void status_fields(dockd::JsonWriter& w, std::uint64_t now_us) const override {
    w.str("type", "status").uint("stamp_us", now_us);
  }
  void camera_fields(dockd::JsonWriter& w) const override { w.uint("camera_frames", 42); }
  void counter_fields(dockd::JsonWriter& w, std::uint64_t) const override { w.uint("ticks", 7); }
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

/// The datagram {"cmd":"<cmd>","seq":<seq>}.
std::string request(const char* cmd, std::uint32_t seq) {
  return std::string("{\"cmd\":\"") + cmd + "\",\"seq\":" + std::to_string(seq) + "}";
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
  link.pending.push_back(request("dock", 7));
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
  link.pending.push_back("{\"cmd\":\"dock\",\"seq\":1,\"dock_id\":9}");
  p.poll(1000);
  CHECK_TRUE(actions.submitted.empty());
  CHECK_EQUAL(1u, link.replies.size());
  STRCMP_CONTAINS("\"code\":5,\"error\":\"unknown_dock_id\"", link.replies[0].c_str());

  actions.next_result = dockcore::SubmitResult::kFull;
  link.pending.push_back(request("undock", 2));
  p.poll(2000);
  CHECK_EQUAL(1u, actions.submitted.size());
  CHECK_EQUAL(3u, actions.submitted[0].dock_id);  // undock goes to the active dock
  CHECK_EQUAL(2u, link.replies.size());
  STRCMP_CONTAINS("\"code\":9,\"error\":\"busy\"", link.replies[1].c_str());

  CHECK_EQUAL(2u, counters.commands_rejected);
  CHECK_EQUAL(1u, counters.queue_overflows);
  CHECK_EQUAL(2u, counters.udp.rejected_later);
  counters.udp.malformed = 4;  // the datagrams that did not parse count too
  CHECK_EQUAL(6u, p.commands_rejected_total());
  CHECK_EQUAL(2u, actions.events.size());
  STRCMP_CONTAINS("\"event\":\"command_rejected\"", actions.events[0].c_str());
}

TEST(DockdHostProtocol, ARequestTheTaskManagerRefusesIsCountedOnce) {
  dockd::HostProtocol p(&link, nullptr, actions, counters);
  link.pending.push_back(request("undock", 5));
  p.poll(1000);
  CHECK_EQUAL(1u, actions.submitted.size());
  p.command_taken(taken(actions.submitted[0].token, dockcore::HostCommandType::kUndock, 3,
                        dockcore::CommandResult::kRejectedNotDocked, dockcore::TaskState::kNotTasking),
                  dockcore::TaskState::kNotTasking, 21000);
  CHECK_EQUAL(1u, link.replies.size());
  STRCMP_CONTAINS("\"seq\":5,\"code\":6,\"error\":\"rejected\"", link.replies[0].c_str());
  CHECK_EQUAL(1u, counters.commands);
  CHECK_EQUAL(1u, counters.commands_rejected);
  CHECK_EQUAL(1u, counters.udp.rejected_later);
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
  link.pending.push_back(request("dock", 1));
  p.poll(1000);
  const std::uint32_t dock_token = actions.submitted[0].token;

  actions.next_result = dockcore::SubmitResult::kReplacedNewest;
  actions.next_displaced = dock_token;
  link.pending.push_back(request("stop", 2));
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

  link.pending.push_back(request("status", 4));
  p.poll(7);
  CHECK_EQUAL(1u, link.replies.size());
  STRCMP_EQUAL("{\"ok\":true,\"cmd\":\"status\",\"seq\":4,\"type\":\"status\",\"stamp_us\":7}",
               link.replies[0].c_str());
  // The camera part: its own fields, named, instead of the status object.
  link.pending.push_back("{\"cmd\":\"status\",\"seq\":5,\"part\":\"camera\"}");
  link.pending.push_back("{\"cmd\":\"status\",\"seq\":6,\"part\":\"main\"}");
  p.poll(8);
  CHECK_EQUAL(3u, link.replies.size());
  STRCMP_EQUAL("{\"ok\":true,\"cmd\":\"status\",\"seq\":5,\"part\":\"camera\",\"camera_frames\":42}",
               link.replies[1].c_str());
  STRCMP_EQUAL("{\"ok\":true,\"cmd\":\"status\",\"seq\":6,\"type\":\"status\",\"stamp_us\":8}",
               link.replies[2].c_str());
}

TEST(DockdHostProtocol, DatagramsThatDoNotParseAreAnsweredWithTheirCodeAndCounted) {
  dockd::HostProtocol p(&link, nullptr, actions, counters);
  link.pending.push_back("{\"cmd\":\"dock\",\"dock_id\":1,\"seq\":7}");
  link.pending.push_back("{\"cmd\":\"dock\",\"seq\":8");
  link.pending.push_back("{\"cmd\":\"fly\",\"seq\":9}");
  link.pending.push_back("{\"cmd\":\"dock\",\"dock_id\":\"x\",\"seq\":10}");
  link.pending.push_back(std::string(600, ' '));
  p.poll(1000);
  CHECK_EQUAL(1u, actions.submitted.size());  // only the dock
  CHECK_EQUAL(4u, link.replies.size());
  STRCMP_EQUAL("{\"ok\":false,\"code\":1,\"error\":\"malformed\",\"message\":\"syntax\"}", link.replies[0].c_str());
  STRCMP_EQUAL(
      "{\"ok\":false,\"seq\":9,\"code\":2,\"error\":\"unknown_command\",\"message\":\"cmd is not one of dock, "
      "undock, stop, cancel, test, status, teach, subscribe, unsubscribe\"}",
      link.replies[1].c_str());
  STRCMP_EQUAL(
      "{\"ok\":false,\"seq\":10,\"code\":3,\"error\":\"bad_field\",\"message\":\"dock_id must be an integer "
      "0..65535\"}",
      link.replies[2].c_str());
  STRCMP_EQUAL("{\"ok\":false,\"code\":4,\"error\":\"too_long\",\"message\":\"datagram longer than 512 bytes\"}",
               link.replies[3].c_str());
  CHECK_EQUAL(1u, counters.udp.requests);
  CHECK_EQUAL(1u, counters.udp.malformed);
  CHECK_EQUAL(1u, counters.udp.unknown_command);
  CHECK_EQUAL(1u, counters.udp.bad_field);
  CHECK_EQUAL(1u, counters.udp.too_long);
  // Host commands refused, though nothing was asked of the daemon: no command_rejected event.
  CHECK_EQUAL(0u, counters.commands_rejected);
  CHECK_EQUAL(4u, p.commands_rejected_total());
  CHECK_TRUE(actions.events.empty());
}

TEST(DockdHostProtocol, AFloodIsReadOverSeveralPolls) {
  dockd::HostProtocol p(&link, nullptr, actions, counters);
  for (int i = 0; i < 70; ++i) link.pending.push_back("{\"cmd\":");
  link.pending.push_back(request("dock", 1));
  p.poll(1000);  // 64 datagrams that ask nothing of the daemon in a row end the poll
  CHECK_EQUAL(64u, link.replies.size());
  CHECK_TRUE(actions.submitted.empty());
  p.poll(21000);
  CHECK_EQUAL(70u, link.replies.size());
  CHECK_EQUAL(1u, actions.submitted.size());
  CHECK_EQUAL(70u, counters.udp.malformed);

  // Datagrams the link drops (foreign peers) count too.
  for (int i = 0; i < 40; ++i) link.pending.push_back("!");
  for (int i = 0; i < 30; ++i) link.pending.push_back("{\"cmd\":");
  link.pending.push_back(request("dock", 2));
  p.poll(41000);
  CHECK_EQUAL(40u, link.c.not_allowed);
  CHECK_EQUAL(70u + 24u, link.replies.size());  // 40 dropped + 24 refused: 64 read
  p.poll(61000);
  CHECK_EQUAL(100u, link.replies.size());
  CHECK_EQUAL(2u, actions.submitted.size());
}

TEST(DockdHostProtocol, SubscriptionsAreAnsweredWithTheLinksTable) {
  dockd::HostProtocol p(&link, nullptr, actions, counters);
  for (std::uint32_t seq = 1; seq <= 3; ++seq) link.pending.push_back(request("subscribe", seq));
  link.pending.push_back(request("unsubscribe", 4));
  p.poll(1000);
  CHECK_EQUAL(4u, link.replies.size());
  STRCMP_EQUAL("{\"ok\":true,\"cmd\":\"subscribe\",\"seq\":1,\"expires_ms\":10000}", link.replies[0].c_str());
  STRCMP_EQUAL("{\"ok\":true,\"cmd\":\"subscribe\",\"seq\":2,\"expires_ms\":10000}", link.replies[1].c_str());
  STRCMP_EQUAL(
      "{\"ok\":false,\"seq\":3,\"code\":8,\"error\":\"subscribers_full\",\"message\":\"subscriber table "
      "full\"}",
      link.replies[2].c_str());
  STRCMP_EQUAL("{\"ok\":true,\"cmd\":\"unsubscribe\",\"seq\":4}", link.replies[3].c_str());
  CHECK_EQUAL(1u, link.subscribers);
  CHECK_EQUAL(1u, link.c.subscribers_rejected);
  CHECK_EQUAL(4u, counters.udp.requests);
  CHECK_EQUAL(0u, p.commands_rejected_total());
  CHECK_TRUE(actions.submitted.empty());
}

TEST_GROUP(DockdHostRequestParser){};

TEST(DockdHostRequestParser, ReadsEveryFieldAndRefusesWhatIsNotInTheProtocol) {
  HostRequest r;
  const char* detail = nullptr;
  const char teach[] = "{\"cmd\":\"teach\",\"dock_id\":3,\"scans\":20,\"seq\":4294967295}";
  CHECK_EQUAL(static_cast<int>(dockd::HostErrorCode::kNone),
              static_cast<int>(dockd::parse_host_request(teach, sizeof teach - 1, r, detail)));
  CHECK_EQUAL(static_cast<int>(HostRequestKind::kTeach), static_cast<int>(r.kind));
  CHECK_TRUE(r.has_dock_id);
  CHECK_EQUAL(3, r.dock_id);
  CHECK_EQUAL(20, r.scans);
  CHECK_TRUE(r.has_seq);
  CHECK_EQUAL(4294967295u, r.seq);
  const char cancel[] = "{\"cmd\":\"cancel\"}";
  CHECK_EQUAL(static_cast<int>(dockd::HostErrorCode::kNone),
              static_cast<int>(dockd::parse_host_request(cancel, sizeof cancel - 1, r, detail)));
  CHECK_EQUAL(static_cast<int>(HostRequestKind::kStop), static_cast<int>(r.kind));
  CHECK_FALSE(r.has_seq);
  STRCMP_EQUAL("stop", dockd::to_string(r.kind));

  struct Bad {
    const char* text;
    dockd::HostErrorCode e;
  } bad[] = {{"{\"seq\":1}", dockd::HostErrorCode::kMalformed},
             {"{\"cmd\":\"dock\",\"scans\":5,\"seq\":2}", dockd::HostErrorCode::kBadField},
             {"{\"cmd\":\"teach\",\"scans\":1001,\"seq\":3}", dockd::HostErrorCode::kBadField},
             {"{\"cmd\":\"dock\",\"speed\":1,\"seq\":4}", dockd::HostErrorCode::kBadField},
             {"{\"cmd\":\"dock\",\"seq\":-1}", dockd::HostErrorCode::kBadField},
             {"{\"cmd\":\"dock\",\"part\":\"camera\",\"seq\":5}", dockd::HostErrorCode::kBadField},
             {"{\"cmd\":\"status\",\"part\":\"lidar\",\"seq\":6}", dockd::HostErrorCode::kBadField},
             {"{\"cmd\":\"status\",\"part\":1,\"seq\":7}", dockd::HostErrorCode::kBadField},
             {"[1]", dockd::HostErrorCode::kMalformed}};
  for (const Bad& b : bad) {
    HostRequest out;
    out.dock_id = 4242;
    CHECK_EQUAL_TEXT(static_cast<int>(b.e),
                     static_cast<int>(dockd::parse_host_request(b.text, std::strlen(b.text), out, detail)), b.text);
    CHECK_EQUAL(4242, out.dock_id);  // untouched but for the echoed seq
    CHECK(std::strlen(detail) > 0);
  }
  HostRequest out;
  const char bad_scans[] = "{\"cmd\":\"dock\",\"scans\":5,\"seq\":2}";
  dockd::parse_host_request(bad_scans, sizeof bad_scans - 1, out, detail);
  CHECK_TRUE(out.has_seq);
  CHECK_EQUAL(2u, out.seq);
}
