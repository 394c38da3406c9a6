// dock-sim replay: a dockd session's loop record (DIR/loop.rec, [record] loop) run through a fresh core, every tick's
// output compared with what dockd's core produced (dockcore/drivers/loop_record.hpp).
#include <cinttypes>
#include <cstdio>
#include <memory>
#include <string>

#include "commands.hpp"
#include "dockcore/drivers/loop_record.hpp"

namespace docksim_cli {
namespace {

void print_digest(const char* who, const dockcore::drivers::TickDigest& d) {
  std::printf("  %-9s state %u phase %u fault %u command %s (result %u, token %u) resume %u charge %u\n", who,
              static_cast<unsigned>(d.state), static_cast<unsigned>(d.phase), static_cast<unsigned>(d.fault),
              d.command_taken != 0 ? "taken" : "none", static_cast<unsigned>(d.command_result),
              static_cast<unsigned>(d.token), static_cast<unsigned>(d.resume), static_cast<unsigned>(d.charge_enable));
  std::printf("  %-9s wheels %.17g %.17g %.17g %.17g rad/s, drive vx %.17g wz %.17g, dock %.17g %.17g %.17g\n", "",
              static_cast<double>(d.wheels[0]), static_cast<double>(d.wheels[1]), static_cast<double>(d.wheels[2]),
              static_cast<double>(d.wheels[3]), static_cast<double>(d.drive_cmd[0]),
              static_cast<double>(d.drive_cmd[2]), static_cast<double>(d.dock_pose[0]),
              static_cast<double>(d.dock_pose[1]), static_cast<double>(d.dock_pose[2]));
}

int run(const std::string& path) {
  const dockcore::drivers::ReplayResult r = dockcore::drivers::replay_loop_record(path);
  if (!r.error.empty()) {
    std::fprintf(stderr, "dock-sim replay: %s\n", r.error.c_str());
    return 2;
  }
  if (r.diverged) {
    std::printf("dock-sim replay: %s: DIVERGED at tick %" PRIu64 " (t = %" PRIu64 " us): %s differs\n", path.c_str(),
                r.diverged_tick, r.diverged_now_us, r.diverged_field.c_str());
    print_digest("recorded", r.recorded);
    print_digest("replayed", r.replayed);
    return 1;
  }
  std::printf("dock-sim replay: %s: %" PRIu64 " records, %" PRIu64 " ticks, %" PRIu64 " scans, %" PRIu64
              " commands: every tick reproduced bit for bit%s\n",
              path.c_str(), r.records, r.ticks, r.scans, r.commands,
              r.truncated ? " (the file ends inside a record: replayed up to there)" : "");
  return 0;
}

}  // namespace

void register_replay(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  CLI::App* sub = app.add_subcommand(
      "replay",
      "Run a dockd loop record (DIR/loop.rec, written with [record] loop = true or dockd --record-loop) through a "
      "fresh core and compare every tick's output (wheel speeds, drive command, state, phase, fault, command "
      "results, dock pose) bit for bit. Exit 0 when every tick is reproduced, 1 at the first divergence (printed), "
      "2 for a bad file or arguments.");
  sub->add_option("record", *path, "Loop record file (loop.rec)")->required();
  sub->callback([path]() {
    const int rc = run(*path);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace docksim_cli
