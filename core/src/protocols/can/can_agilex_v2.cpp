// AgileX protocol V2 codecs: big-endian fields, DLC 8. Layouts: docs/can.md and docs/can/agilex_v2.dbc.
#include "dockcore/protocols/can/can_agilex_v2.hpp"

namespace dockcore::agilex_v2 {

namespace {

void put_u16(std::uint8_t* d, std::uint16_t v) {
  d[0] = static_cast<std::uint8_t>((v >> 8) & 0xFFu);
  d[1] = static_cast<std::uint8_t>(v & 0xFFu);
}
void put_i16(std::uint8_t* d, std::int16_t v) { put_u16(d, static_cast<std::uint16_t>(v)); }
void put_i32(std::uint8_t* d, std::int32_t v) {
  const std::uint32_t u = static_cast<std::uint32_t>(v);
  d[0] = static_cast<std::uint8_t>((u >> 24) & 0xFFu);
  d[1] = static_cast<std::uint8_t>((u >> 16) & 0xFFu);
  d[2] = static_cast<std::uint8_t>((u >> 8) & 0xFFu);
  d[3] = static_cast<std::uint8_t>(u & 0xFFu);
}
std::uint16_t get_u16(const std::uint8_t* d) {
  return static_cast<std::uint16_t>((static_cast<unsigned>(d[0]) << 8) | static_cast<unsigned>(d[1]));
}
std::int16_t get_i16(const std::uint8_t* d) { return static_cast<std::int16_t>(get_u16(d)); }
std::int32_t get_i32(const std::uint8_t* d) {
  return static_cast<std::int32_t>((static_cast<std::uint32_t>(d[0]) << 24) | (static_cast<std::uint32_t>(d[1]) << 16) |
                                   (static_cast<std::uint32_t>(d[2]) << 8) | static_cast<std::uint32_t>(d[3]));
}

CanFrame start(std::uint32_t id) {
  CanFrame f;
  f.id = id;
  f.dlc = kDlc;
  return f;
}

AgxError check(const CanFrame& f, std::uint32_t id) {
  if (f.extended) return AgxError::kExtendedId;
  if (f.id != id) return AgxError::kWrongId;
  if (f.dlc != kDlc) return AgxError::kBadLength;
  return AgxError::kOk;
}

}  // namespace

const char* to_string(AgxError e) {
  switch (e) {
    case AgxError::kOk: return "ok";
    case AgxError::kWrongId: return "wrong_id";
    case AgxError::kExtendedId: return "extended_id";
    case AgxError::kBadLength: return "bad_length";
  }
  return "invalid";
}

CanFrame encode(const ControlModeFrame& m) {
  CanFrame f = start(kIdControlMode);
  f.data[0] = m.mode;
  return f;
}

CanFrame encode(const MotionCommandFrame& m) {
  CanFrame f = start(kIdMotionCommand);
  put_i16(&f.data[0], m.linear_mmps);
  put_i16(&f.data[2], m.angular_mradps);
  put_i16(&f.data[4], m.lateral_mmps);
  put_i16(&f.data[6], m.steering_mrad);
  return f;
}

CanFrame encode(const SystemStateFrame& m) {
  CanFrame f = start(kIdSystemState);
  f.data[0] = m.vehicle_state;
  f.data[1] = m.control_mode;
  put_u16(&f.data[2], m.voltage_100mv);
  put_u16(&f.data[4], m.error_code);
  f.data[7] = m.count;
  return f;
}

CanFrame encode(const MotionStateFrame& m) {
  CanFrame f = start(kIdMotionState);
  put_i16(&f.data[0], m.linear_mmps);
  put_i16(&f.data[2], m.angular_mradps);
  put_i16(&f.data[4], m.lateral_mmps);
  put_i16(&f.data[6], m.steering_mrad);
  return f;
}

CanFrame encode(const OdometryFrame& m) {
  CanFrame f = start(kIdOdometry);
  put_i32(&f.data[0], m.left_mm);
  put_i32(&f.data[4], m.right_mm);
  return f;
}

CanFrame encode(const BmsFrame& m) {
  CanFrame f = start(kIdBms);
  f.data[0] = m.soc_pct;
  f.data[1] = m.soh_pct;
  put_u16(&f.data[2], m.voltage_100mv);
  put_i16(&f.data[4], m.current_100ma);
  put_i16(&f.data[6], m.temperature_100mdegc);
  return f;
}

AgxError decode(const CanFrame& f, ControlModeFrame& out) {
  const AgxError e = check(f, kIdControlMode);
  if (e == AgxError::kOk) out.mode = f.data[0];
  return e;
}

AgxError decode(const CanFrame& f, MotionCommandFrame& out) {
  const AgxError e = check(f, kIdMotionCommand);
  if (e != AgxError::kOk) return e;
  out.linear_mmps = get_i16(&f.data[0]);
  out.angular_mradps = get_i16(&f.data[2]);
  out.lateral_mmps = get_i16(&f.data[4]);
  out.steering_mrad = get_i16(&f.data[6]);
  return e;
}

AgxError decode(const CanFrame& f, SystemStateFrame& out) {
  const AgxError e = check(f, kIdSystemState);
  if (e != AgxError::kOk) return e;
  out.vehicle_state = f.data[0];
  out.control_mode = f.data[1];
  out.voltage_100mv = get_u16(&f.data[2]);
  out.error_code = get_u16(&f.data[4]);
  out.count = f.data[7];
  return e;
}

AgxError decode(const CanFrame& f, MotionStateFrame& out) {
  const AgxError e = check(f, kIdMotionState);
  if (e != AgxError::kOk) return e;
  out.linear_mmps = get_i16(&f.data[0]);
  out.angular_mradps = get_i16(&f.data[2]);
  out.lateral_mmps = get_i16(&f.data[4]);
  out.steering_mrad = get_i16(&f.data[6]);
  return e;
}

AgxError decode(const CanFrame& f, OdometryFrame& out) {
  const AgxError e = check(f, kIdOdometry);
  if (e != AgxError::kOk) return e;
  out.left_mm = get_i32(&f.data[0]);
  out.right_mm = get_i32(&f.data[4]);
  return e;
}

AgxError decode(const CanFrame& f, BmsFrame& out) {
  const AgxError e = check(f, kIdBms);
  if (e != AgxError::kOk) return e;
  out.soc_pct = f.data[0];
  out.soh_pct = f.data[1];
  out.voltage_100mv = get_u16(&f.data[2]);
  out.current_100ma = get_i16(&f.data[4]);
  out.temperature_100mdegc = get_i16(&f.data[6]);
  return e;
}

const char* frame_name(std::uint32_t id) {
  switch (id) {
    case kIdControlMode: return "ControlMode";
    case kIdMotionCommand: return "MotionCommand";
    case kIdSystemState: return "SystemState";
    case kIdMotionState: return "MotionState";
    case kIdOdometry: return "Odometry";
    case kIdBms: return "Bms";
    default: return nullptr;
  }
}

std::uint32_t period_ms(std::uint32_t id) {
  switch (id) {
    case kIdMotionCommand:
    case kIdMotionState:
    case kIdOdometry: return 20;
    case kIdSystemState: return 100;
    case kIdBms: return 500;
    default: return 0;
  }
}

}  // namespace dockcore::agilex_v2
