#pragma once
// chassis-sim's lidar: the LidarEmitter of dockcore_emu configured from the command line, with the sensor faults a
// HIL case scripts (stall, unplug, corruption) on the motion clock.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/emu/lidar_emitter.hpp"

struct LidarOutOptions {
  std::string protocol = "ld06";
  std::string pty_link;       ///< pty mode: symlink path dockd's serial driver opens.
  std::string udp;            ///< UDP mode: HOST:PORT.
  double corrupt_fraction = 0;
  double corrupt_packet_fraction = 0;
  double drop_fraction = 0;
  double stall_at_s = -1, stall_for_s = 0;      ///< Motion-clock times.
  double unplug_at_s = -1, unplug_for_s = 0;
  double corrupt_at_s = -1, corrupt_for_s = 0;  ///< Corruption only in this motion-clock window (-1: always).
  double wrong_baud = 0;                        ///< The sensor's line rate in a wrong-baud window (bit/s).
  double reader_baud = 230400;                  ///< The rate the host's UART is set to (dockd's [lidar] baud).
  double wrong_baud_at_s = -1, wrong_baud_for_s = 0;
  std::uint64_t seed = 7;
  bool rplidar_autostart = false;  ///< RPLIDAR streams without waiting for SCAN (a host speaking another protocol).
};

inline void add_lidar_out_options(CLI::App& app, LidarOutOptions& o) {
  app.add_option("--lidar-protocol", o.protocol, "ld06 | rplidar | lakibeam");
  app.add_option("--lidar-pty", o.pty_link, "Serial lidar on a pty; a symlink to it is made at this path");
  app.add_option("--lidar-udp", o.udp, "UDP lidar: send datagrams to HOST:PORT");
  app.add_option("--lidar-corrupt", o.corrupt_fraction, "Fraction of lidar bytes with a flipped bit (0..1)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--lidar-corrupt-packets", o.corrupt_packet_fraction,
                 "Fraction of lidar packets with one flipped bit (0..1)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--lidar-drop", o.drop_fraction, "Fraction of lidar packets not sent (0..1)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--lidar-stall-at", o.stall_at_s, "Lidar stops sending this long after motion start (s)");
  app.add_option("--lidar-stall-for", o.stall_for_s, "... for this long (s)");
  app.add_option("--lidar-unplug-at", o.unplug_at_s, "Lidar pty closed this long after motion start (s)");
  app.add_option("--lidar-unplug-for", o.unplug_for_s, "... and re-created after this long (s)");
  app.add_flag("--lidar-rplidar-autostart", o.rplidar_autostart,
               "RPLIDAR: stream scans at once, without the host's SCAN request (feeds rplidar bytes to an ld06 reader)");
  app.add_option("--lidar-corrupt-at", o.corrupt_at_s, "--lidar-corrupt applies only from this motion time (s)");
  app.add_option("--lidar-corrupt-for", o.corrupt_for_s, "... for this long (s)");
  app.add_option("--lidar-wrong-baud", o.wrong_baud,
                 "Wrong-baud fault: the sensor sends at this rate while the reader is at --lidar-reader-baud; the pty "
                 "gets what that UART would read (bit-level resampling, framing errors read as 0x00)");
  app.add_option("--lidar-reader-baud", o.reader_baud, "The reader's rate for --lidar-wrong-baud (default 230400)");
  app.add_option("--lidar-wrong-baud-at", o.wrong_baud_at_s, "Wrong-baud window start, motion time (s)");
  app.add_option("--lidar-wrong-baud-for", o.wrong_baud_for_s, "... for this long (s)");
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
  e.corrupt_fraction = o.corrupt_at_s >= 0 ? 0.0 : o.corrupt_fraction;
  e.corrupt_packet_fraction = o.corrupt_packet_fraction;
  e.drop_fraction = o.drop_fraction;
  e.seed = o.seed;
  e.rplidar_wait_for_scan_request = !o.rplidar_autostart;
  e.paced = true;  // packets leave as the sensor sends them: main loop pumps every step
  return dockcore::emu::LidarEmitter::open(e, err);
}

