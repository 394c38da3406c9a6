// dockcore CAN protocol v1 codecs: exact bytes against hand-computed layouts (docs/can.md), the CRC's published
// check value, round trips of every message, every error code, the rolling counter's wrap and judgement.
#include <cstdint>
#include <cstdio>
#include <cstring>

#include "dockcore/protocols/can/can_dockcore_v1.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using namespace dockcore::can_v1;

namespace {

void check_bytes(const CanFrame& f, std::uint32_t id, const std::uint8_t (&want)[8]) {
  LONGS_EQUAL(id, f.id);
  CHECK_FALSE(f.extended);
  LONGS_EQUAL(8, f.dlc);
  for (int i = 0; i < 8; ++i) {
    if (f.data[i] != want[i]) {
      char msg[64];
      std::snprintf(msg, sizeof msg, "byte %d: got 0x%02X want 0x%02X", i, f.data[i], want[i]);
      FAIL(msg);
    }
  }
}

// Bitwise reference CRC written independently of the codec (MSB-first shift register).
std::uint8_t ref_crc(const std::uint8_t* b, std::size_t n) {
  std::uint8_t c = 0xFF;
  for (std::size_t i = 0; i < n; ++i) {
    for (int bit = 7; bit >= 0; --bit) {
      const bool in = ((b[i] >> bit) & 1) != 0;
      const bool top = (c & 0x80) != 0;
      c = static_cast<std::uint8_t>(c << 1);
      if (in != top) c ^= 0x2F;
    }
  }
  return static_cast<std::uint8_t>(c ^ 0xFF);
}

}  // namespace

TEST_GROUP(CanV1) {};

TEST(CanV1, Crc8H2fCheckValue) {
  const char* s = "123456789";
  LONGS_EQUAL(0xDF, crc8_h2f(reinterpret_cast<const std::uint8_t*>(s), 9));
  LONGS_EQUAL(ref_crc(reinterpret_cast<const std::uint8_t*>(s), 9), crc8_h2f(reinterpret_cast<const std::uint8_t*>(s), 9));
  const std::uint8_t d[7] = {1, 2, 3, 4, 5, 6, 7};
  const std::uint8_t with_id[9] = {0x80, 0x01, 1, 2, 3, 4, 5, 6, 7};
  LONGS_EQUAL(ref_crc(with_id, 9), crc8(0x180, d, 7));
  CHECK(crc8(0x180, d, 7) != crc8(0x181, d, 7));  // the id is covered
}

TEST(CanV1, WheelCommandExactBytes) {
  WheelCommandFrame m;
  m.wheel_mmps[0] = 250;    // 0x00FA
  m.wheel_mmps[1] = -100;   // 0xFF9C
  m.enable = true;
  m.counter = 0x13;         // masked to 3
  const CanFrame f = encode(Ids{}, m);
  std::uint8_t want[8] = {0xFA, 0x00, 0x9C, 0xFF, 0x01, 0x00, 0x03, 0};
  const std::uint8_t crc_in[9] = {0x00, 0x01, 0xFA, 0x00, 0x9C, 0xFF, 0x01, 0x00, 0x03};
  want[7] = ref_crc(crc_in, 9);
  check_bytes(f, 0x100, want);

  WheelCommandFrame back;
  LONGS_EQUAL(static_cast<int>(CanV1Error::kOk), static_cast<int>(decode(Ids{}, f, back)));
  CHECK_FALSE(back.rear);
  LONGS_EQUAL(250, back.wheel_mmps[0]);
  LONGS_EQUAL(-100, back.wheel_mmps[1]);
  CHECK(back.enable);
  CHECK_FALSE(back.four_wheel);
  LONGS_EQUAL(3, back.counter);
}

