// dockcore CAN protocol v1 codecs. Byte layouts: docs/can.md (the tables there and in docs/can/dockcore.dbc are the
// specification; tests/unit/test_can_v1.cpp pins exact bytes and the canmatrix cross-check pins the DBC).
#include "dockcore/protocols/can/can_dockcore_v1.hpp"

namespace dockcore::can_v1 {

namespace {

void put_u16(std::uint8_t* d, std::uint16_t v) {
  d[0] = static_cast<std::uint8_t>(v & 0xFFu);
  d[1] = static_cast<std::uint8_t>((v >> 8) & 0xFFu);
}
void put_i16(std::uint8_t* d, std::int16_t v) { put_u16(d, static_cast<std::uint16_t>(v)); }
std::uint16_t get_u16(const std::uint8_t* d) {
  return static_cast<std::uint16_t>(static_cast<unsigned>(d[0]) | (static_cast<unsigned>(d[1]) << 8));
}
std::int16_t get_i16(const std::uint8_t* d) { return static_cast<std::int16_t>(get_u16(d)); }
void put_i24(std::uint8_t* d, std::int32_t v) {
  const std::uint32_t u = static_cast<std::uint32_t>(v);
  d[0] = static_cast<std::uint8_t>(u & 0xFFu);
  d[1] = static_cast<std::uint8_t>((u >> 8) & 0xFFu);
  d[2] = static_cast<std::uint8_t>((u >> 16) & 0xFFu);
}
std::int32_t get_i24(const std::uint8_t* d) {
  std::uint32_t u = static_cast<std::uint32_t>(d[0]) | (static_cast<std::uint32_t>(d[1]) << 8) |
                    (static_cast<std::uint32_t>(d[2]) << 16);
  if ((u & 0x800000u) != 0) u |= 0xFF000000u;  // sign-extend 24 -> 32 bits
  return static_cast<std::int32_t>(u);
}

// A zeroed v1 frame for `id`; finish() adds counter and CRC.
CanFrame start(std::uint32_t id) {
  CanFrame f;
  f.id = id & 0x7FFu;
  f.extended = false;
  f.dlc = kDlc;
  return f;
}
CanFrame finish(CanFrame f, std::uint8_t counter) {
  f.data[6] = static_cast<std::uint8_t>((f.data[6] & 0xF0u) | (counter & 0x0Fu));
  f.data[7] = crc8(f.id, f.data, 7);
  return f;
}

CanV1Error check_id(const CanFrame& f, std::uint32_t id) {
  if (f.extended) return CanV1Error::kExtendedId;
  if (f.id != id) return CanV1Error::kWrongId;
  return check_frame(f);
}
// Either half of a paired message: id == base + off_a or base + off_b.
CanV1Error check_pair(const CanFrame& f, std::uint32_t id_a, std::uint32_t id_b, bool& rear) {
  if (f.extended) return CanV1Error::kExtendedId;
  if (f.id != id_a && f.id != id_b) return CanV1Error::kWrongId;
  rear = f.id == id_b;
  return check_frame(f);
}

}  // namespace

const char* to_string(CanV1Error e) {
  switch (e) {
    case CanV1Error::kOk: return "ok";
    case CanV1Error::kWrongId: return "wrong_id";
    case CanV1Error::kExtendedId: return "extended_id";
    case CanV1Error::kBadLength: return "bad_length";
    case CanV1Error::kBadChecksum: return "bad_checksum";
    case CanV1Error::kCounterDuplicate: return "counter_duplicate";
    case CanV1Error::kCounterStale: return "counter_stale";
    case CanV1Error::kCounterJump: return "counter_jump";
  }
  return "invalid";
}

bool ids_valid(const Ids& ids) {
  if (ids.chassis_base + kOffChassisStatus > 0x7FFu) return false;
  if (ids.host_base + kOffDockPose > 0x7FFu) return false;
  const std::uint32_t c0 = ids.chassis_base;
  const std::uint32_t c1 = ids.chassis_base + kOffChassisStatus;
  const std::uint32_t h0 = ids.host_base;
  const std::uint32_t h1 = ids.host_base + kOffDockPose;
  return c1 < h0 || h1 < c0;
}

const char* to_string(MessageKind k) {
  switch (k) {
    case MessageKind::kUnknown: return "unknown";
    case MessageKind::kWheelCmdA: return "WheelCmdA";
    case MessageKind::kWheelCmdB: return "WheelCmdB";
    case MessageKind::kChargeRequest: return "ChargeRequest";
    case MessageKind::kWheelFbA: return "WheelFbA";
    case MessageKind::kWheelFbB: return "WheelFbB";
    case MessageKind::kEncoderA: return "EncoderA";
    case MessageKind::kEncoderB: return "EncoderB";
    case MessageKind::kPower: return "Power";
    case MessageKind::kChassisStatus: return "ChassisStatus";
    case MessageKind::kHostCommand: return "HostCommand";
    case MessageKind::kDockStatus: return "DockStatus";
    case MessageKind::kDockPose: return "DockPose";
    case MessageKind::kCount: break;
  }
  return "unknown";
}

MessageKind classify(const Ids& ids, std::uint32_t id) {
  if (id >= ids.chassis_base && id <= ids.chassis_base + kOffChassisStatus) {
    switch (id - ids.chassis_base) {
      case kOffWheelCmdA: return MessageKind::kWheelCmdA;
      case kOffWheelCmdB: return MessageKind::kWheelCmdB;
      case kOffChargeRequest: return MessageKind::kChargeRequest;
      case kOffWheelFbA: return MessageKind::kWheelFbA;
      case kOffWheelFbB: return MessageKind::kWheelFbB;
      case kOffEncoderA: return MessageKind::kEncoderA;
      case kOffEncoderB: return MessageKind::kEncoderB;
      case kOffPower: return MessageKind::kPower;
      case kOffChassisStatus: return MessageKind::kChassisStatus;
      default: break;
    }
  }
  if (id >= ids.host_base && id <= ids.host_base + kOffDockPose) {
    switch (id - ids.host_base) {
      case kOffHostCommand: return MessageKind::kHostCommand;
      case kOffDockStatus: return MessageKind::kDockStatus;
      case kOffDockPose: return MessageKind::kDockPose;
      default: break;
    }
  }
  return MessageKind::kUnknown;
}

std::uint32_t id_of(const Ids& ids, MessageKind k) {
  switch (k) {
    case MessageKind::kWheelCmdA: return ids.chassis_base + kOffWheelCmdA;
    case MessageKind::kWheelCmdB: return ids.chassis_base + kOffWheelCmdB;
    case MessageKind::kChargeRequest: return ids.chassis_base + kOffChargeRequest;
    case MessageKind::kWheelFbA: return ids.chassis_base + kOffWheelFbA;
    case MessageKind::kWheelFbB: return ids.chassis_base + kOffWheelFbB;
    case MessageKind::kEncoderA: return ids.chassis_base + kOffEncoderA;
    case MessageKind::kEncoderB: return ids.chassis_base + kOffEncoderB;
    case MessageKind::kPower: return ids.chassis_base + kOffPower;
    case MessageKind::kChassisStatus: return ids.chassis_base + kOffChassisStatus;
    case MessageKind::kHostCommand: return ids.host_base + kOffHostCommand;
    case MessageKind::kDockStatus: return ids.host_base + kOffDockStatus;
    case MessageKind::kDockPose: return ids.host_base + kOffDockPose;
    case MessageKind::kUnknown:
    case MessageKind::kCount: break;
  }
  return 0;
}

std::uint32_t period_ms(MessageKind k) {
  switch (k) {
    case MessageKind::kWheelCmdA:
    case MessageKind::kWheelCmdB:
    case MessageKind::kWheelFbA:
    case MessageKind::kWheelFbB:
    case MessageKind::kEncoderA:
    case MessageKind::kEncoderB: return 20;
    case MessageKind::kChargeRequest:
    case MessageKind::kPower:
    case MessageKind::kChassisStatus:
    case MessageKind::kDockStatus:
    case MessageKind::kDockPose: return 100;
    case MessageKind::kHostCommand:
    case MessageKind::kUnknown:
    case MessageKind::kCount: break;
  }
  return 0;
}

bool sent_by_base(MessageKind k) {
  return k == MessageKind::kWheelFbA || k == MessageKind::kWheelFbB || k == MessageKind::kEncoderA ||
         k == MessageKind::kEncoderB || k == MessageKind::kPower || k == MessageKind::kChassisStatus;
}

std::uint8_t crc8_h2f(const std::uint8_t* bytes, std::size_t n) {
  unsigned crc = 0xFFu;
  for (std::size_t i = 0; i < n; ++i) {
    crc ^= bytes[i];
    for (int b = 0; b < 8; ++b) crc = (crc & 0x80u) != 0 ? ((crc << 1) ^ 0x2Fu) & 0xFFu : (crc << 1) & 0xFFu;
  }
  return static_cast<std::uint8_t>(crc ^ 0xFFu);
}

std::uint8_t crc8(std::uint32_t id, const std::uint8_t* data, std::size_t n) {
  std::uint8_t buf[2 + 8];
  buf[0] = static_cast<std::uint8_t>(id & 0xFFu);
  buf[1] = static_cast<std::uint8_t>((id >> 8) & 0x07u);
  const std::size_t m = n > 8 ? 8 : n;
  for (std::size_t i = 0; i < m; ++i) buf[2 + i] = data[i];
  return crc8_h2f(buf, 2 + m);
}

CanV1Error check_frame(const CanFrame& f) {
  if (f.extended) return CanV1Error::kExtendedId;
  if (f.dlc != kDlc) return CanV1Error::kBadLength;
  if (crc8(f.id, f.data, 7) != f.data[7]) return CanV1Error::kBadChecksum;
  return CanV1Error::kOk;
}

// ---- encoders ----

CanFrame encode(const Ids& ids, const WheelCommandFrame& m) {
  CanFrame f = start(ids.chassis_base + (m.rear ? kOffWheelCmdB : kOffWheelCmdA));
  put_i16(&f.data[0], m.wheel_mmps[0]);
  put_i16(&f.data[2], m.wheel_mmps[1]);
  f.data[4] = static_cast<std::uint8_t>((m.enable ? 0x01u : 0u) | (m.four_wheel ? 0x02u : 0u));
  return finish(f, m.counter);
}

CanFrame encode(const Ids& ids, const ChargeRequestFrame& m) {
  CanFrame f = start(ids.chassis_base + kOffChargeRequest);
  f.data[0] = m.enable ? 1u : 0u;
  return finish(f, m.counter);
}

CanFrame encode(const Ids& ids, const WheelFeedbackFrame& m) {
  CanFrame f = start(ids.chassis_base + (m.rear ? kOffWheelFbB : kOffWheelFbA));
  put_i16(&f.data[0], m.wheel_mmps[0]);
  put_i16(&f.data[2], m.wheel_mmps[1]);
  return finish(f, m.counter);
}

CanFrame encode(const Ids& ids, const EncoderFrame& m) {
  CanFrame f = start(ids.chassis_base + (m.rear ? kOffEncoderB : kOffEncoderA));
  put_i24(&f.data[0], m.counts[0]);
  put_i24(&f.data[3], m.counts[1]);
  return finish(f, m.counter);
}

CanFrame encode(const Ids& ids, const PowerFrame& m) {
  CanFrame f = start(ids.chassis_base + kOffPower);
  put_u16(&f.data[0], m.voltage_10mv);
  put_i16(&f.data[2], m.current_10ma);
  f.data[4] = m.soc_pct;
  f.data[5] = static_cast<std::uint8_t>((m.contact ? 0x01u : 0u) | (m.charge_relay ? 0x02u : 0u));
  return finish(f, m.counter);
}

CanFrame encode(const Ids& ids, const ChassisStatusFrame& m) {
  CanFrame f = start(ids.chassis_base + kOffChassisStatus);
  f.data[0] = m.mode;
  f.data[1] = m.estop ? 1u : 0u;
  put_u16(&f.data[2], m.fault_bits);
  f.data[4] = m.last_cmd_counter;
  return finish(f, m.counter);
}

CanFrame encode(const Ids& ids, const HostCommandFrame& m) {
  CanFrame f = start(ids.host_base + kOffHostCommand);
  f.data[0] = m.command;
  put_u16(&f.data[1], m.dock_id);
  put_u16(&f.data[3], m.sequence);
  return finish(f, m.counter);
}

CanFrame encode(const Ids& ids, const DockStatusFrame& m) {
  CanFrame f = start(ids.host_base + kOffDockStatus);
  f.data[0] = m.task_state;
  f.data[1] = m.align_phase;
  put_u16(&f.data[2], m.fault_code);
  f.data[4] = m.retries;
  f.data[5] = static_cast<std::uint8_t>((m.last_result & 0x0Fu) | ((m.last_seq_lo & 0x0Fu) << 4));
  return finish(f, m.counter);
}

CanFrame encode(const Ids& ids, const DockPoseFrame& m) {
  CanFrame f = start(ids.host_base + kOffDockPose);
  put_i16(&f.data[0], m.x_mm);
  put_i16(&f.data[2], m.y_mm);
  put_i16(&f.data[4], m.yaw_100urad);
  f.data[6] = m.valid ? 0x10u : 0u;
  return finish(f, m.counter);
}

// ---- decoders ----

CanV1Error decode(const Ids& ids, const CanFrame& f, WheelCommandFrame& out) {
  bool rear = false;
  const CanV1Error e = check_pair(f, ids.chassis_base + kOffWheelCmdA, ids.chassis_base + kOffWheelCmdB, rear);
  if (e != CanV1Error::kOk) return e;
  out.rear = rear;
  out.wheel_mmps[0] = get_i16(&f.data[0]);
  out.wheel_mmps[1] = get_i16(&f.data[2]);
  out.enable = (f.data[4] & 0x01u) != 0;
  out.four_wheel = (f.data[4] & 0x02u) != 0;
  out.counter = frame_counter(f);
  return e;
}

CanV1Error decode(const Ids& ids, const CanFrame& f, ChargeRequestFrame& out) {
  const CanV1Error e = check_id(f, ids.chassis_base + kOffChargeRequest);
  if (e != CanV1Error::kOk) return e;
  out.enable = (f.data[0] & 0x01u) != 0;
  out.counter = frame_counter(f);
  return e;
}

CanV1Error decode(const Ids& ids, const CanFrame& f, WheelFeedbackFrame& out) {
  bool rear = false;
  const CanV1Error e = check_pair(f, ids.chassis_base + kOffWheelFbA, ids.chassis_base + kOffWheelFbB, rear);
  if (e != CanV1Error::kOk) return e;
  out.rear = rear;
  out.wheel_mmps[0] = get_i16(&f.data[0]);
  out.wheel_mmps[1] = get_i16(&f.data[2]);
  out.counter = frame_counter(f);
  return e;
}

CanV1Error decode(const Ids& ids, const CanFrame& f, EncoderFrame& out) {
  bool rear = false;
  const CanV1Error e = check_pair(f, ids.chassis_base + kOffEncoderA, ids.chassis_base + kOffEncoderB, rear);
  if (e != CanV1Error::kOk) return e;
  out.rear = rear;
  out.counts[0] = get_i24(&f.data[0]);
  out.counts[1] = get_i24(&f.data[3]);
  out.counter = frame_counter(f);
  return e;
}

CanV1Error decode(const Ids& ids, const CanFrame& f, PowerFrame& out) {
  const CanV1Error e = check_id(f, ids.chassis_base + kOffPower);
  if (e != CanV1Error::kOk) return e;
  out.voltage_10mv = get_u16(&f.data[0]);
  out.current_10ma = get_i16(&f.data[2]);
  out.soc_pct = f.data[4];
  out.contact = (f.data[5] & 0x01u) != 0;
  out.charge_relay = (f.data[5] & 0x02u) != 0;
  out.counter = frame_counter(f);
  return e;
}

CanV1Error decode(const Ids& ids, const CanFrame& f, ChassisStatusFrame& out) {
  const CanV1Error e = check_id(f, ids.chassis_base + kOffChassisStatus);
  if (e != CanV1Error::kOk) return e;
  out.mode = f.data[0];
  out.estop = (f.data[1] & 0x01u) != 0;
  out.fault_bits = get_u16(&f.data[2]);
  out.last_cmd_counter = f.data[4];
  out.counter = frame_counter(f);
  return e;
}

CanV1Error decode(const Ids& ids, const CanFrame& f, HostCommandFrame& out) {
  const CanV1Error e = check_id(f, ids.host_base + kOffHostCommand);
  if (e != CanV1Error::kOk) return e;
  out.command = f.data[0];
  out.dock_id = get_u16(&f.data[1]);
  out.sequence = get_u16(&f.data[3]);
  out.counter = frame_counter(f);
  return e;
}

CanV1Error decode(const Ids& ids, const CanFrame& f, DockStatusFrame& out) {
  const CanV1Error e = check_id(f, ids.host_base + kOffDockStatus);
  if (e != CanV1Error::kOk) return e;
  out.task_state = f.data[0];
  out.align_phase = f.data[1];
  out.fault_code = get_u16(&f.data[2]);
  out.retries = f.data[4];
  out.last_result = static_cast<std::uint8_t>(f.data[5] & 0x0Fu);
  out.last_seq_lo = static_cast<std::uint8_t>((f.data[5] >> 4) & 0x0Fu);
  out.counter = frame_counter(f);
  return e;
}

CanV1Error decode(const Ids& ids, const CanFrame& f, DockPoseFrame& out) {
  const CanV1Error e = check_id(f, ids.host_base + kOffDockPose);
  if (e != CanV1Error::kOk) return e;
  out.x_mm = get_i16(&f.data[0]);
  out.y_mm = get_i16(&f.data[2]);
  out.yaw_100urad = get_i16(&f.data[4]);
  out.valid = (f.data[6] & 0x10u) != 0;
  out.counter = frame_counter(f);
  return e;
}

// ---- counters ----

CanV1Error CounterTracker::accept(std::uint8_t counter) {
  const std::uint8_t c = static_cast<std::uint8_t>(counter & 0x0Fu);
  if (!have_last_) {
    have_last_ = true;
    last_ = c;
    ++ok_;
    return CanV1Error::kOk;
  }
  const unsigned d = (static_cast<unsigned>(c) - static_cast<unsigned>(last_)) & 0x0Fu;
  if (d == 0) {
    ++duplicates_;
    return CanV1Error::kCounterDuplicate;
  }
  last_ = c;
  if (d == 1) {
    ++ok_;
    return CanV1Error::kOk;
  }
  if (d <= 8) {
    ++jumps_;
    lost_ += d - 1;
    return CanV1Error::kCounterJump;
  }
  ++stale_;
  return CanV1Error::kCounterStale;
}

CanV1Error FrameChecker::check(const CanFrame& f, MessageKind& kind) {
  kind = f.extended ? MessageKind::kUnknown : classify(ids_, f.id);
  if (kind == MessageKind::kUnknown) {
    ++unknown_;
    return f.extended ? CanV1Error::kExtendedId : CanV1Error::kWrongId;
  }
  const std::size_t k = static_cast<std::size_t>(kind);
  CanV1Error e = check_frame(f);
  if (e == CanV1Error::kOk) e = trackers_[k].accept(frame_counter(f));
  const std::size_t r = static_cast<std::size_t>(e);
  if (r < kResults) ++counts_[k][r];
  return e;
}

void FrameChecker::reset(MessageKind k) {
  const std::size_t i = static_cast<std::size_t>(k);
  if (i < kKinds) trackers_[i].reset();
}

const CounterTracker& FrameChecker::tracker(MessageKind k) const {
  const std::size_t i = static_cast<std::size_t>(k);
  return trackers_[i < kKinds ? i : 0];
}

std::uint32_t FrameChecker::count(MessageKind k, CanV1Error e) const {
  const std::size_t i = static_cast<std::size_t>(k);
  const std::size_t r = static_cast<std::size_t>(e);
  return (i < kKinds && r < kResults) ? counts_[i][r] : 0u;
}

std::uint32_t FrameChecker::total(CanV1Error e) const {
  std::uint32_t s = 0;
  for (std::size_t i = 0; i < kKinds; ++i) s += count(static_cast<MessageKind>(i), e);
  return s;
}

}  // namespace dockcore::can_v1
