// CanLink over the in-memory FakeCanBus: both chassis profiles (dockcore v1, AgileX V2) and the v1 host frames —
// unit conversions, counters and checksums on the wire, bad frames counted and ignored, host sequence rules,
// bounded command queue, keep-alives; and open_socketcan's message on a kernel without CAN.
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

#include <sys/socket.h>
#include <unistd.h>

#include "../support/fake_can_bus.hpp"
#include "dockcore/drivers/can_link.hpp"
#include "dockcore/protocols/can/can_agilex_v2.hpp"
#include "dockcore/protocols/can/can_dockcore_v1.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using dockcore::testing::FakeCanBus;
namespace v1 = dockcore::can_v1;
namespace agx = dockcore::agilex_v2;

namespace {

drivers::CanLinkOptions v1_options() {
  drivers::CanLinkOptions o;
  o.drive.kind = DriveKind::kDifferential;
  o.drive.wheel_radius_m = static_cast<Real>(0.05);
  o.drive.wheel_base_m = static_cast<Real>(0.30);
  return o;
}

v1::HostCommandFrame host_cmd(std::uint8_t cmd, std::uint16_t seq, std::uint8_t counter) {
  v1::HostCommandFrame h;
  h.command = cmd;
  h.dock_id = 3;
  h.sequence = seq;
  h.counter = counter;
  return h;
}

}  // namespace

TEST_GROUP(CanLink) {};

TEST(CanLink, V1WheelCommandsCarryMmPerSecondCounterAndCrc) {
  FakeCanBus bus;
  auto link = drivers::make_can_link(bus, v1_options());
  hal::WheelCommand cmd;
  cmd.count = 2;
  cmd.radps[0] = static_cast<Real>(5.0);    // 5 rad/s * 0.05 m = 250 mm/s
  cmd.radps[1] = static_cast<Real>(-2.0);   // -100 mm/s
  for (int i = 0; i < 18; ++i) CHECK(link->send_wheels(cmd));
  LONGS_EQUAL(18, bus.sent().size());
  v1::CounterTracker t;
  for (const CanFrame& f : bus.sent()) {
    v1::WheelCommandFrame m;
    CHECK(v1::decode(v1::Ids{}, f, m) == v1::CanV1Error::kOk);
    CHECK(t.accept(m.counter) == v1::CanV1Error::kOk);  // consecutive counters, wrapping after 15
    LONGS_EQUAL(250, m.wheel_mmps[0]);
    LONGS_EQUAL(-100, m.wheel_mmps[1]);
    CHECK(m.enable);
    CHECK_FALSE(m.four_wheel);
  }
  // Non-finite command: zero speeds with the drive disabled.
  bus.clear_sent();
  cmd.radps[0] = static_cast<Real>(NAN);
  CHECK(link->send_wheels(cmd));
  v1::WheelCommandFrame m;
  CHECK(v1::decode(v1::Ids{}, bus.sent().at(0), m) == v1::CanV1Error::kOk);
  CHECK_FALSE(m.enable);
  LONGS_EQUAL(0, m.wheel_mmps[0]);
  LONGS_EQUAL(0, m.wheel_mmps[1]);
  LONGS_EQUAL(19, link->counters().frames_sent);
}

TEST(CanLink, V1MecanumSendsBothHalvesWithOneCounter) {
  FakeCanBus bus;
  drivers::CanLinkOptions o = v1_options();
  o.drive.kind = DriveKind::kMecanum;
  o.chassis_base_id = 0x200;
  auto link = drivers::make_can_link(bus, o);
  hal::WheelCommand cmd;
  cmd.count = 4;
  for (int i = 0; i < 4; ++i) cmd.radps[i] = static_cast<Real>(i + 1);
  CHECK(link->send_wheels(cmd));
  LONGS_EQUAL(2, bus.sent().size());
  const v1::Ids ids{0x200, 0x180};
  v1::WheelCommandFrame a, b;
  CHECK(v1::decode(ids, bus.sent()[0], a) == v1::CanV1Error::kOk);
  CHECK(v1::decode(ids, bus.sent()[1], b) == v1::CanV1Error::kOk);
  LONGS_EQUAL(0x200, bus.sent()[0].id);
  LONGS_EQUAL(0x201, bus.sent()[1].id);
  CHECK(a.four_wheel && b.four_wheel && b.rear);
  LONGS_EQUAL(a.counter, b.counter);
  LONGS_EQUAL(50, a.wheel_mmps[0]);
  LONGS_EQUAL(200, b.wheel_mmps[1]);
}

