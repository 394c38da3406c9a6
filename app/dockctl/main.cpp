// dockctl: the host CLI for dockd's UDP JSON link (docs/dockd.md, "dockctl").
// Exit codes: 0 ok; 1 dockd answered with an error (rejected, unknown dock id, teach failed, ...); 2 usage error;
// 3 no answer within --timeout (dockd not running, wrong port, or the datagram was dropped).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "dockcore/cli/parse_errors.hpp"

namespace {

std::uint64_t mono_ms() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000u + static_cast<std::uint64_t>(ts.tv_nsec) / 1000000u;
}

struct Link {
  int fd = -1;
  sockaddr_in to{};
};

bool send_line(const Link& l, const std::string& s) {
  return ::sendto(l.fd, s.data(), s.size(), 0, reinterpret_cast<const sockaddr*>(&l.to), sizeof l.to) ==
         static_cast<ssize_t>(s.size());
}

/// Waits up to timeout_ms for one datagram from the daemon; "" on timeout.
std::string receive(const Link& l, int timeout_ms) {
  pollfd p{l.fd, POLLIN, 0};
  if (::poll(&p, 1, timeout_ms) <= 0) return "";
  char buf[2048];
  const ssize_t n = ::recv(l.fd, buf, sizeof buf - 1, 0);
  if (n <= 0) return "";
  std::string s(buf, static_cast<std::size_t>(n));
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}

/// True when the reply says "ok": true. The reply may hold more fields than FlatJson keeps, so this looks only for
/// the literal prefix dockd always writes first.
bool reply_ok(const std::string& r) { return r.rfind("{\"ok\":true", 0) == 0; }

