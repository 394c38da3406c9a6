#pragma once
/// @file Fault codes of the docking task, with stable numbers for the host protocol (CAN/UDP status frames).
/// 177-179 keep seed 004's meanings; 180+ are dockcore's, numbered in the order they were added (kLastFaultCode is the
/// highest). Every fault stops the robot (zero velocity) and switches the charge request off; docs/faults.md says when
/// each is raised and how it clears. Never renumber: hosts log them.

#include <cstdint>

namespace dockcore {

/// A fault reported by the task manager. The numeric value is what goes on the wire.
enum class FaultCode : std::uint16_t {
  kNone = 0,               ///< No fault.
  kDetectionFailed = 177,  ///< Dock not detected after the search swings (seed 004).
  /// Robot too far from the dock, or the lidar sees the dock far from where odometry expects it (pushed).
  kDistanceDeviation = 178,
  /// The lidar sees the dock turned by more than the angle tolerance from where odometry expects it (robot turned by
  /// hand).
  kAngleDeviation = 179,
  kObstacleTimeout = 180,     ///< The commanded motion stayed blocked by an obstacle longer than the obstacle timeout.
  kTargetLost = 181,          ///< No fresh dock estimate during alignment for longer than the loss timeout.
  kChargeNotConfirmed = 182,  ///< Contact plus charging current not confirmed after the last retry (robot backed off).
  kContactsLost = 183,        ///< The charging contacts opened while docked and charging.
  kChassisStale = 184,        ///< Chassis feedback (odometry, contact, current) reported stale by the host.
  kLidarStale = 185,          ///< Lidar scans reported stale by the host while the robot may move.
  kUndockFailed = 186,        ///< Undocking could not finish: charging current did not stop, or the back-off timed out.
  /// A host command was rejected (unknown, bad dock id, not applicable). Reported, never latched.
  kBadCommand = 187,
  kAlignFailed = 188,  ///< The controller gave up (kFailed) on the last retry (robot backed off).
  kTaskTimeout = 189,  ///< The docking task as a whole took longer than the task timeout.
  /// The contacts were not reached: the final push used up its distance or time without them closing (or they stayed
  /// open throughout the wait for the charge), on the last retry (robot backed off). kChargeNotConfirmed is the
  /// other failed end of an attempt at the contacts: they closed, the charging current did not come.
  kContactsNotReached = 190,
};

/// The lowest and highest fault codes in use (0 is kNone); every code between them has a name. Decoders use these to
/// tell a known code from a foreign one.
constexpr std::uint16_t kFirstFaultCode = 177;
constexpr std::uint16_t kLastFaultCode = 190;

/// Short stable name of a fault ("detection_failed", ...). Never null. O(1).
const char* to_string(FaultCode f);

}  // namespace dockcore