TEST(CanV1, EveryMessageRoundTripsWithCustomBases) {
  const Ids ids{0x300, 0x050};
  CHECK(ids_valid(ids));
  {
    WheelCommandFrame m{true, {-32768, 32767}, true, true, 15}, b;
    const CanFrame f = encode(ids, m);
    LONGS_EQUAL(0x301, f.id);
    CHECK(decode(ids, f, b) == CanV1Error::kOk);
    CHECK(b.rear && b.enable && b.four_wheel);
    LONGS_EQUAL(-32768, b.wheel_mmps[0]);
    LONGS_EQUAL(32767, b.wheel_mmps[1]);
    LONGS_EQUAL(15, b.counter);
  }
  {
    ChargeRequestFrame m{true, 7}, b;
    const CanFrame f = encode(ids, m);
    LONGS_EQUAL(0x302, f.id);
    LONGS_EQUAL(1, f.data[0]);
    CHECK(decode(ids, f, b) == CanV1Error::kOk);
    CHECK(b.enable);
    LONGS_EQUAL(7, b.counter);
  }
  {
    WheelFeedbackFrame m{true, {123, -456}, 9}, b;
    const CanFrame f = encode(ids, m);
    LONGS_EQUAL(0x311, f.id);
    CHECK(decode(ids, f, b) == CanV1Error::kOk);
    CHECK(b.rear);
    LONGS_EQUAL(123, b.wheel_mmps[0]);
    LONGS_EQUAL(-456, b.wheel_mmps[1]);
  }
  {
    EncoderFrame m{false, {-1, 0x00123456}, 2}, b;
    const CanFrame f = encode(ids, m);
    LONGS_EQUAL(0x312, f.id);
    const std::uint8_t head[6] = {0xFF, 0xFF, 0xFF, 0x56, 0x34, 0x12};
    CHECK(std::memcmp(head, f.data, 6) == 0);
    CHECK(decode(ids, f, b) == CanV1Error::kOk);
    LONGS_EQUAL(-1, b.counts[0]);
    LONGS_EQUAL(0x123456, b.counts[1]);
    // 24-bit wrap: 2^23 encodes as -2^23.
    EncoderFrame w{true, {8388608, -8388609}, 0};
    CHECK(decode(ids, encode(ids, w), b) == CanV1Error::kOk);
    CHECK(b.rear);
    LONGS_EQUAL(-8388608, b.counts[0]);
    LONGS_EQUAL(8388607, b.counts[1]);
  }
  {
    PowerFrame m{2450, -1234, 87, true, true, 4}, b;
    const CanFrame f = encode(ids, m);
    LONGS_EQUAL(0x314, f.id);
    const std::uint8_t head[6] = {0x92, 0x09, 0x2E, 0xFB, 87, 0x03};
    CHECK(std::memcmp(head, f.data, 6) == 0);
    CHECK(decode(ids, f, b) == CanV1Error::kOk);
    LONGS_EQUAL(2450, b.voltage_10mv);
    LONGS_EQUAL(-1234, b.current_10ma);
    LONGS_EQUAL(87, b.soc_pct);
    CHECK(b.contact && b.charge_relay);
  }
  {
    ChassisStatusFrame m{1, true, 0x8011, 12, 5}, b;
    const CanFrame f = encode(ids, m);
    LONGS_EQUAL(0x315, f.id);
    CHECK(decode(ids, f, b) == CanV1Error::kOk);
    LONGS_EQUAL(1, b.mode);
    CHECK(b.estop);
    LONGS_EQUAL(0x8011, b.fault_bits);
    LONGS_EQUAL(12, b.last_cmd_counter);
    LONGS_EQUAL(5, b.counter);
  }
  {
    HostCommandFrame m{1, 0x0203, 0xBEEF, 6}, b;
    const CanFrame f = encode(ids, m);
    LONGS_EQUAL(0x050, f.id);
    const std::uint8_t head[6] = {0x01, 0x03, 0x02, 0xEF, 0xBE, 0x00};
    CHECK(std::memcmp(head, f.data, 6) == 0);
    CHECK(decode(ids, f, b) == CanV1Error::kOk);
    LONGS_EQUAL(1, b.command);
    LONGS_EQUAL(0x0203, b.dock_id);
    LONGS_EQUAL(0xBEEF, b.sequence);
  }
  {
    DockStatusFrame m{3, 2, 181, 1, 6, 0xA, 8}, b;
    const CanFrame f = encode(ids, m);
    LONGS_EQUAL(0x051, f.id);
    const std::uint8_t head[7] = {3, 2, 181, 0, 1, 0xA6, 0x08};
    CHECK(std::memcmp(head, f.data, 7) == 0);
    CHECK(decode(ids, f, b) == CanV1Error::kOk);
    LONGS_EQUAL(3, b.task_state);
    LONGS_EQUAL(2, b.align_phase);
    LONGS_EQUAL(181, b.fault_code);
    LONGS_EQUAL(1, b.retries);
    LONGS_EQUAL(6, b.last_result);
    LONGS_EQUAL(0xA, b.last_seq_lo);
  }
  {
    DockPoseFrame m{-1500, 20, -31416, true, 11}, b;
    const CanFrame f = encode(ids, m);
    LONGS_EQUAL(0x052, f.id);
    LONGS_EQUAL(0x1B, f.data[6]);
    CHECK(decode(ids, f, b) == CanV1Error::kOk);
    LONGS_EQUAL(-1500, b.x_mm);
    LONGS_EQUAL(20, b.y_mm);
    LONGS_EQUAL(-31416, b.yaw_100urad);
    CHECK(b.valid);
    LONGS_EQUAL(11, b.counter);
  }
}

