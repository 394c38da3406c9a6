// dock-sim features: the estimator's decision features (DockEstimate::evidence.features) of labelled candidates, as
// CSV, for fitting the cue weights (tools/fit-evidence, docs/docks.md "How the cue weights are fitted").
//   positives: simulated docks (built-ins, mountings flush / 0-10 cm gap / glass / free-standing / clutter, three
//              lidar models, 5-20 mm noise), the candidate the estimator kept when it lies within 5 cm of the truth;
//   negatives: the best candidate of every scan of real dock-less recordings, with each recording's own noise.
// The world generator (docksim::WorldGenerator) is deliberately not used: it is the evaluation set.
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "dockcore/perception/dock_pose_estimator.hpp"
#include "docksim/cli_checks.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/real_perception.hpp"
#include "docksim/realdata.hpp"
#include "docksim/rng.hpp"
#include "docksim/scenes.hpp"

namespace docksim_cli {
namespace {

using dockcore::DockEstimate;
using dockcore::Pose2;
using dockcore::Real;
using dockcore::Vec2;

// A candidate can only be scored when it passed the hard checks: accepted, or refused for weak evidence.
bool scored(const DockEstimate& e) {
  return e.found || e.reject == dockcore::RejectReason::kWeakEvidence;
}

void print_header() {
  std::printf("label,profile,kind,sigma_m,gate_m,scored,found,hit,hit_sq,dropped,beyond,front,missing,continues,stops,"
              "wall_seen,wall_missed,constraint\n");
}

// One row per scene or scan; `use` says whether its candidate is one to fit on (features are zero otherwise).
void print_row(const char* label, const char* profile, const std::string& kind, double sigma_m, double gate_m,
               bool use, const DockEstimate& e) {
  const dockcore::DecisionFeatures f = use ? e.evidence.features : dockcore::DecisionFeatures{};
  std::printf("%s,%s,%s,%.4f,%.4f,%d,%d,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f\n", label, profile,
              kind.c_str(), sigma_m, gate_m, use ? 1 : 0, use && e.found ? 1 : 0, static_cast<double>(f.hit), static_cast<double>(f.hit_sq),
              static_cast<double>(f.dropped), static_cast<double>(f.beyond), static_cast<double>(f.front),
              static_cast<double>(f.missing), static_cast<double>(f.continues), static_cast<double>(f.stops),
              static_cast<double>(f.wall_seen), static_cast<double>(f.wall_missed), static_cast<double>(f.constraint));
}

struct FeaturesOptions {
  int positives = 6000;
  std::uint64_t seed = 11;
  std::string realdata_dir;
  std::vector<std::string> recordings;  // empty: none (positives only)
};

int run_positives(const FeaturesOptions& o, dockcore::DockPoseEstimator& est, dockcore::LaserScan& scan) {
  const char* profiles[] = {"plate-v", "v-marker", "breakpoint"};
  const char* lidars[] = {"ld06", "rplidar-a1", "industrial"};
  const char* kinds[] = {"flush", "gap", "glass", "free", "clutter"};
  docksim::Rng rng(o.seed);
  for (int t = 0; t < o.positives; ++t) {
    const char* pname = profiles[t % 3];
    dockcore::DockProfile p;
    dockcore::builtin_profile(pname, p);
    docksim::LidarModel m;
    docksim::lidar_model(lidars[(t / 3) % 3], &m);
    const double sigma = rng.uniform(0.005, 0.02);
    m.sigma_const_m = sigma;
    m.sigma_prop = rng.uniform(0, 0.005);
    m.dropout_prob = rng.uniform(0, 0.1);
    const int kind = (t / 9) % 5;
    const double d = rng.uniform(0.3, 2.0);
    const double b = rng.uniform(-0.78, 0.78);
    const double y = rng.uniform(-0.52, 0.52);
    docksim::SceneSpec spec;
    spec.profile = p;
    spec.lidar_pose_in_world = Pose2{};
    spec.dock_pose_in_world = docksim::dock_pose_from_lidar(d, b, y);
    spec.clutter_level = kind == 4 ? 2 : 1;
    spec.with_wall = kind == 0 || kind == 4;
    docksim::World w = docksim::build_scene(spec, rng);
    double back_x = 0;
    for (std::size_t i = 0; i < p.vertex_count; ++i) back_x = std::min(back_x, static_cast<double>(p.vertices_m[i].x()));
    if (kind == 1 || kind == 3) {  // a wall 0-10 cm behind, or a room wall 0.8-2 m behind
      const double gap = kind == 1 ? rng.uniform(0.0, 0.10) : rng.uniform(0.8, 2.0);
      const Pose2& dp = spec.dock_pose_in_world;
      const Pose2 a = dp.compose(Pose2{static_cast<Real>(back_x - gap), -3, 0});
      const Pose2 c = dp.compose(Pose2{static_cast<Real>(back_x - gap), 3, 0});
      w.add_polyline({Vec2(a.x_m, a.y_m), Vec2(c.x_m, c.y_m)});
    }
    const dockcore::EstimatorParams params = dockcore::estimator_params_for_noise(static_cast<Real>(sigma));
    est.configure(p, params);
    docksim::simulate_scan(w, Pose2{}, m, rng, &scan, 0);
    const DockEstimate e = est.estimate(scan.view(), Pose2{});
    const Pose2 at = e.found ? e.pose : e.refused_pose;
    const bool near = std::hypot(at.x_m - spec.dock_pose_in_world.x_m, at.y_m - spec.dock_pose_in_world.y_m) <= 0.05;
    print_row("pos", pname, kinds[kind], sigma, static_cast<double>(params.inlier_gate_m), scored(e) && near, e);
  }
  return 0;
}

int run_negatives(const FeaturesOptions& o, dockcore::DockPoseEstimator& est, dockcore::LaserScan& scan) {
  const docksim::RealDataLocation loc = docksim::locate_realdata(o.realdata_dir);
  if (!loc.found()) {
    std::fprintf(stderr, "dock-sim features: %s; no negatives written\n", loc.describe().c_str());
    return 0;
  }
  for (const std::string& name : o.recordings) {
    const docksim::RealRecording* rec = docksim::find_real_recording(name);
    if (rec == nullptr) {
      std::fprintf(stderr, "dock-sim features: unknown recording %s\n", name.c_str());
      return 2;
    }
    docksim::LoadedRecording loaded;
    std::string error;
    if (!docksim::load_real_recording(loc.dir, *rec, 0, &loaded, &error)) {
      std::fprintf(stderr, "dock-sim features: %s: %s\n", name.c_str(), error.c_str());
      return 2;
    }
    const dockcore::EstimatorParams params = docksim::real_estimator_params(*rec);
    for (const char* const* pn = dockcore::kBuiltinProfileNames; *pn != nullptr; ++pn) {
      dockcore::DockProfile p;
      dockcore::builtin_profile(*pn, p);
      est.configure(p, params);
      for (const docksim::RecordedScan& s : loaded.scans) {
        if (!s.to_laser_scan(&scan)) continue;
        const DockEstimate e = est.estimate(scan.view(), docksim::real_lidar_mount());
        print_row("neg", *pn, name, rec->sigma_m, static_cast<double>(params.inlier_gate_m), scored(e), e);
      }
    }
  }
  return 0;
}

}  // namespace

void register_features(CLI::App& app) {
  auto o = std::make_shared<FeaturesOptions>();
  auto names = std::make_shared<std::string>();
  CLI::App* sub = app.add_subcommand(
      "features", "Decision features of labelled candidates as CSV (simulated docks, real dock-less scans), for "
                  "tools/fit-evidence");
  sub->add_option("--positives", o->positives, "Simulated docking scenes (0: none)")->check(CLI::NonNegativeNumber);
  sub->add_option("--seed", o->seed, "Seed of the simulated scenes")->check(docksim::non_negative_integer());
  sub->add_option("--realdata", o->realdata_dir,
                  "Real-data folder (default: $DOCKCORE_REALDATA, else <repo>/../shared/realdata)");
  sub->add_option("--recordings", *names, "Comma-separated real recordings for negatives (default: none)");
  sub->callback([o, names]() {
    std::stringstream ss(*names);
    std::string item;
    o->recordings.clear();
    while (std::getline(ss, item, ',')) {
      if (!item.empty()) o->recordings.push_back(item);
    }
    auto est = std::make_unique<dockcore::DockPoseEstimator>();
    auto scan = std::make_unique<dockcore::LaserScan>();
    print_header();
    int rc = run_positives(*o, *est, *scan);
    if (rc == 0) rc = run_negatives(*o, *est, *scan);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace docksim_cli
