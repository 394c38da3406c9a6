#include "dockcore/control/wheel_deadband.hpp"

#include <cmath>

namespace dockcore {

void WheelDeadband::configure(const WheelDeadbandParams& params) {
  params_ = params;
  Real start = params.known_radps > 0 ? params.known_radps : 0;
  if (params.adapt && start > params.max_radps) start = params.max_radps > 0 ? params.max_radps : 0;
  for (auto& wheel : floor_radps_) wheel[0] = wheel[1] = start;
  for (Stall& s : stall_) s = Stall{};
  raises_ = 0;
}

Real WheelDeadband::scale(const DriveGeometry& geometry, const DriveLimits& limits, const Twist2& twist) const {
  const WheelSpeeds w = twist_to_wheels(geometry, twist);
  Real fastest = 0;
  for (std::size_t i = 0; i < w.count; ++i) fastest = std::fabs(w.radps[i]) > fastest ? std::fabs(w.radps[i]) : fastest;
  if (!(fastest > 0)) return 1;
  Real s = 1;
  for (std::size_t i = 0; i < w.count; ++i) {
    const Real a = std::fabs(w.radps[i]);
    if (a < kPivotShare * fastest) continue;
    const Real need = floor_radps(i, w.radps[i] < 0) / a;
    s = need > s ? need : s;
  }
  if (limits.max_wheel_radps > 0 && s * fastest > limits.max_wheel_radps) {
    const Real cap = limits.max_wheel_radps / fastest;
    s = cap > 1 ? cap : 1;
  }
  return s;
}

void WheelDeadband::observe(const WheelSpeeds& commanded, const WheelSpeeds& measured, std::uint64_t now_us,
                            bool learn) {
  const std::size_t n = commanded.count < measured.count ? commanded.count : measured.count;
  for (std::size_t i = 0; i < kMaxDriveWheels; ++i) {
    Stall& s = stall_[i];
    const Real c = i < n ? commanded.radps[i] : 0;
    const Real a = std::fabs(c);
    const bool reverse = c < 0;
    // Along the command: a wheel turning the wrong way follows it even less than one standing still.
    const Real along = i < n ? (reverse ? -measured.radps[i] : measured.radps[i]) : 0;
    // A command scale() raised to the floor equals it only up to rounding: a part in a thousand below still counts.
    const bool stalled = learn && params_.adapt && a > 0 && a >= kAtFloor * floor_radps_[i][reverse ? 1 : 0] &&
                         along < kStallShare * a && floor_radps_[i][reverse ? 1 : 0] < params_.max_radps;
    if (!stalled) {
      s.active = false;
      continue;
    }
    if (!s.active || s.reverse != reverse || now_us < s.since_us) {
      s = Stall{true, reverse, now_us, a};
      continue;
    }
    s.min_command_radps = a < s.min_command_radps ? a : s.min_command_radps;
    if (now_us - s.since_us < static_cast<std::uint64_t>(params_.stall_ms) * 1000u) continue;
    Real& f = floor_radps_[i][reverse ? 1 : 0];
    const Real grown = kGrowth * (s.min_command_radps > f ? s.min_command_radps : f);
    f = grown < params_.max_radps ? grown : params_.max_radps;
    ++raises_;
    s.active = false;  // the next stall is timed from the next command at the new floor
  }
}

}  // namespace dockcore
