// AgileX protocol V2 codecs: exact big-endian bytes (including the vendor's 0x111 example), round trips, error codes.
#include <cstdint>
#include <cstring>

#include "dockcore/protocols/can/can_agilex_v2.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using namespace dockcore::agilex_v2;

TEST_GROUP(CanAgilex) {};

TEST(CanAgilex, MotionCommandExactBytes) {
  // protocols.md: bytes 00 FA FF 9C on 0x111 are 0.25 m/s and -0.1 rad/s.
  const CanFrame f = encode(MotionCommandFrame{250, -100, 0, 0});
  LONGS_EQUAL(0x111, f.id);
  LONGS_EQUAL(8, f.dlc);
  CHECK_FALSE(f.extended);
  const std::uint8_t want[8] = {0x00, 0xFA, 0xFF, 0x9C, 0, 0, 0, 0};
  CHECK(std::memcmp(want, f.data, 8) == 0);
  MotionCommandFrame b;
  CHECK(decode(f, b) == AgxError::kOk);
  LONGS_EQUAL(250, b.linear_mmps);
  LONGS_EQUAL(-100, b.angular_mradps);
}

TEST(CanAgilex, EveryFrameRoundTrips) {
  {
    const CanFrame f = encode(ControlModeFrame{1});
    LONGS_EQUAL(0x421, f.id);
    LONGS_EQUAL(1, f.data[0]);
    ControlModeFrame b{0};
    CHECK(decode(f, b) == AgxError::kOk);
    LONGS_EQUAL(1, b.mode);
  }
  {
    const CanFrame f = encode(SystemStateFrame{1, 1, 245, 0x0102, 77});
    const std::uint8_t want[8] = {1, 1, 0x00, 0xF5, 0x01, 0x02, 0, 77};
    CHECK(std::memcmp(want, f.data, 8) == 0);
    SystemStateFrame b;
    CHECK(decode(f, b) == AgxError::kOk);
    LONGS_EQUAL(245, b.voltage_100mv);
    LONGS_EQUAL(0x0102, b.error_code);
    LONGS_EQUAL(77, b.count);
  }
  {
    MotionStateFrame b;
    CHECK(decode(encode(MotionStateFrame{-32768, 32767, -5, 6}), b) == AgxError::kOk);
    LONGS_EQUAL(-32768, b.linear_mmps);
    LONGS_EQUAL(32767, b.angular_mradps);
    LONGS_EQUAL(-5, b.lateral_mmps);
    LONGS_EQUAL(6, b.steering_mrad);
  }
  {
    const CanFrame f = encode(OdometryFrame{-2, 0x01020304});
    const std::uint8_t want[8] = {0xFF, 0xFF, 0xFF, 0xFE, 0x01, 0x02, 0x03, 0x04};
    CHECK(std::memcmp(want, f.data, 8) == 0);
    OdometryFrame b;
    CHECK(decode(f, b) == AgxError::kOk);
    LONGS_EQUAL(-2, b.left_mm);
    LONGS_EQUAL(0x01020304, b.right_mm);
  }
  {
    const CanFrame f = encode(BmsFrame{85, 99, 262, -25, 315});
    const std::uint8_t want[8] = {85, 99, 0x01, 0x06, 0xFF, 0xE7, 0x01, 0x3B};
    CHECK(std::memcmp(want, f.data, 8) == 0);
    BmsFrame b;
    CHECK(decode(f, b) == AgxError::kOk);
    LONGS_EQUAL(262, b.voltage_100mv);
    LONGS_EQUAL(-25, b.current_100ma);
    LONGS_EQUAL(315, b.temperature_100mdegc);
  }
}

TEST(CanAgilex, ErrorsLeaveOutputAlone) {
  const CanFrame good = encode(OdometryFrame{1, 2});
  OdometryFrame out{42, 43};
  CanFrame f = good;
  f.id = 0x312;
  CHECK(decode(f, out) == AgxError::kWrongId);
  f = good;
  f.extended = true;
  CHECK(decode(f, out) == AgxError::kExtendedId);
  f = good;
  f.dlc = 4;
  CHECK(decode(f, out) == AgxError::kBadLength);
  LONGS_EQUAL(42, out.left_mm);
  LONGS_EQUAL(43, out.right_mm);
  STRCMP_EQUAL("bad_length", to_string(AgxError::kBadLength));
  STRCMP_EQUAL("Odometry", frame_name(0x311));
  CHECK(frame_name(0x312) == nullptr);
  LONGS_EQUAL(20, period_ms(0x111));
}

TEST(CanAgilex, EveryIdHasItsNameAndPeriod) {
  // The vendor's frames: name, and the period the header documents (0 = on demand).
  struct Row {
    std::uint32_t id;
    const char* name;
    std::uint32_t period_ms;
  };
  const Row rows[] = {{kIdControlMode, "ControlMode", 0},   {kIdMotionCommand, "MotionCommand", 20},
                      {kIdSystemState, "SystemState", 100}, {kIdMotionState, "MotionState", 20},
                      {kIdOdometry, "Odometry", 20},        {kIdBms, "Bms", 500}};
  for (const Row& r : rows) {
    STRCMP_EQUAL(r.name, frame_name(r.id));
    LONGS_EQUAL(r.period_ms, period_ms(r.id));
  }
  CHECK(frame_name(0) == nullptr);
  LONGS_EQUAL(0, period_ms(0x312));
  const AgxError errors[] = {AgxError::kOk, AgxError::kWrongId, AgxError::kExtendedId, AgxError::kBadLength};
  const char* const names[] = {"ok", "wrong_id", "extended_id", "bad_length"};
  for (std::size_t i = 0; i < 4; ++i) STRCMP_EQUAL(names[i], to_string(errors[i]));
  STRCMP_EQUAL("invalid", to_string(static_cast<AgxError>(200)));
}
