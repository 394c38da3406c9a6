#pragma once
/// The dock pose estimator's tuning keys (dockcore::EstimatorParams, core/include/dockcore/dock_pose_estimator.hpp),
/// one list with units and bounds for both dockd's [estimator] table (app/dockd/config.cpp) and dock-sim's scenario
/// [estimator] table (tools/sim/src/scenario.cpp), so the two accept exactly the same keys and values. Documented in
/// docs/dockd.md and docs/scenarios.md. The range keys (min_range_m, max_range_m, range_sigma_m) are not here: each
/// file keeps them where it always had them. Whether a wall lies behind the dock is not here either: the dock's
/// mounting (its profile's [mounting]) says that; wall_tolerance_m is how far outside the mounting's gap range a
/// wall may still count.
/// Host-side start-up code: heap and exceptions are fine here.

#include <string>

#include <toml++/toml.h>

#include "dockcore/dock_pose_estimator.hpp"
#include "dockcore/params/toml_reader.hpp"

namespace dockcore::params::estimator_toml {

/// Appends the handlers of the estimator's tuning keys to `h`; each stores its checked value in `e`. `prefix` is the
/// table's name in messages ("estimator."). Keys and bounds:
///   huber_k 0.1–10, tukey_c 0.5–20 (units of range_sigma_m); association_gate_m 0.005–1, inlier_gate_m 0.001–0.5,
///   free_space_m 0–1, extension_band_m 0.001–0.5, wall_tolerance_m 0–0.2, max_sigma_m 0.001–1,
///   min_feature_length_m 0.01–2, hint_gate_m 0–5, hint_radius_m 0–10 (m); max_view_angle_deg 1–90 (°);
///   min_evidence_nats -20–100 (nats); min_visible_fraction 0–1; max_iterations 1–50, max_candidates 1–64,
///   min_inliers 1–1000 (integers); select "nearest" | "hint";
///   and the line extraction in a [<prefix>segments] sub-table (SegmentParams): cluster_abs_gap_m 0.005–1,
///   cluster_gap_k 0–50, cluster_noise_margin_m 0–0.5, split_threshold_m 0.001–0.5, min_length_m 0–2,
///   merge_max_rms_m 0.001–0.5 (m or –); cluster_max_missing_beams 0–20, corner_refine_points 0–10, min_points 2–100,
///   merge_max_skipped_points 0–20, max_clusters 1–100000, max_split_iterations 1–1000000 (integers).
template <typename Error>
void add_keys(const toml_reader::Reader<Error>& p, toml_reader::Handlers& h, EstimatorParams& e,
              const std::string& prefix) {
  h.emplace_back("huber_k", p.real(&e.huber_k, 0.1, 10));
  h.emplace_back("tukey_c", p.real(&e.tukey_c, 0.5, 20));
  h.emplace_back("association_gate_m", p.real(&e.association_gate_m, 0.005, 1));
  h.emplace_back("inlier_gate_m", p.real(&e.inlier_gate_m, 0.001, 0.5));
  h.emplace_back("max_iterations", p.integ(&e.max_iterations, 1, 50));
  h.emplace_back("max_candidates", p.integ(&e.max_candidates, 1, 64));
  h.emplace_back("min_feature_length_m", p.real(&e.min_feature_length_m, 0.01, 2));
  h.emplace_back("free_space_m", p.real(&e.free_space_m, 0, 1));
  h.emplace_back("min_inliers", p.integ(&e.min_inliers, 1, 1000));
  h.emplace_back("min_visible_fraction", p.real(&e.min_visible_fraction, 0, 1));
  h.emplace_back("extension_band_m", p.real(&e.extension_band_m, 0.001, 0.5));
  h.emplace_back("min_evidence_nats", p.real(&e.min_evidence_nats, -20, 100));
  h.emplace_back("wall_tolerance_m", p.real(&e.wall_tolerance_m, 0, 0.2));
  h.emplace_back("max_sigma_m", p.real(&e.max_sigma_m, 0.001, 1));
  h.emplace_back("max_view_angle_deg", p.real_deg(&e.max_view_angle_rad, 1, 90));
  h.emplace_back("hint_gate_m", p.real(&e.hint_gate_m, 0, 5));
  h.emplace_back("hint_radius_m", p.real(&e.hint_radius_m, 0, 10));
  h.emplace_back("select", [&p, &e](const toml::node& n) {
    e.select = p.choice(n, {"nearest", "hint"}) == "hint" ? DockSelect::kHint : DockSelect::kNearest;
  });
  h.emplace_back("segments", p.sub(prefix + "segments.", [&p, &e]() {
    SegmentParams& s = e.segments;
    return toml_reader::Handlers{
        {"cluster_abs_gap_m", p.real(&s.cluster_abs_gap_m, 0.005, 1)},
        {"cluster_gap_k", p.real(&s.cluster_gap_k, 0, 50)},
        {"cluster_noise_margin_m", p.real(&s.cluster_noise_margin_m, 0, 0.5)},
        {"cluster_max_missing_beams", p.integ(&s.cluster_max_missing_beams, 0, 20)},
        {"split_threshold_m", p.real(&s.split_threshold_m, 0.001, 0.5)},
        {"corner_refine_points", p.integ(&s.corner_refine_points, 0, 10)},
        {"min_points", p.integ(&s.min_points, 2, 100)},
        {"min_length_m", p.real(&s.min_length_m, 0, 2)},
        {"merge_max_rms_m", p.real(&s.merge_max_rms_m, 0.001, 0.5)},
        {"merge_max_skipped_points", p.integ(&s.merge_max_skipped_points, 0, 20)},
        {"max_clusters", p.integ(&s.max_clusters, 1, 100000)},
        {"max_split_iterations", p.integ(&s.max_split_iterations, 1, 1000000)},
    };
  }));
}

}  // namespace dockcore::params::estimator_toml