/// Prints the status reply's fields named in `keys`, one value per line (strings bare, everything else as JSON).
/// Returns 0, or 1 when the reply is no JSON object or lacks one of them (named on stderr).
int print_fields(const std::string& reply, const std::vector<std::string>& keys) {
  const nlohmann::json j = nlohmann::json::parse(reply, nullptr, false);
  if (!j.is_object()) {
    std::fprintf(stderr, "dockctl: the status reply is not a JSON object\n");
    return 1;
  }
  for (const std::string& k : keys) {
    const auto it = j.find(k);
    if (it == j.end()) {
      std::fprintf(stderr, "dockctl: the status has no field \"%s\"\n", k.c_str());
      return 1;
    }
    std::printf("%s\n", it->is_string() ? it->get<std::string>().c_str() : it->dump().c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"dockctl: command dockd over its UDP link (docs/dockd.md)"};
  app.require_subcommand(1);
  app.fallthrough();  // global options may also follow the subcommand
  std::string host = "127.0.0.1";
  int port = 7300;
  double timeout_s = 2.0;
  app.add_option("--host", host, "dockd address")->capture_default_str();
  app.add_option("--port", port, "dockd UDP port ([host] port)")->capture_default_str()->check(CLI::Range(1, 65535));
  app.add_option("--timeout", timeout_s, "seconds to wait for an answer")->capture_default_str()->check(CLI::Range(0.05, 3600.0));
  int dock_id = -1, scans = 0;
  bool follow = false;
  auto* dock = app.add_subcommand("dock", "dock at a dock (default: dockd's default dock)");
  dock->add_option("--dock", dock_id, "dock id")->check(CLI::Range(0, 65535));
  app.add_subcommand("undock", "leave the dock");
  app.add_subcommand("stop", "stop whatever runs (cancel; clears a fault)");
  auto* status = app.add_subcommand("status", "print dockd's status (one JSON line)");
  auto* follow_opt = status->add_flag("--follow,-f", follow, "subscribe and print the status stream until interrupted");
  std::vector<std::string> fields;
  status->add_option("--field", fields, "print only this field's value (repeatable: one line each, in order)")
      ->excludes(follow_opt);
  std::string part;
  status
      ->add_option("--part", part,
                   "camera: the camera's and the tag fusion's fields; counters: every counter (the status leaves "
                   "each group out when full)")
      ->check(CLI::IsMember({"main", "camera", "counters"}))
      ->excludes(follow_opt);
  auto* test =
      app.add_subcommand("test", "recognition-only test mode: report the dock estimate, never move ('stop' ends it)");
  test->add_option("--dock", dock_id, "dock id (default: dockd's default dock)")->check(CLI::Range(0, 65535));
  auto* teach = app.add_subcommand("teach", "robot placed on the charger by hand: store the dock's docked-pose target");
  teach->add_option("--dock", dock_id, "dock id")->check(CLI::Range(0, 65535));
  teach->add_option("--scans", scans, "scans to average (default: dockd's [state] teach_scans)")->check(CLI::Range(1, 1000));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return dockcore::cli::exit_for_parse_error(app, e, "dockctl");
  }

  Link l;
  l.to.sin_family = AF_INET;
  l.to.sin_port = htons(static_cast<std::uint16_t>(port));
  if (inet_pton(AF_INET, host.c_str(), &l.to.sin_addr) != 1) {
    std::fprintf(stderr, "dockctl: --host %s is not an IPv4 address\n", host.c_str());
    return 2;
  }
  l.fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (l.fd < 0) {
    std::perror("dockctl: socket");
    return 3;
  }
  const std::uint32_t seq = static_cast<std::uint32_t>(mono_ms() & 0x7FFFFFFF);
  const std::string name = app.get_subcommands().front()->get_name();
  std::string req = "{\"cmd\":\"" + name + "\",\"seq\":" + std::to_string(seq);
  if (dock_id >= 0) req += ",\"dock_id\":" + std::to_string(dock_id);
  if (scans > 0) req += ",\"scans\":" + std::to_string(scans);
  if (!part.empty()) req += ",\"part\":\"" + part + "\"";
  req += "}";
  const int timeout_ms = static_cast<int>(timeout_s * 1000);

  if (name == "status" && follow) {
    // Subscriptions expire (dockd's [host] subscription_ms): renew every 3 s.
    std::uint64_t renew = 0;
    std::uint64_t last_rx = mono_ms();
    for (;;) {
      const std::uint64_t now = mono_ms();
      if (now >= renew) {
        send_line(l, "{\"cmd\":\"subscribe\",\"seq\":" + std::to_string(seq) + "}");
        renew = now + 3000;
      }
      const std::string r = receive(l, 500);
      if (r.empty()) {
        if (mono_ms() - last_rx > static_cast<std::uint64_t>(timeout_ms) + 3000u) {
          std::fprintf(stderr, "dockctl: no status from %s:%d\n", host.c_str(), port);
          return 3;
        }
        continue;
      }
      last_rx = mono_ms();
      if (r.rfind("{\"ok\":false", 0) == 0) {
        std::printf("%s\n", r.c_str());
        return 1;
      }
      if (r.rfind("{\"type\":\"status\"", 0) == 0) {
        std::printf("%s\n", r.c_str());
        std::fflush(stdout);
      }
    }
  }

  if (!send_line(l, req)) {
    std::perror("dockctl: sendto");
    return 3;
  }
  // Teach takes as long as its scans: wait for the final answer (status stream lines are not for us).
  const std::uint64_t deadline = mono_ms() + static_cast<std::uint64_t>(timeout_ms) + (name == "teach" ? 15000u : 0u);
  for (;;) {
    const std::uint64_t now = mono_ms();
    if (now >= deadline) break;
    const std::string r = receive(l, static_cast<int>(deadline - now));
    if (r.empty()) break;
    if (r.rfind("{\"type\":\"status\"", 0) == 0) continue;
    if (!fields.empty() && reply_ok(r)) return print_fields(r, fields);
    std::printf("%s\n", r.c_str());
    return reply_ok(r) ? 0 : 1;
  }
  std::fprintf(stderr, "dockctl: no answer from dockd at %s:%d within %.1f s\n", host.c_str(), port, timeout_s);
  return 3;
}