TEST(CanV1, EveryDecodeErrorLeavesOutputAlone) {
  const Ids ids;
  PowerFrame m{1000, 50, 40, true, false, 1};
  const CanFrame good = encode(ids, m);
  PowerFrame out{7, 7, 7, false, true, 9};

  CanFrame f = good;
  f.id = 0x113;
  CHECK(decode(ids, f, out) == CanV1Error::kWrongId);
  f = good;
  f.extended = true;
  CHECK(decode(ids, f, out) == CanV1Error::kExtendedId);
  f = good;
  f.dlc = 7;
  CHECK(decode(ids, f, out) == CanV1Error::kBadLength);
  for (int byte = 0; byte < 8; ++byte) {
    f = good;
    f.data[byte] ^= 0x10;
    CHECK(decode(ids, f, out) == CanV1Error::kBadChecksum);
  }
  // The same bytes under another base: the CRC covers the id.
  const Ids other{0x101, 0x180};
  f = good;
  f.id = 0x115;
  CHECK(decode(other, f, out) == CanV1Error::kBadChecksum);
  LONGS_EQUAL(7, out.voltage_10mv);
  LONGS_EQUAL(9, out.counter);
  CHECK(out.charge_relay);
  STRCMP_EQUAL("bad_checksum", to_string(CanV1Error::kBadChecksum));
  STRCMP_EQUAL("counter_jump", to_string(CanV1Error::kCounterJump));
}

TEST(CanV1, CounterTrackerJudgesEveryDistanceAndWraps) {
  CounterTracker t;
  CHECK(t.accept(14) == CanV1Error::kOk);  // first frame
  CHECK(t.accept(15) == CanV1Error::kOk);
  CHECK(t.accept(0) == CanV1Error::kOk);   // wrap 15 -> 0
  CHECK(t.accept(0) == CanV1Error::kCounterDuplicate);
  CHECK(t.accept(1) == CanV1Error::kOk);   // duplicate did not move `last`
  CHECK(t.accept(4) == CanV1Error::kCounterJump);  // 2 lost
  LONGS_EQUAL(2, t.lost_frames());
  CHECK(t.accept(12) == CanV1Error::kCounterJump);  // d = 8: 7 lost
  LONGS_EQUAL(9, t.lost_frames());
  CHECK(t.accept(11) == CanV1Error::kCounterStale);  // d = 15: one behind
  CHECK(t.accept(12) == CanV1Error::kOk);  // resynchronised after one rejected frame
  CHECK(t.accept(5) == CanV1Error::kCounterStale);  // d = 9
  LONGS_EQUAL(5, t.ok());
  LONGS_EQUAL(2, t.jumps());
  LONGS_EQUAL(1, t.duplicates());
  LONGS_EQUAL(2, t.stale());
  t.reset();
  CHECK(t.accept(9) == CanV1Error::kOk);
  // A full wrap of 40 consecutive frames is all ok.
  CounterTracker w;
  for (int i = 0; i < 40; ++i) CHECK(w.accept(static_cast<std::uint8_t>(i & 15)) == CanV1Error::kOk);
}

