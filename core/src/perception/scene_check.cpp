#include "dockcore/perception/scene_check.hpp"

#include <cmath>

namespace dockcore {

namespace {
// push_readings(): a turn alone must land the expectation this near the detection, plus the range times the blur.
constexpr Real kReadingGateM = static_cast<Real>(0.05);
}  // namespace

const char* to_string(SceneVerdict v) {
  switch (v) {
    case SceneVerdict::kStill:
      return "still";
    case SceneVerdict::kMoved:
      return "moved";
    case SceneVerdict::kUnknown:
      break;
  }
  return "unknown";
}

Pose2 turn_about(const Pose2& robot_in_odom, Real yaw_rad) {
  const Pose2 at_robot{robot_in_odom.x_m, robot_in_odom.y_m, 0};
  return at_robot.compose(Pose2{0, 0, yaw_rad}).compose(at_robot.inverse());
}

std::size_t push_readings(const Pose2& expected_in_odom, const Pose2& detected_in_odom, const Pose2& robot_in_odom,
                          const SceneCheckParams& params, Pose2 out[3]) {
  const Vec2 expected_m(expected_in_odom.x_m, expected_in_odom.y_m);
  const Vec2 detected_m(detected_in_odom.x_m, detected_in_odom.y_m);
  const Real turn_rad = wrap_angle(detected_in_odom.yaw_rad - expected_in_odom.yaw_rad);
  std::size_t n = 0;
  out[n++] = detected_in_odom.compose(expected_in_odom.inverse());
  if (std::fabs(turn_rad) <= params.reading_blur_rad) {
    out[n++] = Pose2{detected_m.x() - expected_m.x(), detected_m.y() - expected_m.y(), 0};
  }
  const Pose2 turn = turn_about(robot_in_odom, turn_rad);
  const Real range_m = (expected_m - Vec2(robot_in_odom.x_m, robot_in_odom.y_m)).norm();
  if ((turn.transform(expected_m) - detected_m).norm() <= kReadingGateM + range_m * params.reading_blur_rad) {
    out[n++] = turn;
  }
  return n;
}

namespace {

// A return the reference may keep: valid and within params.max_range_m.
bool keepable(Real r, const SceneCheckParams& params) {
  return is_valid_range(r) && r <= params.max_range_m;
}

// The scan's keepable returns. The reference's stride runs over them, not over the beams: a room seen over a quarter
// of the turn keeps all its points. O(scan.count).
std::size_t keepable_returns(const ScanView& scan, const SceneCheckParams& params) {
  if (scan.ranges_m == nullptr) return 0;
  std::size_t returns = 0;
  for (std::size_t i = 0; i < scan.count; ++i) returns += keepable(scan.ranges_m[i], params) ? 1 : 0;
  return returns;
}

// The stride over `returns` (> 0) that keeps at most SceneCheck::kCapacity of them.
std::size_t stride_for(std::size_t returns) {
  return (returns + SceneCheck::kCapacity - 1) / SceneCheck::kCapacity;
}

}  // namespace

std::size_t SceneCheck::points_kept(const ScanView& scan, const SceneCheckParams& params) {
  const std::size_t returns = keepable_returns(scan, params);
  if (returns == 0) return 0;
  const std::size_t stride = stride_for(returns);
  return (returns + stride - 1) / stride;
}

void SceneCheck::set_reference(const ScanView& scan, const Pose2& lidar_mount, const Pose2& odom_pose,
                               const SceneCheckParams& params) {
  count_ = 0;
  const std::size_t returns = keepable_returns(scan, params);
  if (returns == 0) return;  // nothing to keep (and no stride to take)
  const Pose2 lidar_in_odom = odom_pose.compose(lidar_mount);
  const std::size_t stride = stride_for(returns);
  std::size_t seen = 0;
  for (std::size_t i = 0; i < scan.count && count_ < kCapacity; ++i) {
    const Real r = scan.ranges_m[i];
    if (!keepable(r, params) || seen++ % stride != 0) continue;
    const Real a = scan.angle_rad(i);
    points_odom_m_[count_++] = lidar_in_odom.transform(Vec2(r * std::cos(a), r * std::sin(a)));
  }
}

SceneVerdict SceneCheck::judge(const ScanView& scan, const Pose2& lidar_mount, const Pose2& odom_pose,
                               const Pose2* corrections, std::size_t n, const SceneCheckParams& params,
                               SceneVotes* votes, std::size_t probes, const ExpectedDock* docks,
                               std::size_t n_docks) const {
  SceneVotes v;
  int best_moved_net = 0;  // over every candidate: what "still" must beat
  bool have_moved = false;
  int best_push_net = 0;  // over the candidates that are not probes: what a "moved" verdict rests on
  bool have_push = false;
  const std::size_t pushes = probes < n ? n - probes : 0;
  if (scan.ranges_m != nullptr && scan.count > 0 && scan.angle_increment_rad > 0) {
    const Pose2 lidar_in_odom = odom_pose.compose(lidar_mount);
    const bool wraps = scan.wraps();
    const long beams = static_cast<long>(scan.count);
    // Where the point should show in this scan, and whether that beam explains (1), contradicts (-1) or says nothing
    // of it (0); `seen` false when the beam has no return or lies outside the scan.
    auto vote = [&](const Vec2& p_odom, bool* seen) {
      *seen = false;
      const Vec2 q = lidar_in_odom.inverse_transform(p_odom);
      const Real predicted_m = q.norm();
      long i = nearest_beam_index(scan.angle_min_rad, scan.angle_increment_rad, scan.count, std::atan2(q.y(), q.x()));
      if (wraps) i = ((i % beams) + beams) % beams;
      if (i < 0 || i >= beams) return 0;
      const Real measured_m = scan.ranges_m[i];
      if (!is_valid_range(measured_m)) {
        // No return on this beam nor on either neighbour: open space where the hypothesis puts a surface. A lone
        // missing return is a dropout and says nothing.
        auto none_at = [&](long j) {
          if (wraps) j = ((j % beams) + beams) % beams;
          return j < 0 || j >= beams || !is_valid_range(scan.ranges_m[j]);
        };
        if (predicted_m < params.max_range_m && none_at(i - 1) && none_at(i + 1)) {
          *seen = true;
          return -1;
        }
        return 0;
      }
      *seen = true;
      const Real tol_m = params.range_tolerance_m + params.range_tolerance_frac * predicted_m;
      if (std::fabs(measured_m - predicted_m) <= tol_m) return 1;
      return measured_m > predicted_m + tol_m ? -1 : 0;  // free space where a surface should be; nearer: occluded
    };
    for (std::size_t k = 0; k < count_; ++k) {
      bool seen = false;
      int still = vote(points_odom_m_[k], &seen);
      for (std::size_t q = 0; still < 0 && q < n_docks; ++q) {
        if ((points_odom_m_[k] - docks[q].centre_odom_m).norm() <= docks[q].radius_m) still = 0;
      }
      if (seen) ++v.compared;
      if (still > 0) ++v.still_explained;
      if (still < 0) ++v.still_contradicted;
    }
    for (std::size_t c = 0; c < n; ++c) {
      std::uint16_t explained = 0;
      std::uint16_t contradicted = 0;
      for (std::size_t k = 0; k < count_; ++k) {
        bool seen = false;
        const int moved = vote(corrections[c].transform(points_odom_m_[k]), &seen);
        if (moved > 0) ++explained;
        if (moved < 0) ++contradicted;
      }
      const int net = static_cast<int>(explained) - static_cast<int>(contradicted);
      if (!have_moved || net > best_moved_net) {
        have_moved = true;
        best_moved_net = net;
        v.moved_explained = explained;
        v.moved_contradicted = contradicted;
      }
      if (c < pushes && (!have_push || net > best_push_net)) {
        have_push = true;
        best_push_net = net;
      }
    }
  }
  if (votes != nullptr) *votes = v;
  const int still_net = static_cast<int>(v.still_explained) - static_cast<int>(v.still_contradicted);
  const int margin = static_cast<int>(params.min_margin_points);
  if (v.compared >= params.min_compared && still_net - best_moved_net >= margin &&
      static_cast<Real>(v.still_explained) >=
          params.min_explained_share * static_cast<Real>(v.still_explained + v.still_contradicted)) {
    return SceneVerdict::kStill;
  }
  if (have_push && best_push_net - still_net >= margin) return SceneVerdict::kMoved;
  return SceneVerdict::kUnknown;
}

}  // namespace dockcore
