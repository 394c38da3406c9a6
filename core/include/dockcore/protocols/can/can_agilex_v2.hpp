#pragma once
/// @file AgileX mobile-base CAN protocol V2 (Scout, Scout Mini, Tracer, Bunker...): codecs for both directions of the
/// frames dockcore uses. 500 kbit/s, 11-bit ids, DLC 8, BIG-endian (Motorola) fields. Specification: docs/can.md
/// "AgileX profile" and docs/can/agilex_v2.dbc.
///
/// The base obeys 0x111 only after 0x421 = 1 (CAN command mode) and stops by itself when no 0x111 arrived for 500 ms
/// ("communication protection"): send 0x111 at >= 50 Hz. The protocol has no checksum; only 0x211 carries an 8-bit
/// count. Stateless codecs: encode() never fails; decode() checks id, 11-bit format and DLC 8 and writes `out` only
/// on kOk. No heap, no exceptions; every call O(1).

#include <cstdint>

#include "dockcore/protocols/can/can_frame.hpp"

namespace dockcore::agilex_v2 {

constexpr std::uint32_t kIdControlMode = 0x421;  ///< host -> base, on demand: 0 standby, 1 CAN command mode.
constexpr std::uint32_t kIdMotionCommand = 0x111;///< host -> base, 20 ms.
constexpr std::uint32_t kIdSystemState = 0x211;  ///< base -> host, 100 ms.
constexpr std::uint32_t kIdMotionState = 0x221;  ///< base -> host, 20 ms.
constexpr std::uint32_t kIdOdometry = 0x311;     ///< base -> host, 20 ms.
constexpr std::uint32_t kIdBms = 0x361;          ///< base -> host, ~500 ms (period not specified by the vendor).
constexpr std::uint8_t kDlc = 8;

/// Physical scale of the wire units (as in docs/can/agilex_v2.dbc: physical = raw x scale).
constexpr double kMpsPerBit = 0.001;        ///< Linear and lateral speed.
constexpr double kRadpsPerBit = 0.001;      ///< Angular speed.
constexpr double kRadPerBit = 0.001;        ///< Steering angle.
constexpr double kOdomMetresPerBit = 0.001; ///< Odometry.
constexpr double kVoltsPerBit = 0.1;        ///< 0x211 and 0x361 voltage.
constexpr double kAmpsPerBit = 0.1;         ///< 0x361 current.
constexpr double kDegCPerBit = 0.1;         ///< 0x361 temperature.

enum class AgxError : std::uint8_t {
  kOk = 0,
  kWrongId = 1,
  kExtendedId = 2,
  kBadLength = 3,  ///< DLC is not 8.
};
/// Stable name. Never null. O(1).
const char* to_string(AgxError e);

/// 0x421: control mode request. 0 = standby, 1 = CAN command mode.
struct ControlModeFrame {
  std::uint8_t mode = 1;
};
/// 0x111: body motion command. linear mm/s, angular 0.001 rad/s (CCW positive), lateral mm/s (omni bases),
/// steering angle 0.001 rad (Ackermann bases; 0 otherwise).
struct MotionCommandFrame {
  std::int16_t linear_mmps = 0;
  std::int16_t angular_mradps = 0;
  std::int16_t lateral_mmps = 0;
  std::int16_t steering_mrad = 0;
};
/// 0x211: vehicle state (0 normal, 1 e-stop, 2 exception), control mode (0 standby, 1 CAN, 3 remote control),
/// battery voltage 0.1 V/bit, error bits, 8-bit count (byte 7).
struct SystemStateFrame {
  std::uint8_t vehicle_state = 0;
  std::uint8_t control_mode = 0;
  std::uint16_t voltage_100mv = 0;
  std::uint16_t error_code = 0;
  std::uint8_t count = 0;
};
/// 0x221: measured motion, same scaling as 0x111.
struct MotionStateFrame {
  std::int16_t linear_mmps = 0;
  std::int16_t angular_mradps = 0;
  std::int16_t lateral_mmps = 0;
  std::int16_t steering_mrad = 0;
};
/// 0x311: wheel odometry, left and right travelled distance, mm (wrapping int32).
struct OdometryFrame {
  std::int32_t left_mm = 0;
  std::int32_t right_mm = 0;
};
/// 0x361: battery. SOC %, SOH %, voltage 0.1 V/bit, current 0.1 A/bit signed (taken as positive = charging; the
/// vendor documents no sign convention — verify on the real base), temperature 0.1 °C/bit.
struct BmsFrame {
  std::uint8_t soc_pct = 0;
  std::uint8_t soh_pct = 0;
  std::uint16_t voltage_100mv = 0;
  std::int16_t current_100ma = 0;
  std::int16_t temperature_100mdegc = 0;
};

// Encoders: complete frames (id, DLC 8, unused bytes 0). O(1).
CanFrame encode(const ControlModeFrame& m);
CanFrame encode(const MotionCommandFrame& m);
CanFrame encode(const SystemStateFrame& m);
CanFrame encode(const MotionStateFrame& m);
CanFrame encode(const OdometryFrame& m);
CanFrame encode(const BmsFrame& m);

// Decoders: id, format, DLC; `out` written only on kOk. O(1).
AgxError decode(const CanFrame& f, ControlModeFrame& out);
AgxError decode(const CanFrame& f, MotionCommandFrame& out);
AgxError decode(const CanFrame& f, SystemStateFrame& out);
AgxError decode(const CanFrame& f, MotionStateFrame& out);
AgxError decode(const CanFrame& f, OdometryFrame& out);
AgxError decode(const CanFrame& f, BmsFrame& out);

/// Frame name ("MotionCommand", ...) for one of the six ids, nullptr for any other id. O(1).
const char* frame_name(std::uint32_t id);
/// Documented nominal period in ms of one of the six ids; 0 = on demand or unknown. O(1).
std::uint32_t period_ms(std::uint32_t id);

}  // namespace dockcore::agilex_v2