TEST(CanV1, FrameCheckerCountsPerKind) {
  const Ids ids;
  FrameChecker fc(ids);
  MessageKind k = MessageKind::kUnknown;
  for (std::uint8_t c = 0; c < 3; ++c) {
    DockStatusFrame s;
    s.counter = c;
    CHECK(fc.check(encode(ids, s), k) == CanV1Error::kOk);
    CHECK(k == MessageKind::kDockStatus);
  }
  DockStatusFrame s;
  s.counter = 2;
  CHECK(fc.check(encode(ids, s), k) == CanV1Error::kCounterDuplicate);
  CanFrame bad = encode(ids, s);
  bad.data[0] ^= 1;
  CHECK(fc.check(bad, k) == CanV1Error::kBadChecksum);
  CanFrame foreign;
  foreign.id = 0x7FF;
  foreign.dlc = 8;
  CHECK(fc.check(foreign, k) == CanV1Error::kWrongId);
  CHECK(k == MessageKind::kUnknown);
  LONGS_EQUAL(3, fc.count(MessageKind::kDockStatus, CanV1Error::kOk));
  LONGS_EQUAL(1, fc.count(MessageKind::kDockStatus, CanV1Error::kCounterDuplicate));
  LONGS_EQUAL(1, fc.total(CanV1Error::kBadChecksum));
  LONGS_EQUAL(1, fc.unknown_ids());
}

TEST(CanV1, IdsClassifyAndValidate) {
  const Ids ids;
  for (int k = 1; k < static_cast<int>(MessageKind::kCount); ++k) {
    const MessageKind kind = static_cast<MessageKind>(k);
    CHECK(classify(ids, id_of(ids, kind)) == kind);
  }
  CHECK(classify(ids, 0x103) == MessageKind::kUnknown);
  CHECK(classify(ids, 0x183) == MessageKind::kUnknown);
  LONGS_EQUAL(20, period_ms(MessageKind::kWheelCmdA));
  LONGS_EQUAL(100, period_ms(MessageKind::kDockStatus));
  LONGS_EQUAL(0, period_ms(MessageKind::kHostCommand));
  CHECK(ids_valid(Ids{0x100, 0x180}));
  CHECK_FALSE(ids_valid(Ids{0x100, 0x110}));  // overlapping ranges
  CHECK_FALSE(ids_valid(Ids{0x7F0, 0x180}));  // chassis range past 0x7FF
  CHECK_FALSE(ids_valid(Ids{0x100, 0x7FE}));
  CHECK(ids_valid(Ids{0x7EA, 0x000}));
  STRCMP_EQUAL("WheelCmdA", to_string(MessageKind::kWheelCmdA));
}

