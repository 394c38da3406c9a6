#include "mc_stats.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <thread>

namespace docksim_cli {

double r6(double v) {
  return std::round(v * 1e6) / 1e6;
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), f, v);
  return buf;
}

double pct(std::vector<double> v, double p) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  // Nearest-rank percentile.
  const std::size_t n = v.size();
  std::size_t k = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(n)));
  k = std::min(n, std::max<std::size_t>(1, k));
  return v[k - 1];
}

namespace {
// log of the binomial probability of k successes in n trials at success rate p (0 < p < 1).
double log_binom(int n, int k, double p) {
  return std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0) + k * std::log(p) +
         (n - k) * std::log1p(-p);
}
}  // namespace

double clopper_pearson_lower(int n, int k, double alpha) {
  if (k <= 0) return 0;
  if (k >= n) return std::pow(alpha, 1.0 / n);
  double lo = 0, hi = 1;
  for (int it = 0; it < 80; ++it) {
    const double p = 0.5 * (lo + hi);
    double tail = 0;
    for (int i = k; i <= n; ++i) tail += std::exp(log_binom(n, i, p));
    (tail > alpha ? hi : lo) = p;
  }
  return 0.5 * (lo + hi);
}

double clopper_pearson_upper(int n, int k, double alpha) {
  if (n <= 0) return 1;
  // k or fewer hits at rate p is n - k or more misses at rate 1 - p.
  return 1.0 - clopper_pearson_lower(n, n - k, alpha);
}

Summary summarise(const std::string& name, const std::vector<docksim::SimRun>& runs) {
  Summary s;
  s.name = name;
  for (const auto& r : runs) {
    const auto& o = r.outcome;
    ++s.trials;
    if (o.charging_confirmed) {
      ++s.successes;
      s.lat_mm.push_back(std::fabs(o.lateral_m) * 1e3);
      s.lon_mm.push_back(std::fabs(o.longitudinal_m) * 1e3);
      s.yaw_deg.push_back(std::fabs(o.yaw_rad) * kRadToDeg);
      s.time_s.push_back(o.time_to_charging_s);
    }
    s.path_m.push_back(o.path_length_m);
    s.reversals += o.reversals;
    s.runs_with_reversals += o.reversals > 0;
    s.inplace += o.inplace_turns_45;
    s.runs_with_inplace += o.inplace_turns_45 > 0;
    s.retries += o.retries;
    s.runs_with_retries += o.retries > 0;
    s.min_clearance_m = std::min(s.min_clearance_m, o.min_clearance_m);
    for (const auto& kv : o.faults) s.faults[kv.first] += kv.second;
    s.timeouts += o.timed_out;
    if (!std::isnan(o.seed_success_t_s)) {
      s.seed_t.push_back(o.seed_success_t_s);
      s.seed_z.push_back(o.seed_success_z_err_m);
      s.seed_x.push_back(o.seed_success_x_m);
    }
  }
  return s;
}

void run_trials(std::size_t total, int jobs, const std::function<void(std::size_t)>& run) {
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex progress_mutex;
  auto worker = [&]() {
    for (;;) {
      const std::size_t i = next.fetch_add(1);
      if (i >= total) return;
      run(i);
      const std::size_t d = done.fetch_add(1) + 1;
      if (d % 10 == 0 || d == total) {
        std::lock_guard<std::mutex> lock(progress_mutex);
        const int w = 40;
        const int filled = static_cast<int>(w * d / total);
        std::fprintf(stderr, "\r[%s%s] %zu/%zu", std::string(static_cast<std::size_t>(filled), '#').c_str(),
                     std::string(static_cast<std::size_t>(w - filled), '.').c_str(), d, total);
        if (d == total) std::fprintf(stderr, "\n");
      }
    }
  };
  std::vector<std::thread> pool;
  for (int j = 0; j < jobs; ++j) pool.emplace_back(worker);
  for (auto& th : pool) th.join();
}

}  // namespace docksim_cli