TEST(CanLink, V1FeedbackPowerStatusAndBadFrames) {
  FakeCanBus bus;
  auto link = drivers::make_can_link(bus, v1_options());
  const v1::Ids ids;
  bus.inject(v1::encode(ids, v1::WheelFeedbackFrame{false, {250, -100}, 0}), 1000);
  bus.inject(v1::encode(ids, v1::EncoderFrame{false, {8388600, -5}, 0}), 1001);
  bus.inject(v1::encode(ids, v1::EncoderFrame{false, {-8388600, -10}, 1}), 1002);  // wraps forward by 16 counts
  bus.inject(v1::encode(ids, v1::PowerFrame{2512, 150, 64, true, true, 0}), 1003);
  bus.inject(v1::encode(ids, v1::ChassisStatusFrame{1, true, v1::kFaultCmdTimeout, 3, 0}), 1004);
  const hal::ChassisFeedback& fb = link->poll();
  DOUBLES_EQUAL(5.0, static_cast<double>(fb.wheel_radps[0]), 1e-5);
  DOUBLES_EQUAL(-2.0, static_cast<double>(fb.wheel_radps[1]), 1e-5);
  LONGS_EQUAL(1001 + 1, fb.wheels_stamp_us);
  LONGS_EQUAL(8388600 + 16, fb.encoder_counts[0]);
  LONGS_EQUAL(-10, fb.encoder_counts[1]);
  DOUBLES_EQUAL(25.12, static_cast<double>(fb.battery_voltage_v), 1e-4);
  DOUBLES_EQUAL(1.5, static_cast<double>(fb.battery_current_a), 1e-5);
  DOUBLES_EQUAL(0.64, static_cast<double>(fb.soc), 1e-5);
  CHECK(fb.charging_contact);
  CHECK(fb.estop);
  LONGS_EQUAL(v1::kFaultCmdTimeout, fb.fault_bits);
  LONGS_EQUAL(1004, fb.status_stamp_us);
  LONGS_EQUAL(5, link->counters().frames_received);
  LONGS_EQUAL(0, link->counters().bad_frames);

  // Bad checksum, bad length, a duplicate counter, an unused id inside the range: counted, nothing changes.
  CanFrame bad = v1::encode(ids, v1::WheelFeedbackFrame{false, {999, 999}, 1});
  bad.data[7] ^= 0xFF;
  bus.inject(bad);
  CanFrame shorty = v1::encode(ids, v1::WheelFeedbackFrame{false, {999, 999}, 1});
  shorty.dlc = 6;
  bus.inject(shorty);
  bus.inject(v1::encode(ids, v1::WheelFeedbackFrame{false, {999, 999}, 0}));  // duplicate of counter 0
  CanFrame unused = v1::encode(ids, v1::WheelFeedbackFrame{});
  unused.id = 0x105;
  bus.inject(unused);
  CanFrame foreign = unused;
  foreign.id = 0x7A0;  // outside both ranges: not ours, not counted as bad
  bus.inject(foreign);
  link->poll();
  LONGS_EQUAL(4, link->counters().bad_frames);
  DOUBLES_EQUAL(5.0, static_cast<double>(fb.wheel_radps[0]), 1e-5);

  // Bus counters are mirrored.
  bus.inject_error(true);
  bus.fail_sends(1);
  CHECK_FALSE(link->send_wheels(hal::WheelCommand{}));
  link->poll();
  LONGS_EQUAL(1, link->counters().bus_errors);
  LONGS_EQUAL(1, link->counters().bus_off);
  LONGS_EQUAL(1, link->counters().send_failures);
  bus.inject_error(false);
  link->poll();
  LONGS_EQUAL(2, link->counters().bus_errors);
  LONGS_EQUAL(1, link->counters().bus_off);
}

