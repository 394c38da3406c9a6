#include "dockcore/control/wheel_deadband.hpp"

#include <cmath>

namespace dockcore {

void WheelDeadband::configure(const WheelDeadbandParams& params) {
  params_ = params;
  const Real start = bounded_floor(0);
  for (auto& wheel : floor_radps_) wheel[0] = wheel[1] = start;
  for (Stall& s : stall_) s = Stall{};
  for (Trend& t : trend_) t = Trend{};
  raises_ = 0;
}

Real WheelDeadband::bounded_floor(Real floor_radps) const {
  const Real known = params_.known_radps > 0 ? params_.known_radps : 0;
  Real f = floor_radps > known ? floor_radps : known;
  if (params_.adapt && f > params_.max_radps) f = params_.max_radps > 0 ? params_.max_radps : 0;
  return f;
}

WheelDeadband::Floors WheelDeadband::floors() const {
  Floors f;
  for (std::size_t i = 0; i < kMaxDriveWheels; ++i) {
    for (std::size_t d = 0; d < 2; ++d) f.radps[i][d] = floor_radps_[i][d];
  }
  f.raises = raises_;
  return f;
}

void WheelDeadband::restore_floors(const Floors& learned) {
  for (std::size_t i = 0; i < kMaxDriveWheels; ++i) {
    for (std::size_t d = 0; d < 2; ++d) {
      const Real f = learned.radps[i][d];
      floor_radps_[i][d] = bounded_floor(std::isfinite(f) ? f : static_cast<Real>(0));
    }
    stall_[i] = Stall{};
  }
  raises_ = learned.raises;
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
    Trend& tr = trend_[i];
    if (!tr.have_ref || now_us < tr.ref_us || tr.reverse != reverse) {
      tr = Trend{now_us, along, true, reverse, false, false};
    } else if (now_us - tr.ref_us >= kSlowingUs) {
      tr.slowing = tr.ref_along_radps > 0 && along < kSlowingShare * tr.ref_along_radps;
      tr.rising = along - tr.ref_along_radps > kRisingShare * a;
      tr.ref_us = now_us;
      tr.ref_along_radps = along;
    }
    Real& f = floor_radps_[i][reverse ? 1 : 0];
    if (!learn || !params_.adapt || !(a > 0) || !(f < params_.max_radps) || (s.active && s.reverse != reverse) ||
        now_us < s.last_us) {
      s.active = false;
      continue;
    }
    // A command scale() raised to the floor equals it only up to rounding: a part in a thousand below still counts.
    // A command under its floor (a wheel meant to stand nearly still in a pivot) says nothing either way.
    if (a < kAtFloor * f) {
      s.last_us = now_us;
      continue;
    }
    // Under a quarter of the command, or under nine tenths and running down; never while speeding up towards it.
    const bool stalled = !tr.rising && (along < kStallShare * a || (along < kFollowShare * a && tr.slowing));
    if (!s.active) {
      if (stalled) s = Stall{true, reverse, false, now_us, 0, 0, a};
      continue;
    }
    const std::uint64_t dt_us = now_us - s.last_us;
    s.last_us = now_us;
    const std::uint64_t stall_us = static_cast<std::uint64_t>(params_.stall_ms) * 1000u;
    if (!stalled) {
      // Following a command the wheel stood at shows that stand was the drive being slow. Following a larger one
      // says nothing of a deadband below it: the stiffer wheel of a creep whose heading corrections carry it in and
      // out of its deadband stands below it and turns above it, and its stands must still add up.
      if (kAtFloor * a <= s.min_command_radps) s.following_us += dt_us;
      if (s.following_us >= stall_us) s.active = false;
      s.turned = true;
      continue;
    }
    // A stand after turning bounds the deadband by its own commands: an earlier stand's smaller ones may have been a
    // start from rest, slow to follow, and would teach a floor the wheel still stands above.
    if (s.turned) s.min_command_radps = a;
    s.turned = false;
    s.following_us = 0;
    s.stalled_us += dt_us;
    s.min_command_radps = a < s.min_command_radps ? a : s.min_command_radps;
    if (s.stalled_us < stall_us) continue;
    const Real grown = kGrowth * (s.min_command_radps > f ? s.min_command_radps : f);
    f = grown < params_.max_radps ? grown : params_.max_radps;
    ++raises_;
    s.active = false;  // the next stall is timed from the next command at the new floor
  }
}

}  // namespace dockcore
