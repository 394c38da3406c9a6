// lidar-dump: reads a lidar (serial device, UDP port) or a raw byte capture, decodes it with core's parser and prints
// scans as JSON lines (the recorded-scan format dock-sim detect reads) or CSV, then the error counters.
#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <poll.h>
#include <string>
#include <vector>

#include "dockcore/drivers/lidar_driver.hpp"
#include "dockcore/perception/intensity_check.hpp"
#include "dockcore/protocols/lidar/lidar_rplidar.hpp"
#include "docksim/cli_checks.hpp"
#include "docksim/scan_io.hpp"

using dockcore::drivers::LidarProtocol;

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

nlohmann::json counters_json(const dockcore::LidarParserCounters& c, std::uint32_t reconnects,
                             const dockcore::IntensityCheck& ic) {
  return nlohmann::json{{"intensity", dockcore::to_string(ic.verdict())},
                        {"intensity_scans_judged", ic.scans_judged()},
                        {"intensity_scans_flat", ic.scans_flat()},
                        {"scans", c.scans},
                        {"crc_errors", c.crc_errors},
                        {"resyncs", c.resyncs},
                        {"dropped_bytes", c.dropped_bytes},
                        {"reconnects", reconnects},
                        {"bytes", c.bytes},
                        {"bytes_accepted", c.bytes_accepted},
                        {"packets", c.packets},
                        {"bad_span", c.bad_span},
                        {"health_packets", c.health_packets},
                        {"info_packets", c.info_packets},
                        {"descriptors", c.descriptors},
                        {"bad_packets", c.bad_packets},
                        {"samples", c.samples},
                        {"samples_discarded", c.samples_discarded},
                        {"bin_collisions", c.bin_collisions},
                        {"scans_overwritten", c.scans_overwritten},
                        {"clock_resyncs", c.clock_resyncs},
                        {"stray_start", c.stray_start},
                        {"idle_bytes", c.idle_bytes}};
}

