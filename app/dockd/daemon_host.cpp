// dockd: the host protocol — UDP requests and CAN host commands turned into replies and queued core commands, and
// the replies to queued requests once the core takes them.
#include "daemon.hpp"
#include "daemon_internal.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>

namespace dockd {

std::uint32_t Daemon::hold_reply(const HostRequest& r) {
  // A free slot always exists: at most the queue's capacity of requests wait, plus the one being submitted.
  for (UdpReply& slot : replies_) {
    if (slot.token != 0) continue;
    if (++next_token_ == 0) next_token_ = 1;  // 0: no reply (CAN, resumes)
    slot.token = next_token_;
    slot.request = r;
    return next_token_;
  }
  return 0;
}

const Daemon::UdpReply* Daemon::take_reply(std::uint32_t token) {
  if (token == 0) return nullptr;
  for (UdpReply& slot : replies_) {
    if (slot.token != token) continue;
    slot.token = 0;
    return &slot;
  }
  return nullptr;
}

dockcore::SubmitResult Daemon::submit(dockcore::HostCommandType type, std::uint16_t dock_id, std::uint32_t token) {
  dockcore::QueuedCommand c;
  c.command = dockcore::HostCommand{type, dock_id};
  c.token = token;
  dockcore::QueuedCommand replaced;
  if (loop_record_) loop_record_->submit(c);
  const dockcore::SubmitResult res = core_->submit(c, &replaced);
  if (res != dockcore::SubmitResult::kQueued) ++counters_.queue_overflows;
  if (res == dockcore::SubmitResult::kReplacedNewest) take_reply(replaced.token);  // that request goes unanswered
  if (res == dockcore::SubmitResult::kFull) take_reply(token);
  return res;
}

void Daemon::reply_json(const HostRequest& r, const char* json, std::size_t len) {
  // A reply that did not fit its buffer (len 0) reaches the link too, which counts it as a send failure.
  if (io_.udp_host != nullptr) io_.udp_host->reply(r.peer, json, len);
}

void Daemon::reply_error(const HostRequest& r, HostErrorCode code, const char* msg) {
  char buf[512];
  const std::size_t n = dockcore::drivers::format_host_error(buf, sizeof buf, r.has_seq, r.seq, code, msg);
  reply_json(r, buf, n);
  ++counters_.commands_rejected;
  if (io_.udp_host != nullptr) io_.udp_host->count_rejected();
  if (!refusal_log_.admit(r.stamp_us)) return;
  EventLine e(r.stamp_us, "command_rejected");
  e.w.str("source", "udp").str("cmd", to_string(r.kind)).uint("seq", r.seq).str("error", to_string(code));
  log_event(e, LogLevel::kWarn);
}

void Daemon::report_held_events(std::uint64_t now_us) {
  const std::uint32_t n = refusal_log_.take_held(now_us);
  if (n == 0) return;
  EventLine e(now_us, "events_held_back");
  e.w.str("of", "refusals").uint("count", n).uint("limit_per_s", EventRateLimit::kPerWindow);
  log_event(e, LogLevel::kWarn);
}

void Daemon::handle_udp_request(const HostRequest& r, std::uint64_t now_us) {
  switch (r.kind) {
    case HostRequestKind::kStatus: {
      // The reply is the status object with {"ok":true,"cmd":"status","seq":N} in front.
      char out[dockcore::drivers::kMaxHostReply];
      dockcore::drivers::JsonWriter w(out, sizeof out);
      w.boolean("ok", true).str("cmd", "status").uint("seq", r.seq);
      status_fields(w, now_us);
      reply_json(r, out, w.finish());
      return;
    }
    case HostRequestKind::kTeach:
      start_teach(r, now_us);
      return;
    case HostRequestKind::kDock:
    case HostRequestKind::kTest: {
      const std::uint16_t id = r.has_dock_id ? r.dock_id : cfg_.default_dock_id;
      if (cfg_.find_dock(id) == nullptr) {
        char msg[96];
        std::snprintf(msg, sizeof msg, "dock id %u is not in the dock database", id);
        reply_error(r, HostErrorCode::kUnknownDockId, msg);
        return;
      }
      const HostCommandType type =
          r.kind == HostRequestKind::kDock ? HostCommandType::kDock : HostCommandType::kTestMode;
      if (submit(type, id, hold_reply(r)) != dockcore::SubmitResult::kQueued) {
        reply_error(r, HostErrorCode::kBusy, "command queue full (8 pending): retry later");
      }
      return;
    }
    case HostRequestKind::kUndock:
    case HostRequestKind::kStop: {
      const HostCommandType type =
          r.kind == HostRequestKind::kUndock ? HostCommandType::kUndock : HostCommandType::kCancel;
      if (r.kind == HostRequestKind::kStop && teach_.active) finish_teach(false, "cancelled by stop", now_us);
      // A stop is never lost: when the queue is full it replaces the newest queued command.
      if (submit(type, active_dock_, hold_reply(r)) == dockcore::SubmitResult::kFull) {
        reply_error(r, HostErrorCode::kBusy, "command queue full (8 pending): retry later");
      }
      return;
    }
    case HostRequestKind::kSubscribe:
    case HostRequestKind::kUnsubscribe:
      return;  // handled by the link
  }
}

void Daemon::poll_hosts(std::uint64_t now_us) {
  if (io_.udp_host != nullptr) {
    HostRequest r;
    // Bounded per tick: a flood is answered over several ticks instead of stalling this one.
    for (int i = 0; i < 64 && io_.udp_host->poll_request(r, now_us); ++i) handle_udp_request(r, now_us);
  }
  if (io_.can_host != nullptr) {
    dockcore::hal::HostCommandMessage m;
    for (int i = 0; i < 16 && io_.can_host->poll_command(m); ++i) {
      const HostCommandType type = static_cast<HostCommandType>(m.command);
      if (type == HostCommandType::kCancel && teach_.active) finish_teach(false, "cancelled by stop", now_us);
      if (submit(type, m.dock_id, 0) != dockcore::SubmitResult::kQueued) ++counters_.commands_rejected;
      EventLine e(now_us, "command");
      e.w.str("source", "can").uint("command", m.command).uint("dock_id", m.dock_id).uint("seq", m.sequence);
      log_event(e);
    }
  }
}

}  // namespace dockd