// Error frames as the kernel (or `cansend vcan0 200000XX#...`) delivers them: id = CAN_ERR_FLAG | classes,
// data[1] = controller state (linux/can/error.h).
TEST(CanLink, ErrorFrameDecode) {
  const std::uint8_t none[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  drivers::CanErrorReport r = drivers::decode_can_error_frame(0x123u, none);  // a data frame
  CHECK_FALSE(r.error_frame);
  CHECK_FALSE(r.bus_off);
  STRCMP_EQUAL("", r.message);
  r = drivers::decode_can_error_frame(0x80000123u, none);  // extended data frame (CAN_EFF_FLAG): not an error
  CHECK_FALSE(r.error_frame);

  r = drivers::decode_can_error_frame(0x20000040u, none);  // CAN_ERR_BUSOFF
  CHECK(r.error_frame);
  CHECK(r.bus_off);
  CHECK_FALSE(r.restarted);
  STRCMP_CONTAINS("bus-off", r.message);
  r = drivers::decode_can_error_frame(0x20000044u, none);  // bus-off wins over the controller class
  CHECK(r.bus_off);
  STRCMP_CONTAINS("bus-off", r.message);

  const std::uint8_t passive[8] = {0, 0x20, 0, 0, 0, 0, 0, 0};   // CAN_ERR_CRTL_TX_PASSIVE
  const std::uint8_t warning[8] = {0, 0x04, 0, 0, 0, 0, 0, 0};   // CAN_ERR_CRTL_RX_WARNING
  const std::uint8_t overflow[8] = {0, 0x01, 0, 0, 0, 0, 0, 0};  // CAN_ERR_CRTL_RX_OVERFLOW
  r = drivers::decode_can_error_frame(0x20000004u, passive);     // CAN_ERR_CRTL
  CHECK(r.error_frame);
  CHECK_FALSE(r.bus_off);
  STRCMP_EQUAL("socketcan: controller error passive", r.message);
  STRCMP_EQUAL("socketcan: controller error warning", drivers::decode_can_error_frame(0x20000004u, warning).message);
  STRCMP_EQUAL("socketcan: controller buffer overflow", drivers::decode_can_error_frame(0x20000004u, overflow).message);
  STRCMP_EQUAL("socketcan: controller problem", drivers::decode_can_error_frame(0x20000004u, nullptr).message);

  STRCMP_CONTAINS("bus error", drivers::decode_can_error_frame(0x20000080u, none).message);  // CAN_ERR_BUSERROR
  STRCMP_CONTAINS("protocol", drivers::decode_can_error_frame(0x20000008u, none).message);   // CAN_ERR_PROT
  STRCMP_CONTAINS("no ACK", drivers::decode_can_error_frame(0x20000020u, none).message);     // CAN_ERR_ACK
  STRCMP_CONTAINS("transmit timeout", drivers::decode_can_error_frame(0x20000001u, none).message);
  STRCMP_CONTAINS("lost arbitration", drivers::decode_can_error_frame(0x20000002u, none).message);
  r = drivers::decode_can_error_frame(0x20000100u, none);  // CAN_ERR_RESTARTED
  CHECK(r.error_frame);
  CHECK(r.restarted);
  CHECK_FALSE(r.bus_off);
  STRCMP_CONTAINS("restarted", r.message);
  STRCMP_EQUAL("socketcan: error frame", drivers::decode_can_error_frame(0x20000000u, none).message);
}

TEST(CanLink, HostCommandsSequenceRulesAndBoundedQueue) {
  FakeCanBus bus;
  auto link = drivers::make_can_link(bus, v1_options());
  const v1::Ids ids;
  bus.inject(v1::encode(ids, host_cmd(1, 100, 0)), 10);
  bus.inject(v1::encode(ids, host_cmd(2, 100, 1)), 11);   // replayed sequence (fresh counter): rejected
  bus.inject(v1::encode(ids, host_cmd(2, 99, 2)), 12);    // older: rejected
  bus.inject(v1::encode(ids, host_cmd(3, 101, 3)), 13);   // next: accepted
  bus.inject(v1::encode(ids, host_cmd(3, 101, 3)), 14);   // identical frame again: counter duplicate -> bad frame
  link->poll();
  hal::HostCommandMessage m;
  CHECK(link->poll_command(m));
  LONGS_EQUAL(1, m.command);
  LONGS_EQUAL(3, m.dock_id);
  LONGS_EQUAL(100, m.sequence);
  LONGS_EQUAL(10, m.stamp_us);
  CHECK(link->poll_command(m));
  LONGS_EQUAL(3, m.command);
  LONGS_EQUAL(101, m.sequence);
  CHECK_FALSE(link->poll_command(m));
  LONGS_EQUAL(2, link->host_commands_rejected());
  LONGS_EQUAL(1, link->counters().bad_frames);

  // Sequence wrap 65535 -> 0 is "newer"; queue holds 8, the rest are rejected and counted (fresh link: 65530
  // would be "older" than 101).
  FakeCanBus bus2;
  link = drivers::make_can_link(bus2, v1_options());
  std::uint16_t seq = 65530;
  std::uint8_t ctr = 4;
  for (int i = 0; i < 12; ++i) {
    bus2.inject(v1::encode(ids, host_cmd(2, seq, ctr)));
    seq = static_cast<std::uint16_t>(seq + 1);
    ctr = static_cast<std::uint8_t>((ctr + 1) & 15);
  }
  link->poll();
  int n = 0;
  while (link->poll_command(m)) ++n;
  LONGS_EQUAL(8, n);
  LONGS_EQUAL(4, link->host_commands_rejected());
}

TEST(CanLink, StatusFramesAndChargeKeepAlive) {
  FakeCanBus bus;
  auto link = drivers::make_can_link(bus, v1_options());
  const v1::Ids ids;
  bus.inject(v1::encode(ids, host_cmd(1, 0x1234, 0)));
  link->poll();
  hal::StatusMessage s;
  s.task_state = 3;
  s.align_phase = 2;
  s.fault_code = 0;
  s.retries = 1;
  s.last_result = 1;
  s.dock_valid = true;
  s.dock_in_robot.x_m = static_cast<Real>(1.2346);
  s.dock_in_robot.y_m = static_cast<Real>(-0.05);
  s.dock_in_robot.yaw_rad = static_cast<Real>(-0.5);
  CHECK(link->send_status(s));
  LONGS_EQUAL(2, bus.sent().size());
  v1::DockStatusFrame st;
  v1::DockPoseFrame p;
  CHECK(v1::decode(ids, bus.sent()[0], st) == v1::CanV1Error::kOk);
  CHECK(v1::decode(ids, bus.sent()[1], p) == v1::CanV1Error::kOk);
  LONGS_EQUAL(3, st.task_state);
  LONGS_EQUAL(2, st.align_phase);
  LONGS_EQUAL(1, st.retries);
  LONGS_EQUAL(1, st.last_result);
  LONGS_EQUAL(0x4, st.last_seq_lo);
  CHECK(p.valid);
  LONGS_EQUAL(1235, p.x_mm);  // rounded
  LONGS_EQUAL(-50, p.y_mm);
  LONGS_EQUAL(-5000, p.yaw_100urad);

  bus.clear_sent();
  CHECK(link->request_charging(true));
  LONGS_EQUAL(1, bus.sent().size());
  for (std::uint64_t t = 0; t <= 1000000; t += 20000) link->service(t);  // 1 s of 50 Hz ticks
  // One immediate frame plus one per 100 ms.
  CHECK(bus.sent().size() >= 10 && bus.sent().size() <= 12);
  v1::ChargeRequestFrame c;
  CHECK(v1::decode(ids, bus.sent().back(), c) == v1::CanV1Error::kOk);
  CHECK(c.enable);
}

TEST(CanLink, AgilexTwistFeedbackAndEnable) {
  FakeCanBus bus;
  drivers::CanLinkOptions o = v1_options();
  o.protocol = drivers::ChassisProtocol::kAgilexV2;
  auto link = drivers::make_can_link(bus, o);
  std::size_t n = 0;
  const std::uint32_t* ids = link->rx_ids(n);
  LONGS_EQUAL(5, n);
  LONGS_EQUAL(agx::kIdSystemState, ids[0]);
  LONGS_EQUAL(0x180, ids[4]);

  link->service(1000);
  LONGS_EQUAL(1, bus.sent().size());
  LONGS_EQUAL(0x421, bus.sent()[0].id);
  LONGS_EQUAL(1, bus.sent()[0].data[0]);
  link->service(50000);  // within 100 ms: no repeat
  LONGS_EQUAL(1, bus.sent().size());
  link->service(101000);
  LONGS_EQUAL(2, bus.sent().size());
  bus.inject(agx::encode(agx::SystemStateFrame{0, 1, 250, 0, 0}));
  link->poll();
  link->service(300000);  // the base reports CAN mode: no more enables
  LONGS_EQUAL(2, bus.sent().size());

  // Wheels 5 rad/s and 3 rad/s (r = 0.05, B = 0.3): v = 0.2 m/s, w = -0.333 rad/s.
  bus.clear_sent();
  hal::WheelCommand cmd;
  cmd.radps[0] = static_cast<Real>(5);
  cmd.radps[1] = static_cast<Real>(3);
  CHECK(link->send_wheels(cmd));
  agx::MotionCommandFrame mc;
  CHECK(agx::decode(bus.sent().at(0), mc) == agx::AgxError::kOk);
  LONGS_EQUAL(200, mc.linear_mmps);
  LONGS_EQUAL(-333, mc.angular_mradps);

  bus.inject(agx::encode(agx::MotionStateFrame{200, -333, 0, 0}), 77);
  bus.inject(agx::encode(agx::OdometryFrame{1500, -20}));
  bus.inject(agx::encode(agx::BmsFrame{80, 99, 262, 25, 300}));
  CanFrame bad = agx::encode(agx::BmsFrame{});
  bad.dlc = 5;
  bus.inject(bad);
  const hal::ChassisFeedback& fb = link->poll();
  DOUBLES_EQUAL(5.0, static_cast<double>(fb.wheel_radps[0]), 0.01);
  DOUBLES_EQUAL(3.0, static_cast<double>(fb.wheel_radps[1]), 0.01);
  LONGS_EQUAL(77, fb.wheels_stamp_us);
  LONGS_EQUAL(1500, fb.encoder_counts[0]);
  LONGS_EQUAL(-20, fb.encoder_counts[1]);
  DOUBLES_EQUAL(26.2, static_cast<double>(fb.battery_voltage_v), 1e-4);
  DOUBLES_EQUAL(2.5, static_cast<double>(fb.battery_current_a), 1e-5);
  CHECK(fb.charging_contact);
  LONGS_EQUAL(1, link->counters().bad_frames);
  CHECK(link->request_charging(true));  // no relay frame on AgileX
  LONGS_EQUAL(1, bus.sent().size());

  // Host frames still work on the AgileX profile.
  bus.inject(v1::encode(v1::Ids{}, host_cmd(1, 5, 0)));
  link->poll();
  hal::HostCommandMessage m;
  CHECK(link->poll_command(m));
  LONGS_EQUAL(5, m.sequence);
}

TEST(CanLink, RxIdsAndProtocolNames) {
  drivers::CanLinkOptions o;
  o.chassis_base_id = 0x300;
  o.host_base_id = 0x400;
  std::uint32_t ids[16];
  const std::size_t n = drivers::can_link_rx_ids(o, ids, 16);
  LONGS_EQUAL(7, n);
  LONGS_EQUAL(0x310, ids[0]);
  LONGS_EQUAL(0x315, ids[5]);
  LONGS_EQUAL(0x400, ids[6]);
  LONGS_EQUAL(3, drivers::can_link_rx_ids(o, ids, 3));
  CHECK(drivers::parse_chassis_protocol("agilex-v2") == drivers::ChassisProtocol::kAgilexV2);
  CHECK(drivers::parse_chassis_protocol("dockcore-v1") == drivers::ChassisProtocol::kDockcoreV1);
  CHECK(!drivers::parse_chassis_protocol("canopen").has_value());
  STRCMP_EQUAL("agilex-v2", drivers::to_string(drivers::ChassisProtocol::kAgilexV2));
}

TEST(CanLink, OpenSocketcanExplainsMissingKernelSupport) {
  // Only meaningful where the kernel has no CAN (this project's build machines); elsewhere vcan may or may not exist.
  const int s = socket(PF_CAN, SOCK_RAW, 1);
  if (s >= 0) {
    close(s);
    return;
  }
  std::string err;
  const std::uint32_t ids[1] = {0x110};
  auto bus = drivers::open_socketcan("vcan0", ids, 1, err);
  CHECK(bus == nullptr);
  CHECK(err.find("kernel has no CAN support") != std::string::npos);
  err.clear();
  CHECK(drivers::open_socketcan("", ids, 1, err) == nullptr);
  CHECK(err.find("bad interface name") != std::string::npos);
}