struct Printer {
  bool csv = false;
  std::uint64_t printed = 0;
  dockcore::IntensityCheck intensity;  ///< The core's verdict on the sensor's intensity, over the printed scans.
  void print(const dockcore::LaserScan& s) {
    intensity.add(s.view());
    if (csv) {
      for (std::size_t i = 0; i < s.count; ++i)
        std::printf("%llu,%llu,%zu,%.9g,%.6g,%.6g\n", static_cast<unsigned long long>(printed),
                    static_cast<unsigned long long>(s.stamp_us), i, s.view().angle_rad(i), s.ranges_m[i],
                    s.intensities[i]);
    } else {
      std::printf("%s\n", docksim::format_scan_line(s.view()).c_str());
    }
    std::fflush(stdout);
    ++printed;
  }
};
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"lidar-dump: decode a lidar or a capture and print its scans and error counters"};
  std::string protocol = "ld06", device, file, record, json_counters, bind = "0.0.0.0";
  int udp_port = -1;
  std::uint32_t baud = 0, bins = 0;
  std::uint64_t count = 0;
  double duration = 0;
  bool csv = false, mid_stream = false;
  int bench = 0;
  app.add_option("--protocol", protocol, "ld06 | rplidar | lakibeam")->capture_default_str();
  auto* o_dev = app.add_option("--device", device, "Serial device (ld06: 230400 baud, rplidar: 115200 by default)");
  auto* o_udp = app.add_option("--udp", udp_port, "UDP port to bind (lakibeam, ld06 over UDP)");
  auto* o_file = app.add_option("--file", file, "Raw byte capture (lakibeam: concatenated 1206-byte datagrams)");
  o_dev->excludes(o_udp)->excludes(o_file);
  o_udp->excludes(o_file);
  app.add_option("--bind", bind, "UDP bind address")->capture_default_str();
  app.add_option("--baud", baud, "Serial baud rate");
  app.add_option("--bins", bins, "Bins per turn of the printed scans (0 = protocol default)");
  app.add_flag("--csv", csv, "CSV rows scan,stamp_us,index,angle_rad,range_m,intensity instead of JSON lines");
  app.add_option("--record", record, "Save the raw bytes (datagrams) read to FILE");
  app.add_option("--json-counters", json_counters, "Write the counters as JSON to FILE ('-' = stdout, after the scans)");
  app.add_option("--count", count, "Stop after N scans")->check(docksim::non_negative_integer());
  app.add_option("--duration", duration, "Stop after S seconds (device / UDP)");
  app.add_option("--bench", bench, "--file: decode the capture N times without printing; report ns per byte");
  app.add_flag("--mid-stream", mid_stream, "rplidar --file: accept nodes without a scan descriptor");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  const auto proto = dockcore::drivers::parse_lidar_protocol(protocol);
  if (!proto) {
    std::fprintf(stderr, "lidar-dump: unknown protocol '%s'\n", protocol.c_str());
    return 2;
  }
  if (device.empty() && file.empty() && udp_port < 0) {
    std::fprintf(stderr, "lidar-dump: give --device, --udp or --file\n");
    return 2;
  }
  std::ofstream rec;
  if (!record.empty()) {
    rec.open(record, std::ios::binary);
    if (!rec) {
      std::fprintf(stderr, "lidar-dump: cannot write %s\n", record.c_str());
      return 2;
    }
  }
  Printer out;
  out.csv = csv;
  if (csv) std::printf("scan,stamp_us,index,angle_rad,range_m,intensity\n");
  dockcore::LidarParserCounters counters{};
  std::uint32_t reconnects = 0;

  if (!file.empty()) {
    std::ifstream in(file, std::ios::binary);
    if (!in) {
      std::fprintf(stderr, "lidar-dump: cannot open %s\n", file.c_str());
      return 2;
    }
    std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (rec.is_open()) rec.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (bench > 0) {
      dockcore::drivers::LidarDecoder bd(*proto);
      if (mid_stream) bd.set_require_descriptor(false);
      const std::size_t step = *proto == LidarProtocol::kLakibeam ? dockcore::kLakibeamDatagramBytes : bytes.size();
      const std::uint64_t t0 = dockcore::drivers::monotonic_us();
      for (int r = 0; r < bench; ++r) {
        for (std::size_t off = 0; off < bytes.size(); off += step) {
          const std::size_t n = std::min(step, bytes.size() - off);
          if (*proto == LidarProtocol::kLakibeam) bd.feed_datagram(bytes.data() + off, n, 0);
          else bd.feed_bytes(bytes.data() + off, n, 0, 0);
          while (bd.take_scan() != nullptr) {
          }
        }
      }
      const double us = static_cast<double>(dockcore::drivers::monotonic_us() - t0);
      const double total = static_cast<double>(bytes.size()) * bench;
      std::printf("{\"bytes\":%.0f,\"ns_per_byte\":%.2f,\"scans\":%u,\"us_per_scan\":%.1f}\n", total,
                  us * 1000.0 / total, bd.counters().scans, us / std::max(1u, bd.counters().scans));
      return 0;
    }
    dockcore::drivers::LidarDecoder dec(*proto);
    if (bins > 0 && !dec.configure_grid(bins)) {
      std::fprintf(stderr, "lidar-dump: --bins must be in 1..%zu\n", dockcore::kMaxScanPoints);
      return 2;
    }
    if (mid_stream) dec.set_require_descriptor(false);
    // Stamps from the byte position at the nominal baud rate, so a capture's scans come out spaced as recorded.
    const std::uint32_t rate = baud > 0 ? baud : (*proto == LidarProtocol::kRplidar ? 115200 : 230400);
    const double byte_us = 1e7 / rate;
    const std::size_t step = *proto == LidarProtocol::kLakibeam ? dockcore::kLakibeamDatagramBytes : 1;
    for (std::size_t off = 0; off < bytes.size() && !(count > 0 && out.printed >= count); off += step) {
      const std::size_t n = std::min(step, bytes.size() - off);
      const auto t = static_cast<std::uint64_t>(static_cast<double>(off) * byte_us);
      if (*proto == LidarProtocol::kLakibeam) dec.feed_datagram(bytes.data() + off, n, t);
      else dec.feed_bytes(bytes.data() + off, n, t, 0);
      for (const dockcore::LaserScan* sc = dec.take_scan(); sc != nullptr && !(count > 0 && out.printed >= count);
           sc = dec.take_scan())
        out.print(*sc);
    }
    counters = dec.counters();
  } else {
    dockcore::drivers::LidarDriverOptions o;
    o.protocol = *proto;
    o.bins_per_turn = bins;
    if (!device.empty()) {
      o.transport = dockcore::drivers::LidarTransport::kSerial;
      o.device = device;
      o.baud = baud > 0 ? baud : (*proto == LidarProtocol::kRplidar ? 115200 : 230400);
    } else {
      o.transport = dockcore::drivers::LidarTransport::kUdp;
      o.udp_bind_address = bind;
      o.udp_port = static_cast<std::uint16_t>(udp_port);
    }
    if (rec.is_open())
      o.raw_tap = [&rec](const std::uint8_t* d, std::size_t n) {
        rec.write(reinterpret_cast<const char*>(d), static_cast<std::streamsize>(n));
      };
    std::string err;
    auto drv = dockcore::drivers::make_lidar_driver(o, err);
    if (!drv) {
      std::fprintf(stderr, "lidar-dump: %s\n", err.c_str());
      return 2;
    }
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    const std::uint64_t t0 = dockcore::drivers::monotonic_us();
    std::string last_err;
    while (!g_stop) {
      const std::uint64_t now = dockcore::drivers::monotonic_us();
      if (duration > 0 && static_cast<double>(now - t0) >= duration * 1e6) break;
      if (count > 0 && out.printed >= count) break;
      pollfd p{drv->fd(), POLLIN, 0};
      if (p.fd >= 0) ::poll(&p, 1, 20);
      else ::poll(nullptr, 0, 20);
      if (const dockcore::LaserScan* sc = drv->poll_scan()) out.print(*sc);
      if (last_err != drv->last_error()) {
        last_err = drv->last_error();
        if (!last_err.empty()) std::fprintf(stderr, "lidar-dump: %s\n", last_err.c_str());
      }
    }
    counters = drv->parser_counters();
    reconnects = drv->counters().reconnects;
  }
  std::fprintf(stderr,
               "counters: scans=%u crc_errors=%u resyncs=%u dropped_bytes=%u reconnects=%u packets=%u bad_span=%u "
               "health=%u info=%u descriptors=%u bad_packets=%u samples_discarded=%u bin_collisions=%u "
               "scans_overwritten=%u clock_resyncs=%u\n",
               counters.scans, counters.crc_errors, counters.resyncs, counters.dropped_bytes, reconnects,
               counters.packets, counters.bad_span, counters.health_packets, counters.info_packets,
               counters.descriptors, counters.bad_packets, counters.samples_discarded, counters.bin_collisions,
               counters.scans_overwritten, counters.clock_resyncs);
  {
    const dockcore::IntensityCheck& ic = out.intensity;
    std::fprintf(stderr, "intensity: %s (%u of %u judged scans flat; last: %.0f %% of %u returns within ±%g of %g)\n",
                 dockcore::to_string(ic.verdict()), ic.scans_flat(), ic.scans_judged(),
                 static_cast<double>(ic.last().share) * 100.0, static_cast<unsigned>(ic.last().returns),
                 static_cast<double>(ic.params().flat_band), static_cast<double>(ic.last().mode));
  }
  if (*proto == LidarProtocol::kRplidar) {
    // Where every byte went; pending = bytes still buffered in the parser (the byte-accounting identity).
    const auto a = dockcore::rplidar_byte_account(
        counters, static_cast<std::size_t>(counters.bytes - counters.bytes_accepted - counters.dropped_bytes));
    std::fprintf(stderr,
                 "rplidar: stray_start=%u bytes=%llu = nodes %llu + descriptors %llu + responses %llu + resync %llu + "
                 "idle %llu + pending %llu\n",
                 counters.stray_start, static_cast<unsigned long long>(counters.bytes),
                 static_cast<unsigned long long>(a.node_bytes), static_cast<unsigned long long>(a.descriptor_bytes),
                 static_cast<unsigned long long>(a.response_bytes), static_cast<unsigned long long>(a.resync_bytes),
                 static_cast<unsigned long long>(a.idle_bytes), static_cast<unsigned long long>(a.pending_bytes));
  }
  if (!json_counters.empty()) {
    const std::string j = counters_json(counters, reconnects, out.intensity).dump();
    if (json_counters == "-") {
      std::printf("%s\n", j.c_str());
    } else {
      std::ofstream f(json_counters);
      f << j << "\n";
      if (!f) {
        std::fprintf(stderr, "lidar-dump: cannot write %s\n", json_counters.c_str());
        return 1;
      }
    }
  }
  return 0;
}
