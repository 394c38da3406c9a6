#pragma once
// What `dock-sim montecarlo` and `dock-sim certify` share: the per-controller summary of a set of closed-loop runs,
// the nearest-rank percentile, and the worker pool that runs seeded trials in parallel with a progress bar.
#include <cstddef>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "angles.hpp"
#include "docksim/sim_run.hpp"

namespace docksim_cli {

/// v rounded to 1e-6, so JSON figures carry no float noise beyond what is measured. O(1).
double r6(double v);

/// printf-formats one number (`f` takes one double). O(1).
std::string fmt(const char* f, double v);

/// Nearest-rank percentile p (0-100) of v; NaN for an empty v. O(n log n).
double pct(std::vector<double> v, double p);

/// One-sided lower confidence bound on a success rate (Clopper–Pearson) from k successes in n trials: the p at which
/// k or more successes have probability alpha. 0 when k is 0. Bisection to 1e-9: O(80 (n - k)).
double clopper_pearson_lower(int n, int k, double alpha);
/// One-sided upper confidence bound on a rate from k hits in n trials (Clopper–Pearson): the p at which k or fewer
/// hits have probability alpha; 1 - alpha^(1/n) (about 3/n at alpha 0.05) when k is 0, 1 when n is 0. O(80 k).
double clopper_pearson_upper(int n, int k, double alpha);

/// Outcome statistics of a set of runs of one controller. Errors and times are over the runs that confirmed charging.
struct Summary {
  std::string name;
  int trials = 0, successes = 0;
  std::vector<double> lat_mm, lon_mm, yaw_deg, time_s, path_m;
  long reversals = 0, runs_with_reversals = 0, inplace = 0, runs_with_inplace = 0, retries = 0, runs_with_retries = 0;
  double min_clearance_m = std::numeric_limits<double>::infinity();
  std::map<int, int> faults;
  int timeouts = 0;
  std::vector<double> seed_t, seed_z, seed_x;  // seed003's own success test
};

/// Summarises `runs` under `name`. O(runs).
Summary summarise(const std::string& name, const std::vector<docksim::SimRun>& runs);

/// Calls run(i) for every i in [0, total) on `jobs` threads (>= 1), drawing a progress bar on stderr labelled
/// with nothing but the counts. run must be safe to call concurrently for different i.
void run_trials(std::size_t total, int jobs, const std::function<void(std::size_t)>& run);

}  // namespace docksim_cli
