// Prints test vectors for the DBC cross-check (tests/can/dbc_crosscheck.py): one JSON object per line with the DBC
// it belongs to, the frame id and bytes made by core's encoders, and every signal's physical value computed from the
// message struct and the scales in the codec headers. Deterministic (fixed LCG seed); edge values plus random ones.
#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "dockcore/protocols/can/can_agilex_v2.hpp"
#include "dockcore/protocols/can/can_dockcore_v1.hpp"

namespace {

using namespace dockcore;

std::uint32_t g_state = 12345u;
std::uint32_t rnd() {
  g_state = g_state * 1664525u + 1013904223u;
  return g_state >> 8;
}
std::int16_t ri16() { return static_cast<std::int16_t>(static_cast<std::uint16_t>(rnd())); }
std::uint16_t ru16() { return static_cast<std::uint16_t>(rnd()); }
std::uint8_t ru8() { return static_cast<std::uint8_t>(rnd()); }
std::int32_t ri32() { return static_cast<std::int32_t>((rnd() << 16) ^ rnd()); }
std::int32_t ri24() { return static_cast<std::int32_t>(rnd() & 0xFFFFFFu) - 0x800000; }

using Signals = std::vector<std::pair<std::string, double>>;

void emit(const char* dbc, const CanFrame& f, const Signals& s) {
  std::printf("{\"dbc\":\"%s\",\"id\":%" PRIu32 ",\"data\":\"", dbc, f.id);
  for (int i = 0; i < f.dlc; ++i) std::printf("%02X", f.data[i]);
  std::printf("\",\"signals\":{");
  for (std::size_t i = 0; i < s.size(); ++i) std::printf("%s\"%s\":%.10g", i ? "," : "", s[i].first.c_str(), s[i].second);
  std::printf("}}\n");
}

void v1(int round) {
  namespace v = can_v1;
  const v::Ids ids;  // the DBC uses the default bases
  const auto c = [] { return static_cast<std::uint8_t>(rnd() & 15u); };
  const auto crc = [](const CanFrame& f) { return static_cast<double>(f.data[7]); };
  const bool edge = round == 0;
  for (int half = 0; half < 2; ++half) {
    v::WheelCommandFrame m{half == 1, {edge ? std::int16_t(-32768) : ri16(), edge ? std::int16_t(32767) : ri16()},
                           (rnd() & 1) != 0, (rnd() & 1) != 0, c()};
    const CanFrame f = v::encode(ids, m);
    const char* w0 = half ? "Wheel2Speed" : "Wheel0Speed";
    const char* w1 = half ? "Wheel3Speed" : "Wheel1Speed";
    emit("dockcore", f, {{w0, m.wheel_mmps[0] * v::kWheelMpsPerBit}, {w1, m.wheel_mmps[1] * v::kWheelMpsPerBit},
                         {"DriveEnable", m.enable}, {"FourWheel", m.four_wheel}, {"Counter", m.counter},
                         {"Checksum", crc(f)}});
    v::WheelFeedbackFrame fb{half == 1, {ri16(), ri16()}, c()};
    const CanFrame g = v::encode(ids, fb);
    emit("dockcore", g, {{half ? "Wheel2Measured" : "Wheel0Measured", fb.wheel_mmps[0] * v::kWheelMpsPerBit},
                         {half ? "Wheel3Measured" : "Wheel1Measured", fb.wheel_mmps[1] * v::kWheelMpsPerBit},
                         {"Counter", fb.counter}, {"Checksum", crc(g)}});
    v::EncoderFrame e{half == 1, {edge ? -8388608 : ri24(), edge ? 8388607 : ri24()}, c()};
    const CanFrame h = v::encode(ids, e);
    emit("dockcore", h, {{half ? "Encoder2" : "Encoder0", e.counts[0]}, {half ? "Encoder3" : "Encoder1", e.counts[1]},
                         {"Counter", e.counter}, {"Checksum", crc(h)}});
  }
  {
    v::ChargeRequestFrame m{(rnd() & 1) != 0, c()};
    const CanFrame f = v::encode(ids, m);
    emit("dockcore", f, {{"ChargeEnable", m.enable}, {"Counter", m.counter}, {"Checksum", crc(f)}});
  }
  {
    v::PowerFrame m{edge ? std::uint16_t(65535) : ru16(), edge ? std::int16_t(-32768) : ri16(), ru8(),
                    (rnd() & 1) != 0, (rnd() & 1) != 0, c()};
    const CanFrame f = v::encode(ids, m);
    emit("dockcore", f, {{"BatteryVoltage", m.voltage_10mv * v::kVoltsPerBit},
                         {"BatteryCurrent", m.current_10ma * v::kAmpsPerBit}, {"SOC", m.soc_pct},
                         {"ChargingContact", m.contact}, {"ChargeRelay", m.charge_relay}, {"Counter", m.counter},
                         {"Checksum", crc(f)}});
  }
  {
    v::ChassisStatusFrame m{ru8(), (rnd() & 1) != 0, ru16(), ru8(), c()};
    const CanFrame f = v::encode(ids, m);
    emit("dockcore", f, {{"Mode", m.mode}, {"EStop", m.estop}, {"FaultBits", m.fault_bits},
                         {"LastCmdCounter", m.last_cmd_counter}, {"Counter", m.counter}, {"Checksum", crc(f)}});
  }
  {
    v::HostCommandFrame m{ru8(), ru16(), ru16(), c()};
    const CanFrame f = v::encode(ids, m);
    emit("dockcore", f, {{"Command", m.command}, {"DockId", m.dock_id}, {"Sequence", m.sequence},
                         {"Counter", m.counter}, {"Checksum", crc(f)}});
  }
  {
    v::DockStatusFrame m{ru8(), ru8(), ru16(), ru8(), static_cast<std::uint8_t>(rnd() & 15u),
                         static_cast<std::uint8_t>(rnd() & 15u), c()};
    const CanFrame f = v::encode(ids, m);
    emit("dockcore", f, {{"TaskState", m.task_state}, {"AlignPhase", m.align_phase}, {"FaultCode", m.fault_code},
                         {"Retries", m.retries}, {"LastResult", m.last_result}, {"LastSeqLo", m.last_seq_lo},
                         {"Counter", m.counter}, {"Checksum", crc(f)}});
  }
  {
    v::DockPoseFrame m{ri16(), ri16(), edge ? std::int16_t(-31416) : ri16(), (rnd() & 1) != 0, c()};
    const CanFrame f = v::encode(ids, m);
    emit("dockcore", f, {{"DockX", m.x_mm * v::kPoseMetresPerBit}, {"DockY", m.y_mm * v::kPoseMetresPerBit},
                         {"DockYaw", m.yaw_100urad * v::kYawRadPerBit}, {"PoseValid", m.valid},
                         {"Counter", m.counter}, {"Checksum", crc(f)}});
  }
}

void agilex(int round) {
  namespace a = agilex_v2;
  const bool edge = round == 0;
  {
    a::ControlModeFrame m{static_cast<std::uint8_t>(rnd() & 1u)};
    emit("agilex_v2", a::encode(m), {{"ControlMode", m.mode}});
  }
  {
    a::MotionCommandFrame m = edge ? a::MotionCommandFrame{250, -100, 0, 0}
                                   : a::MotionCommandFrame{ri16(), ri16(), ri16(), ri16()};
    emit("agilex_v2", a::encode(m), {{"LinearVelocity", m.linear_mmps * a::kMpsPerBit},
                                     {"AngularVelocity", m.angular_mradps * a::kRadpsPerBit},
                                     {"LateralVelocity", m.lateral_mmps * a::kMpsPerBit},
                                     {"SteeringAngle", m.steering_mrad * a::kRadPerBit}});
  }
  {
    a::SystemStateFrame m{ru8(), ru8(), ru16(), ru16(), ru8()};
    emit("agilex_v2", a::encode(m), {{"VehicleState", m.vehicle_state}, {"ControlMode", m.control_mode},
                                     {"BatteryVoltage", m.voltage_100mv * a::kVoltsPerBit},
                                     {"ErrorCode", m.error_code}, {"Count", m.count}});
  }
  {
    a::MotionStateFrame m{ri16(), ri16(), ri16(), ri16()};
    emit("agilex_v2", a::encode(m), {{"LinearVelocity", m.linear_mmps * a::kMpsPerBit},
                                     {"AngularVelocity", m.angular_mradps * a::kRadpsPerBit},
                                     {"LateralVelocity", m.lateral_mmps * a::kMpsPerBit},
                                     {"SteeringAngle", m.steering_mrad * a::kRadPerBit}});
  }
  {
    a::OdometryFrame m{edge ? INT32_MIN : ri32(), edge ? INT32_MAX : ri32()};
    emit("agilex_v2", a::encode(m), {{"LeftWheel", m.left_mm * a::kOdomMetresPerBit},
                                     {"RightWheel", m.right_mm * a::kOdomMetresPerBit}});
  }
  {
    a::BmsFrame m{ru8(), ru8(), ru16(), ri16(), ri16()};
    emit("agilex_v2", a::encode(m), {{"SOC", m.soc_pct}, {"SOH", m.soh_pct}, {"Voltage", m.voltage_100mv * a::kVoltsPerBit},
                                     {"Current", m.current_100ma * a::kAmpsPerBit},
                                     {"Temperature", m.temperature_100mdegc * a::kDegCPerBit}});
  }
}

}  // namespace

int main() {
  for (int round = 0; round < 20; ++round) {
    v1(round);
    agilex(round);
  }
  return 0;
}
