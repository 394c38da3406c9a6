#pragma once
// What a benchmark run changes in the estimator's parameters, on top of those each scene or recording gets from its
// lidar's noise (estimator_params_for_noise). Lets one command measure the trade-off a setting makes across every
// section (detection on simulated and composite scenes against false docks on real scans).
#include <cmath>
#include <cstdint>
#include <limits>

#include "dockcore/perception/dock_pose_estimator.hpp"

namespace docksim {

struct EstimatorOverrides {
  /// EstimatorParams::min_evidence_nats (nats); NaN: the default.
  double min_evidence_nats = std::numeric_limits<double>::quiet_NaN();
  /// EstimatorParams::stripe_hypotheses switched on (it acts only on a reflector dock whose intensity is read).
  bool stripe_hypotheses = false;
  /// EstimatorParams::max_candidates (hypotheses refined per global search, 1-64); 0: the default. What the global
  /// search costs scales with it.
  int max_candidates = 0;

  /// `p` with the set fields replaced. O(1).
  dockcore::EstimatorParams applied(dockcore::EstimatorParams p) const {
    if (!std::isnan(min_evidence_nats)) p.min_evidence_nats = static_cast<dockcore::Real>(min_evidence_nats);
    if (stripe_hypotheses) p.stripe_hypotheses = true;
    if (max_candidates > 0) p.max_candidates = static_cast<std::uint8_t>(max_candidates);
    return p;
  }
  /// estimator_params_for_noise(sigma_m) with the set fields replaced: every benchmark's estimator parameters.
  /// O(1).
  dockcore::EstimatorParams for_noise(double sigma_m) const {
    return applied(dockcore::estimator_params_for_noise(static_cast<dockcore::Real>(sigma_m)));
  }
};

}  // namespace docksim