/// What a UART receiving at `reader_baud` reads from 8N1 bytes sent back to back at `line_baud` (a wrong baud rate
/// setting). The line is modelled bit by bit: the receiver waits for a low level (start bit, searched in 1/16 bit
/// steps as a 16x-oversampling UART does), samples the 8 data bits and the stop bit at their middles, and delivers
/// the byte; a low stop bit is a framing error, read as 0x00 (Linux termios without IGNPAR/PARMRK). The idle line
/// is high. Deterministic; O(bits).
inline std::vector<std::uint8_t> uart_misread(const std::vector<std::uint8_t>& in, double line_baud,
                                              double reader_baud) {
  std::vector<std::uint8_t> out;
  if (in.empty() || line_baud <= 0 || reader_baud <= 0) return out;
  const double k = reader_baud / line_baud;  // one line bit in reader bit times
  const double end = static_cast<double>(in.size()) * 10.0 * k;
  auto level = [&](double t) -> int {
    if (t < 0 || t >= end) return 1;
    const auto idx = static_cast<std::size_t>(t / k);
    const std::size_t bit = idx % 10;
    if (bit == 0) return 0;  // start
    if (bit == 9) return 1;  // stop
    return (in[idx / 10] >> (bit - 1)) & 1;
  };
  double t = 0;
  while (t < end) {
    if (level(t) != 0) {
      t += 1.0 / 16;
      continue;
    }
    std::uint8_t b = 0;
    for (int i = 0; i < 8; ++i) b = static_cast<std::uint8_t>(b | (level(t + 1.5 + i) << i));
    const bool framing_error = level(t + 9.5) == 0;
    out.push_back(framing_error ? 0 : b);
    t += 9.5 + 1.0 / 16;  // look for the next start bit after the stop bit's middle
  }
  return out;
}

/// One scripted fault window on the motion clock. It opens on the first call at or after `at_s` and then lasts
/// `for_s` from the moment it opened: a loop that was descheduled across the scheduled window (a loaded VM) still
/// applies the whole fault, late, instead of skipping it.
struct FaultWindow {
  double opened = -1;
  bool done = false;
  /// True while the fault applies at motion time `mt` (negative before motion starts).
  bool active(double at_s, double for_s, double mt) {
    if (at_s < 0 || done || mt < 0) return false;
    if (opened < 0 && mt >= at_s) opened = mt;
    if (opened < 0) return false;
    if (mt >= opened + for_s) {
      done = true;
      return false;
    }
    return true;
  }
};

/// Fault windows of one lidar (chassis-sim has one).
struct LidarFaultState {
  FaultWindow stall, unplug, corrupt, baud;
  bool unplugged = false, corrupting = false, wrong_baud = false;
};

/// Applies the scripted stall/unplug/corruption/wrong-baud windows for motion time `mt` (negative before motion
/// starts); `log` gets the name of each transition (truth log events: lidar_stall, lidar_unstall, lidar_unplug,
/// lidar_replug, lidar_corrupt, lidar_clean, lidar_wrong_baud, lidar_right_baud).
inline void lidar_faults(dockcore::emu::LidarEmitter& em, const LidarOutOptions& o, double mt, LidarFaultState& st,
                         const std::function<void(const char*)>& log) {
  if (o.stall_at_s >= 0) {
    const bool want = st.stall.active(o.stall_at_s, o.stall_for_s, mt);
    if (want != em.stalled()) log(want ? "lidar_stall" : "lidar_unstall");
    em.set_stalled(want);
  }
  if (o.unplug_at_s >= 0) {
    const bool want_out = st.unplug.active(o.unplug_at_s, o.unplug_for_s, mt);
    if (want_out && !st.unplugged) {
      em.unplug();
      st.unplugged = true;
      log("lidar_unplug");
    } else if (!want_out && st.unplugged) {
      std::string err;
      if (em.replug(err)) {
        st.unplugged = false;
        log("lidar_replug");
      } else {
        std::fprintf(stderr, "chassis-sim: lidar replug failed: %s\n", err.c_str());
      }
    }
  }
  if (o.corrupt_at_s >= 0) {
    const bool want = st.corrupt.active(o.corrupt_at_s, o.corrupt_for_s, mt);
    if (want != st.corrupting) log(want ? "lidar_corrupt" : "lidar_clean");
    st.corrupting = want;
    em.set_corrupt_fraction(want ? o.corrupt_fraction : 0.0);
  }
  if (o.wrong_baud > 0) {
    const bool want = o.wrong_baud_at_s < 0 || st.baud.active(o.wrong_baud_at_s, o.wrong_baud_for_s, mt);
    if (want != st.wrong_baud) {
      st.wrong_baud = want;
      log(want ? "lidar_wrong_baud" : "lidar_right_baud");
      if (want) {
        const double line = o.wrong_baud, reader = o.reader_baud;
        em.set_line_filter([line, reader](std::vector<std::uint8_t>& b) { b = uart_misread(b, line, reader); });
      } else {
        em.set_line_filter(nullptr);
      }
    }
  }
}

