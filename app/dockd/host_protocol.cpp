// dockd: the host protocol — UDP requests and CAN host commands turned into replies and queued core commands, the
// replies to queued requests once the core takes them, and the status on both links.
#include "host_protocol.hpp"

#include <cstdio>

namespace dockd {

using dockcore::HostCommandType;
using dockcore::SubmitResult;
using dockcore::TaskState;
using dockcore::drivers::HostErrorCode;
using dockcore::hal::HostRequest;
using dockcore::hal::HostRequestKind;

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

void HostProtocol::reply(const HostRequest& r, const char* json, std::size_t len) {
  if (udp_ != nullptr) udp_->reply(r.peer, json, len);
}

void HostProtocol::reply_error(const HostRequest& r, HostErrorCode code, const char* message) {
  char buf[512];
  const std::size_t n = dockcore::drivers::format_host_error(buf, sizeof buf, r.has_seq, r.seq, code, message);
  reply(r, buf, n);
  ++counters_.commands_rejected;
  if (udp_ != nullptr) udp_->count_rejected();
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

void HostProtocol::handle_udp(const HostRequest& r, std::uint64_t now_us) {
  switch (r.kind) {
    case HostRequestKind::kStatus: {
      // The reply is the status object with {"ok":true,"cmd":"status","seq":N} in front.
      char out[dockcore::drivers::kMaxHostReply];
      dockcore::drivers::JsonWriter w(out, sizeof out);
      w.boolean("ok", true).str("cmd", "status").uint("seq", r.seq);
      actions_.status_fields(w, now_us);
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
      return;  // handled by the link
  }
}

void HostProtocol::poll(std::uint64_t now_us) {
  if (udp_ != nullptr) {
    HostRequest r;
    for (int i = 0; i < 64 && udp_->poll_request(r, now_us); ++i) handle_udp(r, now_us);
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
      dockcore::drivers::JsonWriter w(buf, sizeof buf);
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
    char buf[dockcore::drivers::kMaxHostReply];
    dockcore::drivers::JsonWriter w(buf, sizeof buf);
    actions_.status_fields(w, now_us);
    const std::size_t n = w.finish();
    if (n > 0) udp_->publish(buf, n, now_us);
  }
  ++counters_.status_sent;
}

std::uint32_t HostProtocol::commands_rejected_total() const {
  // Requests the UDP link refused before dockd saw them (it answered them itself): still host commands refused.
  return counters_.commands_rejected + (udp_ != nullptr ? udp_->counters().refused() : 0u);
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
