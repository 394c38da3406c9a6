#pragma once
// chassis-sim's lidar: the LidarEmitter of dockcore_emu configured from the command line, with the sensor faults a
// HIL case scripts (stall, unplug, corruption) on the motion clock.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>

#include "dockcore/emu/lidar_emitter.hpp"

struct LidarOutOptions {
  std::string protocol = "ld06";
  std::string pty_link;       ///< pty mode: symlink path dockd's serial driver opens.
  std::string udp;            ///< UDP mode: HOST:PORT.
  double corrupt_fraction = 0;
  double drop_fraction = 0;
  double stall_at_s = -1, stall_for_s = 0;      ///< Motion-clock times.
  double unplug_at_s = -1, unplug_for_s = 0;
  std::uint64_t seed = 7;
};

inline void add_lidar_out_options(CLI::App& app, LidarOutOptions& o) {
  app.add_option("--lidar-protocol", o.protocol, "ld06 | rplidar | lakibeam");
  app.add_option("--lidar-pty", o.pty_link, "Serial lidar on a pty; a symlink to it is made at this path");
  app.add_option("--lidar-udp", o.udp, "UDP lidar: send datagrams to HOST:PORT");
  app.add_option("--lidar-corrupt", o.corrupt_fraction, "Fraction of lidar bytes with a flipped bit (0..1)");
  app.add_option("--lidar-drop", o.drop_fraction, "Fraction of lidar packets not sent (0..1)");
  app.add_option("--lidar-stall-at", o.stall_at_s, "Lidar stops sending this long after motion start (s)");
  app.add_option("--lidar-stall-for", o.stall_for_s, "... for this long (s)");
  app.add_option("--lidar-unplug-at", o.unplug_at_s, "Lidar pty closed this long after motion start (s)");
  app.add_option("--lidar-unplug-for", o.unplug_for_s, "... and re-created after this long (s)");
}

/// Opens the emitter; nullptr with a message when the options are wrong or the pty/socket cannot be opened.
inline std::unique_ptr<dockcore::emu::LidarEmitter> open_lidar_out(const LidarOutOptions& o, std::string& err) {
  dockcore::emu::LidarEmitterOptions e;
  if (!dockcore::emu::parse_emu_protocol(o.protocol, &e.protocol)) {
    err = "unknown --lidar-protocol '" + o.protocol + "' (ld06 | rplidar | lakibeam)";
    return nullptr;
  }
  if (o.pty_link.empty() == o.udp.empty()) {
    err = "give exactly one of --lidar-pty PATH and --lidar-udp HOST:PORT";
    return nullptr;
  }
  if (!o.udp.empty()) {
    const auto colon = o.udp.rfind(':');
    if (colon == std::string::npos) {
      err = "--lidar-udp wants HOST:PORT, got '" + o.udp + "'";
      return nullptr;
    }
    e.udp_host = o.udp.substr(0, colon);
    e.udp_port = static_cast<std::uint16_t>(std::stoul(o.udp.substr(colon + 1)));
  }
  e.pty_link = o.pty_link;
  e.corrupt_fraction = o.corrupt_fraction;
  e.drop_fraction = o.drop_fraction;
  e.seed = o.seed;
  return dockcore::emu::LidarEmitter::open(e, err);
}

/// Applies the scripted stall/unplug windows for motion time `mt` (negative before motion starts).
inline void lidar_faults(dockcore::emu::LidarEmitter& em, const LidarOutOptions& o, double mt, bool& unplugged) {
  if (o.stall_at_s >= 0) em.set_stalled(mt >= o.stall_at_s && mt < o.stall_at_s + o.stall_for_s);
  if (o.unplug_at_s >= 0) {
    const bool want_out = mt >= o.unplug_at_s && mt < o.unplug_at_s + o.unplug_for_s;
    if (want_out && !unplugged) {
      em.unplug();
      unplugged = true;
    } else if (!want_out && unplugged) {
      std::string err;
      if (em.replug(err)) {
        unplugged = false;
      } else {
        std::fprintf(stderr, "chassis-sim: lidar replug failed: %s\n", err.c_str());
      }
    }
  }
}