TEST(CanV1, EveryKindAndErrorHasItsOwnName) {
  // Message names are the DBC's frame names: one per kind, none shared, "unknown" only for kUnknown and values
  // outside the enum.
  const int kinds = static_cast<int>(MessageKind::kCount);
  for (int a = 1; a < kinds; ++a) {
    const char* name = to_string(static_cast<MessageKind>(a));
    CHECK(name != nullptr);
    CHECK(std::strcmp(name, "unknown") != 0);
    for (int b = 1; b < a; ++b) CHECK(std::strcmp(name, to_string(static_cast<MessageKind>(b))) != 0);
  }
  STRCMP_EQUAL("unknown", to_string(MessageKind::kUnknown));
  STRCMP_EQUAL("unknown", to_string(MessageKind::kCount));
  STRCMP_EQUAL("ChassisStatus", to_string(MessageKind::kChassisStatus));
  STRCMP_EQUAL("DockPose", to_string(MessageKind::kDockPose));
  // Error names as docs/can.md writes them (dock-decode prints them in brackets); "invalid" outside the enum.
  const char* const want[] = {"ok",           "wrong_id",          "extended_id",   "bad_length",
                              "bad_checksum", "counter_duplicate", "counter_stale", "counter_jump"};
  const CanV1Error errors[] = {CanV1Error::kOk,           CanV1Error::kWrongId,     CanV1Error::kExtendedId,
                               CanV1Error::kBadLength,    CanV1Error::kBadChecksum, CanV1Error::kCounterDuplicate,
                               CanV1Error::kCounterStale, CanV1Error::kCounterJump};
  for (std::size_t i = 0; i < sizeof(errors) / sizeof(errors[0]); ++i) STRCMP_EQUAL(want[i], to_string(errors[i]));
  STRCMP_EQUAL("invalid", to_string(static_cast<CanV1Error>(200)));
}

TEST(CanV1, SentByBaseIsExactlyTheBaseToHostRange) {
  // docs/can.md: chassis+0x10 .. chassis+0x15 go base -> dockd; chassis+0x00 .. 0x02 and the host range do not.
  for (const Ids ids : {Ids{}, Ids{0x300, 0x080}}) {
    for (int k = 1; k < static_cast<int>(MessageKind::kCount); ++k) {
      const MessageKind kind = static_cast<MessageKind>(k);
      const std::uint32_t id = id_of(ids, kind);
      const bool base_range = id >= ids.chassis_base + 0x10 && id <= ids.chassis_base + 0x15;
      CHECK_EQUAL(base_range, sent_by_base(kind));
    }
  }
  CHECK_FALSE(sent_by_base(MessageKind::kUnknown));
  LONGS_EQUAL(0, id_of(Ids{}, MessageKind::kUnknown));
  LONGS_EQUAL(0, id_of(Ids{}, MessageKind::kCount));
}

TEST(CanV1, FrameCheckerResetForgetsOneKindOnly) {
  const Ids ids;
  FrameChecker fc(ids);
  MessageKind k = MessageKind::kUnknown;
  DockStatusFrame s;
  WheelFeedbackFrame w;
  for (std::uint8_t c = 0; c < 3; ++c) {
    s.counter = c;
    w.counter = c;
    CHECK(fc.check(encode(ids, s), k) == CanV1Error::kOk);
    CHECK(fc.check(encode(ids, w), k) == CanV1Error::kOk);
    CHECK(k == MessageKind::kWheelFbA);
  }
  // A sender that restarted at counter 11: stale (d = 9) for a tracker that remembers 2, accepted after reset().
  s.counter = 11;
  CHECK(fc.check(encode(ids, s), k) == CanV1Error::kCounterStale);
  fc.reset(MessageKind::kDockStatus);
  s.counter = 12;
  CHECK(fc.check(encode(ids, s), k) == CanV1Error::kOk);
  // The wheel feedback's tracker was not reset: its last counter, 2, is still a duplicate.
  w.counter = 2;
  CHECK(fc.check(encode(ids, w), k) == CanV1Error::kCounterDuplicate);
  // tracker() shows each kind's own judgement counts.
  LONGS_EQUAL(4, fc.tracker(MessageKind::kDockStatus).ok());
  LONGS_EQUAL(1, fc.tracker(MessageKind::kDockStatus).stale());
  LONGS_EQUAL(0, fc.tracker(MessageKind::kDockStatus).duplicates());
  LONGS_EQUAL(3, fc.tracker(MessageKind::kWheelFbA).ok());
  LONGS_EQUAL(1, fc.tracker(MessageKind::kWheelFbA).duplicates());
  LONGS_EQUAL(0, fc.tracker(MessageKind::kPower).ok());
}
