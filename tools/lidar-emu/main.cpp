// lidar-emu: simulated scans of a scenario's world, from a fixed pose, as a real lidar byte stream on a pty (LD06,
// RPLIDAR) or UDP datagrams (LD06, Lakibeam), paced in real time, with fault injection. docs/lidars.md.
#include <CLI/CLI.hpp>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <memory>
#include <string>

#include "dockcore/emu/lidar_emitter.hpp"
#include "docksim/cli_checks.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/rng.hpp"
#include "docksim/scenario.hpp"
#include "docksim/sim_run.hpp"

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }
double now_s() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
void sleep_until(double t) {
  const double d = t - now_s();
  if (d <= 0) return;
  timespec ts{static_cast<time_t>(d), static_cast<long>((d - static_cast<double>(static_cast<time_t>(d))) * 1e9)};
  while (nanosleep(&ts, &ts) != 0 && errno == EINTR && !g_stop) {
  }
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"lidar-emu: emulate an LD06 / RPLIDAR / Lakibeam lidar on a pty or UDP from a simulated scenario"};
  std::string protocol = "ld06", pty, udp, scenario_path, pose_text, model_name;
  double rate_hz = 0, corrupt = 0, corrupt_packets = 0, drop = 0, stall_after = -1, stall_for = 0, duration = 0;
  std::uint64_t seed = 1;
  app.add_option("--protocol", protocol, "ld06 | rplidar | lakibeam")->capture_default_str();
  app.add_option("--pty", pty, "Create a pty and a symlink at PATH to its slave (ld06, rplidar)");
  app.add_option("--udp", udp, "Send datagrams to HOST:PORT (ld06, lakibeam)");
  app.add_option("--scenario", scenario_path, "Scenario TOML (world, dock, lidar model)")->required();
  app.add_option("--pose", pose_text, "Robot pose X,Y,YAW_DEG in the world (default: 1 m in front of the dock, facing it)");
  app.add_option("--model", model_name, "Lidar model (default: the scenario's for ld06, rplidar-a1, industrial for lakibeam)");
  app.add_option("--rate-hz", rate_hz, "Scans per second (default: the model's rate)");
  app.add_option("--corrupt", corrupt, "Fraction of bytes with a flipped bit")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--corrupt-packets", corrupt_packets, "Fraction of packets with one flipped bit")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--drop", drop, "Fraction of packets not sent")->capture_default_str()->check(CLI::Range(0.0, 1.0));
  app.add_option("--stall-after", stall_after, "Stop sending after S seconds ...");
  app.add_option("--stall-for", stall_for, "... for S seconds");
  app.add_option("--duration", duration, "Stop after S seconds (0 = until SIGINT/SIGTERM)");
  app.add_option("--seed", seed, "Seed of the lidar noise and the fault injection")
      ->capture_default_str()
      ->check(docksim::non_negative_integer());
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  dockcore::emu::LidarEmitterOptions o;
  if (!dockcore::emu::parse_emu_protocol(protocol, &o.protocol)) {
    std::fprintf(stderr, "lidar-emu: unknown protocol '%s'\n", protocol.c_str());
    return 2;
  }
  if (pty.empty() == udp.empty()) {
    std::fprintf(stderr, "lidar-emu: give exactly one of --pty PATH or --udp HOST:PORT\n");
    return 2;
  }
  if (!udp.empty()) {
    const auto colon = udp.rfind(':');
    int port = colon == std::string::npos ? 0 : std::atoi(udp.c_str() + colon + 1);
    if (port <= 0 || port > 65535) {
      std::fprintf(stderr, "lidar-emu: --udp wants HOST:PORT\n");
      return 2;
    }
    o.udp_host = udp.substr(0, colon);
    o.udp_port = static_cast<std::uint16_t>(port);
  }
  o.pty_link = pty;
  o.corrupt_fraction = corrupt;
  o.corrupt_packet_fraction = corrupt_packets;
  o.drop_fraction = drop;
  o.seed = seed;

  docksim::Scenario sc;
  try {
    sc = docksim::load_scenario_file(scenario_path);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lidar-emu: %s\n", e.what());
    return 2;
  }
  docksim::LidarModel model = sc.lidar;
  if (model_name.empty() && o.protocol == dockcore::emu::EmuProtocol::kRplidar) model_name = "rplidar-a1";
  if (model_name.empty() && o.protocol == dockcore::emu::EmuProtocol::kLakibeam) model_name = "industrial";
  if (!model_name.empty()) {
    docksim::LidarModel m;
    if (!docksim::lidar_model(model_name, &m)) {
      std::fprintf(stderr, "lidar-emu: unknown lidar model '%s'\n", model_name.c_str());
      return 2;
    }
    m.sigma_const_m = model.sigma_const_m;
    m.dropout_prob = model.dropout_prob;
    model = m;
  }
  if (rate_hz <= 0) rate_hz = model.rate_hz;
  o.rate_hz = rate_hz;

  dockcore::Pose2 robot;
  if (!pose_text.empty()) {
    double x = 0, y = 0, yaw = 0;
    if (std::sscanf(pose_text.c_str(), "%lf,%lf,%lf", &x, &y, &yaw) != 3) {
      std::fprintf(stderr, "lidar-emu: --pose wants X,Y,YAW_DEG\n");
      return 2;
    }
    robot = dockcore::Pose2{static_cast<dockcore::Real>(x), static_cast<dockcore::Real>(y),
                            static_cast<dockcore::Real>(yaw * dockcore::kPi / 180.0)};
  } else {
    const dockcore::Vec2 p = sc.dock_pose.transform(dockcore::Vec2(1.0, 0.0));
    robot = dockcore::Pose2{p.x(), p.y(), dockcore::wrap_angle(sc.dock_pose.yaw_rad + dockcore::kPi)};
  }
  const docksim::World world = docksim::scenario_world(sc, true);
  const dockcore::Pose2 lidar_pose = robot.compose(sc.lidar_mount);

  std::string err;
  auto emitter = dockcore::emu::LidarEmitter::open(o, err);
  if (!emitter) {
    std::fprintf(stderr, "lidar-emu: %s\n", err.c_str());
    return 1;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGPIPE, SIG_IGN);
  if (!pty.empty()) std::fprintf(stderr, "lidar-emu: %s -> %s (%s)\n", pty.c_str(), emitter->slave_path().c_str(), protocol.c_str());
  else std::fprintf(stderr, "lidar-emu: sending %s datagrams to %s\n", protocol.c_str(), udp.c_str());

  docksim::Rng rng(seed);
  auto scan = std::make_unique<dockcore::LaserScan>();
  const double t0 = now_s();
  const double period = 1.0 / rate_hz;
  for (std::uint64_t k = 0; !g_stop; ++k) {
    const double t = t0 + static_cast<double>(k) * period;
    if (duration > 0 && t - t0 >= duration) break;
    sleep_until(t);
    if (g_stop) break;
    const double el = t - t0;
    emitter->set_stalled(stall_after >= 0 && el >= stall_after && el < stall_after + stall_for);
    docksim::simulate_scan(world, lidar_pose, model, rng, scan.get(), static_cast<std::uint64_t>(el * 1e6));
    emitter->emit_scan(scan->view());
  }
  const auto& s = emitter->stats();
  std::fprintf(stderr,
               "lidar-emu: scans=%llu suppressed=%llu packets=%llu dropped=%llu bytes=%llu unwritten=%llu "
               "corrupted=%llu requests=%llu\n",
               static_cast<unsigned long long>(s.scans), static_cast<unsigned long long>(s.scans_suppressed),
               static_cast<unsigned long long>(s.packets), static_cast<unsigned long long>(s.packets_dropped),
               static_cast<unsigned long long>(s.bytes_written), static_cast<unsigned long long>(s.bytes_unwritten),
               static_cast<unsigned long long>(s.bytes_corrupted), static_cast<unsigned long long>(s.requests_seen));
  return 0;
}
