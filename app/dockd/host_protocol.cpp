// dockd: the host protocol — UDP request datagrams parsed and, with the CAN host commands, turned into replies and
// queued core commands, the replies to queued requests once the core takes them, and the status on both links.
#include "host_protocol.hpp"

#include <cstdio>
#include <cstring>

#include "dockcore/drivers/flat_json.hpp"

namespace dockd {

using dockcore::HostCommandType;
using dockcore::SubmitResult;
using dockcore::TaskState;
using dockcore::drivers::FlatJson;
using dockcore::drivers::FlatJsonError;
using dockcore::hal::kMaxHostDatagram;

const char* to_string(HostRequestKind k) {
  switch (k) {
    case HostRequestKind::kDock:
      return "dock";
    case HostRequestKind::kStop:
      return "stop";
    case HostRequestKind::kUndock:
      return "undock";
    case HostRequestKind::kTest:
      return "test";
    case HostRequestKind::kStatus:
      return "status";
    case HostRequestKind::kTeach:
      return "teach";
    case HostRequestKind::kSubscribe:
      return "subscribe";
    case HostRequestKind::kUnsubscribe:
      return "unsubscribe";
  }
  return "?";
}

const char* to_string(HostErrorCode e) {
  switch (e) {
    case HostErrorCode::kNone:
      return "none";
    case HostErrorCode::kMalformed:
      return "malformed";
    case HostErrorCode::kUnknownCommand:
      return "unknown_command";
    case HostErrorCode::kBadField:
      return "bad_field";
    case HostErrorCode::kTooLong:
      return "too_long";
    case HostErrorCode::kUnknownDockId:
      return "unknown_dock_id";
    case HostErrorCode::kRejected:
      return "rejected";
    case HostErrorCode::kTeachFailed:
      return "teach_failed";
    case HostErrorCode::kSubscribersFull:
      return "subscribers_full";
    case HostErrorCode::kBusy:
      return "busy";
    case HostErrorCode::kReplyTooLong:
      return "reply_too_long";
  }
  return "?";
}

HostErrorCode parse_host_request(const char* data, std::size_t len, HostRequest& out, const char*& detail) {
  detail = "";
  if (len > kMaxHostDatagram) {
    detail = "datagram longer than 512 bytes";
    return HostErrorCode::kTooLong;
  }
  FlatJson j;
  const FlatJsonError je = j.parse(data, len);
  if (je != FlatJsonError::kOk) {
    detail = to_string(je);
    return HostErrorCode::kMalformed;
  }
  HostRequest r;
  std::int64_t v = 0;
  if (j.has("seq")) {
    if (!j.get_int("seq", 0, 4294967295LL, v)) {
      detail = "seq must be an integer 0..4294967295";
      return HostErrorCode::kBadField;
    }
    r.has_seq = true;
    r.seq = static_cast<std::uint32_t>(v);
    out.has_seq = true;  // echoed in the error reply even when the rest is bad
    out.seq = r.seq;
  }
  const char* cmd = nullptr;
  if (!j.get_string("cmd", cmd)) {
    detail = "\"cmd\" (a string) is required";
    return HostErrorCode::kMalformed;
  }
  struct Name {
    const char* name;
    HostRequestKind kind;
  };
  static const Name kNames[] = {{"dock", HostRequestKind::kDock},
                                {"stop", HostRequestKind::kStop},
                                {"cancel", HostRequestKind::kStop},
                                {"undock", HostRequestKind::kUndock},
                                {"test", HostRequestKind::kTest},
                                {"status", HostRequestKind::kStatus},
                                {"teach", HostRequestKind::kTeach},
                                {"subscribe", HostRequestKind::kSubscribe},
                                {"unsubscribe", HostRequestKind::kUnsubscribe}};
  bool found = false;
  for (const Name& n : kNames) {
    if (std::strcmp(n.name, cmd) == 0) {
      r.kind = n.kind;
      found = true;
    }
  }
  if (!found) {
    detail = "cmd is not one of dock, undock, stop, cancel, test, status, teach, subscribe, unsubscribe";
    return HostErrorCode::kUnknownCommand;
  }
  for (std::size_t i = 0; i < j.size(); ++i) {
    const char* k = j.key(i);
    if (std::strcmp(k, "cmd") != 0 && std::strcmp(k, "seq") != 0 && std::strcmp(k, "dock_id") != 0 &&
        std::strcmp(k, "scans") != 0 && std::strcmp(k, "part") != 0) {
      detail = "unknown field (expected cmd, seq, dock_id, scans, part)";
      return HostErrorCode::kBadField;
    }
  }
  if (j.has("dock_id")) {
    if (!j.get_int("dock_id", 0, 65535, v)) {
      detail = "dock_id must be an integer 0..65535";
      return HostErrorCode::kBadField;
    }
    r.has_dock_id = true;
    r.dock_id = static_cast<std::uint16_t>(v);
  }
  if (j.has("scans")) {
    if (r.kind != HostRequestKind::kTeach || !j.get_int("scans", 1, 1000, v)) {
      detail = "scans must be an integer 1..1000 and only with teach";
      return HostErrorCode::kBadField;
    }
    r.scans = static_cast<std::uint16_t>(v);
  }
  if (j.has("part")) {
    const char* part = "";
    const bool named = j.get_string("part", part);
    const bool camera = named && std::strcmp(part, "camera") == 0;
    const bool counters = named && std::strcmp(part, "counters") == 0;
    if (r.kind != HostRequestKind::kStatus || (!camera && !counters && std::strcmp(part, "main") != 0)) {
      detail = "part must be \"main\", \"camera\" or \"counters\" and only with status";
      return HostErrorCode::kBadField;
    }
    r.part = camera ? StatusPart::kCamera : counters ? StatusPart::kCounters : StatusPart::kMain;
  }
  out = r;
  return HostErrorCode::kNone;
}

std::size_t format_host_error(char* buf, std::size_t size, bool has_seq, std::uint32_t seq, HostErrorCode code,
                              const char* message, const char* type) {
  JsonWriter w(buf, size);
  if (type != nullptr) w.str("type", type);
  w.boolean("ok", false);
  if (has_seq) w.uint("seq", seq);
  w.uint("code", static_cast<unsigned>(code)).str("error", to_string(code)).str_cut("message", message, 255);
  return w.finish();
}

HostProtocol::HostProtocol(dockcore::hal::HostRequestLink* udp, dockcore::hal::HostLink* can, HostActions& actions,
                           DaemonCounters& counters)
    : udp_(udp), can_(can), actions_(actions), counters_(counters) {}

std::uint32_t HostProtocol::hold(const HostRequest& r) {
  // A free slot always exists: at most the queue's capacity of requests wait, plus the one being submitted.
  for (Slot& slot : slots_) {
    if (slot.token != 0) continue;
    if (++next_token_ == 0) next_token_ = 1;  // 0: no reply (CAN, resumes)
    slot.token = next_token_;
    slot.request = r;
    return next_token_;
  }
  return 0;
}

const HostProtocol::Slot* HostProtocol::take(std::uint32_t token) {
  if (token == 0) return nullptr;
  for (Slot& slot : slots_) {
    if (slot.token != token) continue;
    slot.token = 0;
    return &slot;
  }
  return nullptr;
}

SubmitResult HostProtocol::submit(HostCommandType type, std::uint16_t dock_id, std::uint32_t token) {
  std::uint32_t displaced = 0;
  const SubmitResult res = actions_.submit(type, dock_id, token, displaced);
  if (res != SubmitResult::kQueued) ++counters_.queue_overflows;
  if (res == SubmitResult::kReplacedNewest) take(displaced);  // that request goes unanswered
  if (res == SubmitResult::kFull) take(token);
  return res;
}

namespace {

/// The error object that goes instead of a reply or status object that did not fit one datagram (seq as `has_seq`;
/// `type` as format_host_error's).
std::size_t too_long_error(char* buf, std::size_t size, bool has_seq, std::uint32_t seq, const char* what,
                           const char* type = nullptr) {
  char msg[96];
  std::snprintf(msg, sizeof msg, "the %s did not fit one datagram (%zu bytes)", what, dockcore::hal::kMaxHostReply);
  return format_host_error(buf, size, has_seq, seq, HostErrorCode::kReplyTooLong, msg, type);
}

}  // namespace

void HostProtocol::reply(const HostRequest& r, const char* json, std::size_t len) {
  if (udp_ == nullptr) return;
  if (len == 0 || len + 1 > dockcore::hal::kMaxHostReply) {
    // Silence would look like a lost datagram to the host: it gets an error it can act on.
    ++counters_.replies_too_long;
    char buf[256];
    char what[32];
    std::snprintf(what, sizeof what, "%s reply", to_string(r.kind));
    udp_->reply(r.peer, buf, too_long_error(buf, sizeof buf, r.has_seq, r.seq, what));
    return;
  }
  udp_->reply(r.peer, json, len);
}

void HostProtocol::reply_error(const HostRequest& r, HostErrorCode code, const char* message) {
  char buf[512];
  const std::size_t n = format_host_error(buf, sizeof buf, r.has_seq, r.seq, code, message);
  reply(r, buf, n);
  ++counters_.commands_rejected;
  ++counters_.udp.rejected_later;
  if (!refusal_log_.admit(r.stamp_us)) return;
  EventLine e(r.stamp_us, "command_rejected");
  e.w.str("source", "udp").str("cmd", to_string(r.kind)).uint("seq", r.seq).str("error", to_string(code));
  actions_.log_event(e, LogLevel::kWarn);
}

void HostProtocol::report_held_events(std::uint64_t now_us) {
  const std::uint32_t n = refusal_log_.take_held(now_us);
  if (n == 0) return;
  EventLine e(now_us, "events_held_back");
  e.w.str("of", "refusals").uint("count", n).uint("limit_per_s", EventRateLimit::kPerWindow);
  actions_.log_event(e, LogLevel::kWarn);
}

bool HostProtocol::handle_datagram(const dockcore::hal::HostDatagram& d, std::uint64_t now_us) {
  HostRequest r;
  const char* detail = "";
  const HostErrorCode e = parse_host_request(d.data, d.len, r, detail);
  if (e != HostErrorCode::kNone) {
    // Answered and counted, but not a command_rejected event: nothing was asked of the daemon.
    switch (e) {
      case HostErrorCode::kTooLong:
        ++counters_.udp.too_long;
        break;
      case HostErrorCode::kUnknownCommand:
        ++counters_.udp.unknown_command;
        break;
      case HostErrorCode::kBadField:
        ++counters_.udp.bad_field;
        break;
      default:
        ++counters_.udp.malformed;
        break;
    }
    char buf[512];
    const std::size_t n = format_host_error(buf, sizeof buf, r.has_seq, r.seq, e, detail);
    udp_->reply(d.peer, buf, n);
    return false;
  }
  r.peer = d.peer;
  r.stamp_us = d.stamp_us;
  ++counters_.udp.requests;
  if (r.kind == HostRequestKind::kSubscribe || r.kind == HostRequestKind::kUnsubscribe) {
    handle_subscription(r, now_us);
    return false;
  }
  handle_udp(r, now_us);
  return true;
}

void HostProtocol::handle_subscription(const HostRequest& r, std::uint64_t now_us) {
  char buf[256];
  if (r.kind == HostRequestKind::kUnsubscribe) {
    udp_->unsubscribe(r.peer);
    JsonWriter w(buf, sizeof buf);
    w.boolean("ok", true).str("cmd", "unsubscribe").uint("seq", r.seq);
    reply(r, buf, w.finish());
    return;
  }
  std::uint32_t expires_ms = 0;
  if (!udp_->subscribe(r.peer, now_us, expires_ms)) {
    const std::size_t n =
        format_host_error(buf, sizeof buf, r.has_seq, r.seq, HostErrorCode::kSubscribersFull, "subscriber table full");
    reply(r, buf, n);
    return;
  }
  JsonWriter w(buf, sizeof buf);
  w.boolean("ok", true).str("cmd", "subscribe").uint("seq", r.seq).uint("expires_ms", expires_ms);
  reply(r, buf, w.finish());
}

void HostProtocol::handle_udp(const HostRequest& r, std::uint64_t now_us) {
  switch (r.kind) {
    case HostRequestKind::kStatus: {
      // The reply is the status object (or the camera or counters part, after "part") with
      // {"ok":true,"cmd":"status","seq":N} in front.
      char out[dockcore::hal::kMaxHostReply];
      JsonWriter w(out, sizeof out);
      w.boolean("ok", true).str("cmd", "status").uint("seq", r.seq);
      if (r.part == StatusPart::kCamera) {
        w.str("part", "camera");
        actions_.camera_fields(w);
      } else if (r.part == StatusPart::kCounters) {
        w.str("part", "counters");
        actions_.counter_fields(w, now_us);
      } else {
        actions_.status_fields(w, now_us);
      }
      reply(r, out, w.finish());
      return;
    }
    case HostRequestKind::kTeach:
      actions_.start_teach(r, now_us);
      return;
    case HostRequestKind::kDock:
    case HostRequestKind::kTest: {
      const DockdConfig& cfg = actions_.config();
      const std::uint16_t id = r.has_dock_id ? r.dock_id : cfg.default_dock_id;
      if (cfg.find_dock(id) == nullptr) {
        char msg[96];
        std::snprintf(msg, sizeof msg, "dock id %u is not in the dock database", id);
        reply_error(r, HostErrorCode::kUnknownDockId, msg);
        return;
      }
      const HostCommandType type =
          r.kind == HostRequestKind::kDock ? HostCommandType::kDock : HostCommandType::kTestMode;
      if (submit(type, id, hold(r)) != SubmitResult::kQueued) {
        reply_error(r, HostErrorCode::kBusy, "command queue full (8 pending): retry later");
      }
      return;
    }
    case HostRequestKind::kUndock:
    case HostRequestKind::kStop: {
      const HostCommandType type =
          r.kind == HostRequestKind::kUndock ? HostCommandType::kUndock : HostCommandType::kCancel;
      if (r.kind == HostRequestKind::kStop) actions_.cancel_teach(now_us);
      // A stop is never lost: when the queue is full it replaces the newest queued command.
      if (submit(type, actions_.active_dock_id(), hold(r)) == SubmitResult::kFull) {
        reply_error(r, HostErrorCode::kBusy, "command queue full (8 pending): retry later");
      }
      return;
    }
    case HostRequestKind::kSubscribe:
    case HostRequestKind::kUnsubscribe:
      return;  // handle_subscription
  }
}

void HostProtocol::poll(std::uint64_t now_us) {
  if (udp_ != nullptr) {
    // Datagrams the link has read, those it dropped (foreign peers) included: a bound on the reads between two
    // requests, whoever sent them.
    const auto reads = [this] { return udp_->counters().datagrams + udp_->counters().not_allowed; };
    dockcore::hal::HostDatagram d;
    int requests = 0;
    std::uint32_t round_start = reads();
    while (requests < 64 && reads() - round_start < 64 && udp_->poll_datagram(d, now_us)) {
      if (handle_datagram(d, now_us)) {
        ++requests;
        round_start = reads();
      }
    }
  }
  if (can_ != nullptr) {
    dockcore::hal::HostCommandMessage m;
    for (int i = 0; i < 16 && can_->poll_command(m); ++i) {
      const HostCommandType type = static_cast<HostCommandType>(m.command);
      if (type == HostCommandType::kCancel) actions_.cancel_teach(now_us);
      if (submit(type, m.dock_id, 0) != SubmitResult::kQueued) ++counters_.commands_rejected;
      EventLine e(now_us, "command");
      e.w.str("source", "can").uint("command", m.command).uint("dock_id", m.dock_id).uint("seq", m.sequence);
      actions_.log_event(e, LogLevel::kInfo);
    }
  }
}

void HostProtocol::command_taken(const dockcore::TickOutput& out, TaskState before, std::uint64_t now_us) {
  ++counters_.commands;
  const HostCommandType type = out.command.command.type;
  const std::uint16_t dock_id = out.command.command.dock_id;
  const bool accepted = out.command_result == dockcore::CommandResult::kAccepted ||
                        out.command_result == dockcore::CommandResult::kAlreadyDocked;
  const Slot* udp = take(out.command.token);
  const TaskState after = out.status.state;
  // A refused UDP request is counted by reply_error, with its error reply; a CAN or resumed command here.
  if (!accepted && udp == nullptr) ++counters_.commands_rejected;
  if (udp != nullptr) {
    if (accepted) {
      char buf[256];
      JsonWriter w(buf, sizeof buf);
      w.boolean("ok", true)
          .str("cmd", to_string(udp->request.kind))
          .uint("seq", udp->request.seq)
          .str("result", dockcore::to_string(out.command_result))
          .uint("dock_id", dock_id)
          .str("state", dockcore::to_string(after));
      reply(udp->request, buf, w.finish());
    } else {
      char msg[128];
      std::snprintf(msg, sizeof msg, "task manager: %s (state %s)", dockcore::to_string(out.command_result),
                    dockcore::to_string(before));
      reply_error(udp->request, HostErrorCode::kRejected, msg);
    }
  }
  if (accepted || refusal_log_.admit(now_us)) {
    EventLine e(now_us, "command_result");
    e.w.str("source", out.command.resume ? "resume" : (udp != nullptr ? "udp" : "can"))
        .uint("command", static_cast<unsigned>(type))
        .uint("dock_id", dock_id)
        .str("result", dockcore::to_string(out.command_result));
    actions_.log_event(e, accepted ? LogLevel::kInfo : LogLevel::kWarn);
  }
}

void HostProtocol::publish_status(const dockcore::hal::StatusMessage& can_status, std::uint64_t now_us) {
  if (can_ != nullptr) can_->send_status(can_status);
  if (udp_ != nullptr && udp_->subscriber_count() > 0) {
    char buf[dockcore::hal::kMaxHostReply];
    JsonWriter w(buf, sizeof buf);
    actions_.status_fields(w, now_us);
    std::size_t n = w.finish();
    if (n == 0) {
      ++counters_.replies_too_long;
      // Marked as a stream object, so a host waiting for its own reply does not take it for one.
      n = too_long_error(buf, sizeof buf, false, 0, "status", "status");
    }
    udp_->publish(buf, n, now_us);
  }
  ++counters_.status_sent;
}

std::uint32_t HostProtocol::commands_rejected_total() const {
  // Datagrams that did not parse are host commands refused too, though not counted in commands_rejected.
  return counters_.commands_rejected + counters_.udp.refused();
}

std::uint32_t HostProtocol::udp_not_allowed() const {
  return udp_ != nullptr ? udp_->counters().not_allowed : 0u;
}

std::uint32_t HostProtocol::can_rejected() const {
  return can_ != nullptr ? can_->host_commands_rejected() : 0u;
}

bool HostProtocol::set_allowlist(const std::vector<std::string>& allowlist, std::string& error) {
  return udp_ == nullptr || udp_->set_allowlist(allowlist, error);
}

}  // namespace dockd
