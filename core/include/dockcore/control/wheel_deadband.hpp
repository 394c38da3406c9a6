#pragma once
/// @file WheelDeadband: keeps slow commands moving on a drive whose wheels do not turn below some speed (PWM drives
/// that do not overcome static friction, stiction, a heavy base). Part of the core's output shaping
/// (docs/architecture.md, "The control tick").
///
/// Each wheel and direction has a floor, rad/s: the slowest command it is known to execute. A command whose turning
/// wheels sit below their floors is scaled up as a whole, so the path's curvature is kept and the robot still moves
/// along it, faster. The floors start at the configured deadband and, when adapting, grow from what the drive does:
/// a wheel commanded at or above its floor that turns at under a quarter of the command, or under nine tenths of it
/// and slowing down, and is not speeding up, for `stall_ms` in all is stalled, and its floor becomes 1.25 × the
/// smallest command of its latest stand, never more than `max_radps`. Below its command, a wheel that follows speeds
/// up towards it whatever its motor's lag, and one in its deadband runs down towards standing: a slow motor running
/// down is caught long before it falls under a quarter, and a slow motor starting is never taken for a stall. The
/// stalled time adds up over interruptions: a wheel whose deadband sits inside the range the controller's corrections
/// sweep stands below it, turns above it, stands again, and no single stand lasts long. A stall ends without learning
/// when the wheel follows, for `stall_ms` without a break, commands no larger than the smallest of its latest stand
/// (turning faster says nothing of a deadband below), or when the command stops or turns round. The caller judges when
/// a stall may be the drive's (not the dock or an obstacle holding the robot). No heap; O(wheels) per call.

#include <cstdint>

#include "dockcore/control/kinematics.hpp"
#include "dockcore/geometry.hpp"

namespace dockcore {

/// How dockcore treats the drive's wheel deadband ([robot.deadband] in dockd's config and scenarios).
struct WheelDeadbandParams {
  /// Deadband the drive is known to have, rad/s (0: none known): the starting floor of every wheel and direction.
  Real known_radps = 0;
  /// Learn larger floors per wheel and direction from commanded versus measured wheel speeds.
  bool adapt = true;
  /// Largest floor learned, rad/s: bounds how fast the slowest creep can become (floor × wheel radius).
  Real max_radps = static_cast<Real>(1.5);
  /// How long in all a wheel must be stalled before its floor grows, ms. Longer than the drive's command latency: a
  /// wheel that has not yet seen a new command neither follows it nor speeds up.
  std::uint16_t stall_ms = 150;
};

class WheelDeadband {
 public:
  /// A measured wheel speed under this share of the command counts as not following it.
  static constexpr Real kStallShare = static_cast<Real>(0.25);
  /// ... and so does one under this share of it that is slowing down: measured at most kSlowingShare of what it was
  /// kSlowingUs or more before (file comment). A creep's heading corrections take the command out of the deadband
  /// again before a slow motor has run down under kStallShare.
  static constexpr Real kFollowShare = static_cast<Real>(0.9);
  static constexpr Real kSlowingShare = static_cast<Real>(0.95);
  static constexpr std::uint32_t kSlowingUs = 60000;
  /// A wheel speeding up by this share of its command over kSlowingUs is following it, however far below it is (a
  /// slow motor starting, or turning round).
  static constexpr Real kRisingShare = static_cast<Real>(0.05);
  /// A stalled wheel's floor becomes this times the smallest command of the stall.
  static constexpr Real kGrowth = static_cast<Real>(1.25);
  /// A command at least this share of its floor counts as at the floor (scale() meets the floor up to rounding).
  static constexpr Real kAtFloor = static_cast<Real>(0.999);
  /// Wheels turning slower than this share of the fastest one are meant to stand nearly still (a pivot): they are
  /// left in the deadband rather than speeding the whole command up without bound.
  static constexpr Real kPivotShare = static_cast<Real>(0.25);

  /// Takes the parameters and forgets what was learned: every floor is known_radps (clamped to max_radps when
  /// adapting, to [0, ∞) always). O(wheels).
  void configure(const WheelDeadbandParams& params);

  /// The factor s >= 1 by which `twist` must be scaled so that every wheel of twist_to_wheels(geometry, twist) that
  /// turns at kPivotShare of the fastest one or more reaches its floor, limited so that no wheel exceeds
  /// limits.max_wheel_radps (when set). 1 for a zero twist or when no floor binds. O(wheels).
  Real scale(const DriveGeometry& geometry, const DriveLimits& limits, const Twist2& twist) const;

  /// One control tick's observation: the wheel speeds the drive was last commanded and those it measured since (same
  /// order and count), stamped `now_us` (the measurement's stamp: a tick without new feedback repeats it and adds no
  /// time). `learn` false (the robot may be held by the dock, an obstacle, a
  /// push; the feedback is stale) ends any stall in progress without learning, and so does a zero or reversed
  /// command. O(wheels).
  void observe(const WheelSpeeds& commanded, const WheelSpeeds& measured, std::uint64_t now_us, bool learn);

  /// The floor of `wheel` (< kMaxDriveWheels) for forward (`reverse` false) or backward rotation, rad/s. O(1).
  Real floor_radps(std::size_t wheel, bool reverse) const { return floor_radps_[wheel][reverse ? 1 : 0]; }
  /// Times a floor grew since configure(). O(1).
  std::uint32_t raises() const { return raises_; }
  /// What a drive taught: every wheel's floors, rad/s ([wheel][0] forward, [wheel][1] backward), and the raise count.
  struct Floors {
    Real radps[kMaxDriveWheels][2] = {};
    std::uint32_t raises = 0;
  };
  /// The floors now. O(wheels).
  Floors floors() const;
  /// Takes `learned`'s floors and raise count (not any stall in progress): what a drive taught one configuration,
  /// kept across another or a restart (the wheels are the same). Each floor is clamped as configure() clamps the
  /// starting one, and never lowered below this configuration's known deadband; a non-finite one is taken as 0.
  /// O(wheels).
  void restore_floors(const Floors& learned);

 private:
  /// `floor_radps` raised to the known deadband and, when adapting, capped at max_radps (0 when that is not > 0): the
  /// bounds every configured or restored floor keeps. O(1).
  Real bounded_floor(Real floor_radps) const;
  struct Stall {
    bool active = false;
    bool reverse = false;
    bool turned = false;             ///< Followed since the last stalled tick: the next one begins a new stand.
    std::uint64_t last_us = 0;       ///< The stall's last observation.
    std::uint64_t stalled_us = 0;    ///< Time spent not following since the stall began.
    std::uint64_t following_us = 0;  ///< Time spent following a command stood at, since the last stalled tick.
    Real min_command_radps = 0;      ///< Smallest command on a stalled tick of the latest stand.
  };
  /// A wheel's measured speed along its command kSlowingUs or more before: whether it is slowing down.
  struct Trend {
    std::uint64_t ref_us = 0;
    Real ref_along_radps = 0;
    bool have_ref = false;
    bool reverse = false;  ///< The command's direction the reference was taken along.
    bool slowing = false;
    bool rising = false;
  };
  WheelDeadbandParams params_{};
  Real floor_radps_[kMaxDriveWheels][2] = {};
  Stall stall_[kMaxDriveWheels] = {};
  Trend trend_[kMaxDriveWheels] = {};
  std::uint32_t raises_ = 0;
};

}  // namespace dockcore
