// Shared by the generated-world sections of `dock-sim perception` (perception_gen_common.hpp).
#include "perception_gen_common.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <thread>

#include "dockcore/perception/profile_check.hpp"
#include "docksim/sim_run.hpp"

namespace docksim_cli::genbench {

using dockcore::Pose2;
using dockcore::Real;

int edge_bin(double v, const double* edges, int bins) {
  for (int i = 0; i < bins - 1; ++i) {
    if (v < edges[i + 1]) return i;
  }
  return bins - 1;
}

std::string exclusion(const dockcore::DockProfile& profile, double beam_spacing_rad, double max_range_m) {
  const dockcore::ProfileCheck c =
      dockcore::check_profile(profile, static_cast<Real>(beam_spacing_rad), static_cast<Real>(max_range_m));
  if (c.reason == dockcore::ProfileCheckReason::kOk) return "";
  std::string r = dockcore::to_string(c.reason);
  if (c.component != dockcore::PoseComponent::kNone) r += std::string(" (") + dockcore::to_string(c.component) + ")";
  return r;
}

std::string miss_cause(const dockcore::DockEstimate& e, const Pose2& truth_sensor, const Pose2& mount_inv) {
  if (e.found) return "found elsewhere";
  if (e.status != dockcore::EstimateStatus::kNotVerified) return dockcore::to_string(e.status);
  const Errors d = errors_of(truth_sensor, mount_inv.compose(e.refused_pose));
  const bool at_dock = is_correct(d);
  std::string r = std::string(at_dock ? "at dock: " : "elsewhere: ") + dockcore::to_string(e.reject);
  if (at_dock && e.reject == dockcore::RejectReason::kWeakEvidence) {
    const dockcore::EvidenceCue w = e.evidence.weakest();
    if (w != dockcore::EvidenceCue::kCount) r += std::string(", weakest ") + dockcore::to_string(w);
  }
  return r;
}

std::uint64_t scan_seed(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  return docksim::trial_seed(docksim::seed_stream(seed, 0x5343414e00ull /* "SCAN" */ + stream), index);
}

Worker::Worker(int estimators) {
  for (int i = 0; i < std::max(1, estimators); ++i) est.push_back(std::make_unique<dockcore::DockPoseEstimator>());
}

void Worker::simulate(const docksim::GenScene& s, std::size_t k, docksim::Rng& rng, std::uint64_t stamp_us) {
  docksim::simulate_scan(s.world, s.lidar_in_world(k), s.lidar, rng, scan.get(), stamp_us);
}

void run_scenes(std::size_t total, int jobs, int estimators, const char* label,
                const std::function<void(std::size_t, Worker&)>& fn) {
  const auto t0 = std::chrono::steady_clock::now();
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex progress;
  auto work = [&]() {
    Worker w(estimators);
    for (;;) {
      const std::size_t i = next.fetch_add(1);
      if (i >= total) return;
      fn(i, w);
      const std::size_t d = done.fetch_add(1) + 1;
      if (d % 200 == 0 || d == total) {
        std::lock_guard<std::mutex> lock(progress);
        std::fprintf(stderr, "\r%s %7zu / %zu", label, d, total);
        if (d == total) std::fprintf(stderr, "\n");
      }
    }
  };
  std::vector<std::thread> pool;
  for (int j = 0; j < std::max(1, jobs); ++j) pool.emplace_back(work);
  for (auto& th : pool) th.join();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::fprintf(stderr, "%s: %zu scenes in %.1f s with %d threads\n", label, total, seconds, std::max(1, jobs));
}

void Confirmation::add(int k, const dockcore::DockEstimate& e, const Pose2& robot_in_world) {
  if (!e.found) {
    agree = false;
    return;
  }
  ++hits;
  // The robot's odometry is exact here: the detections are compared where they put the dock in the world.
  const Pose2 in_world = robot_in_world.compose(e.pose);
  if (k == 0) {
    first = in_world;
  } else {
    const Errors d = errors_of(first, in_world);
    if (d.pos_m > kAgreePosM || d.yaw_rad > kAgreeYawRad) agree = false;
  }
}

json Rate::to_json() const {
  return json{{"n", n}, {"hits", k}, {"rate", n ? json(static_cast<double>(k) / n) : json(nullptr)}};
}

std::string pad(const std::string& s, std::size_t width, bool right) {
  std::size_t cols = 0;
  for (const unsigned char ch : s) cols += (ch & 0xC0) != 0x80 ? 1 : 0;
  if (cols >= width) return s;
  const std::string fill(width - cols, ' ');
  return right ? fill + s : s + fill;
}
std::string fmt(const json& v, const char* f, double scale) {
  if (v.is_null()) return "-";
  char buf[48];
  std::snprintf(buf, sizeof buf, f, scale * v.get<double>());
  return buf;
}
std::string pct(const json& v, const char* f) {
  return fmt(v, f, 100);
}
std::string rate_n(const json& r, const char* f) {
  return pct(r["rate"], f) + " (" + std::to_string(r["n"].get<int>()) + ")";
}

void print_row(const std::vector<Column>& cols, const std::vector<std::string>& cells) {
  std::string line;
  for (std::size_t i = 0; i < cols.size(); ++i) {
    if (i > 0) line += ' ';
    line += pad(cells[i], cols[i].width, cols[i].right);
  }
  while (!line.empty() && line.back() == ' ') line.pop_back();
  std::printf("%s\n", line.c_str());
}

void print_header(const std::vector<Column>& cols) {
  std::vector<std::string> t;
  for (const Column& c : cols) t.emplace_back(c.title);
  print_row(cols, t);
}

}  // namespace docksim_cli::genbench
