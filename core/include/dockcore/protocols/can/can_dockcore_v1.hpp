#pragma once
/// @file dockcore CAN protocol v1: frame codecs for both directions (chassis base side and host side), the
/// checksum, and the rolling-counter tracker. The wire format is specified in docs/can.md and docs/can/dockcore.dbc;
/// this header is its executable form.
///
/// Every v1 frame: classic CAN, 11-bit id = base + documented offset, DLC 8, little-endian (Intel) signals,
/// byte 6 bits 0..3 = 4-bit rolling counter (+1 per frame sent of that id, wraps 15 -> 0), byte 7 = CRC-8 (see
/// crc8()) over the id and bytes 0..6. Reserved bits are sent as 0 and ignored on receive.
///
/// Stateless codecs: encode() never fails (values are wire integers; the counter is masked to 4 bits); decode()
/// checks id, frame format, length and checksum and writes `out` only on kOk. Counters are judged separately by
/// CounterTracker (or FrameChecker, which does everything for every v1 id). No heap, no exceptions; every call O(1).

#include <cstddef>
#include <cstdint>

#include "dockcore/protocols/can/can_frame.hpp"

namespace dockcore::can_v1 {

/// Result of decoding / checking one frame. Wire-independent; names are stable (to_string).
enum class CanV1Error : std::uint8_t {
  kOk = 0,
  kWrongId = 1,           ///< The id is not the one this decoder is for.
  kExtendedId = 2,        ///< A 29-bit frame: v1 uses 11-bit ids only.
  kBadLength = 3,         ///< DLC is not 8.
  kBadChecksum = 4,       ///< Byte 7 is not the CRC-8 of id and bytes 0..6.
  kCounterDuplicate = 5,  ///< Same counter as the previous frame of this id: rejected.
  kCounterStale = 6,      ///< Counter 9..15 steps ahead (= 1..7 behind): an old or replayed frame, rejected.
  kCounterJump = 7,       ///< Counter 2..8 steps ahead: 1..7 frames were lost. The frame itself is ACCEPTED.
};

/// Stable name ("ok", "bad_checksum", ...). Never null. O(1).
const char* to_string(CanV1Error e);

/// True when a frame with this result carries usable data (kOk or kCounterJump). O(1).
constexpr bool accepted(CanV1Error e) { return e == CanV1Error::kOk || e == CanV1Error::kCounterJump; }

/// Every v1 frame has 8 data bytes.
constexpr std::uint8_t kDlc = 8;

/// Default base ids (configurable: CanLinkOptions, dock-decode --chassis-base/--host-base).
constexpr std::uint32_t kDefaultChassisBaseId = 0x100;
constexpr std::uint32_t kDefaultHostBaseId = 0x180;

/// Id offsets from the chassis base.
constexpr std::uint32_t kOffWheelCmdA = 0x00;     ///< host -> base, 20 ms: wheels 0, 1.
constexpr std::uint32_t kOffWheelCmdB = 0x01;     ///< host -> base, 20 ms, four-wheel drives only: wheels 2, 3.
constexpr std::uint32_t kOffChargeRequest = 0x02; ///< host -> base, 100 ms + on change.
constexpr std::uint32_t kOffWheelFbA = 0x10;      ///< base -> host, 20 ms: measured wheels 0, 1.
constexpr std::uint32_t kOffWheelFbB = 0x11;      ///< base -> host, 20 ms, four-wheel drives only.
constexpr std::uint32_t kOffEncoderA = 0x12;      ///< base -> host, 20 ms: encoder counts wheels 0, 1.
constexpr std::uint32_t kOffEncoderB = 0x13;      ///< base -> host, 20 ms, four-wheel drives only.
constexpr std::uint32_t kOffPower = 0x14;         ///< base -> host, 100 ms.
constexpr std::uint32_t kOffChassisStatus = 0x15; ///< base -> host, 100 ms.
/// Id offsets from the host base.
constexpr std::uint32_t kOffHostCommand = 0x00;   ///< host -> dockd, on demand.
constexpr std::uint32_t kOffDockStatus = 0x01;    ///< dockd -> host, 100 ms + on change.
constexpr std::uint32_t kOffDockPose = 0x02;      ///< dockd -> host, 100 ms (with DockStatus).

/// Physical scale of the wire units (as in the DBC: physical = raw x scale).
constexpr double kWheelMpsPerBit = 0.001;   ///< Wheel speeds: 1 mm/s per bit.
constexpr double kVoltsPerBit = 0.01;       ///< Battery voltage.
constexpr double kAmpsPerBit = 0.01;        ///< Battery current.
constexpr double kPoseMetresPerBit = 0.001; ///< Dock pose x, y.
constexpr double kYawRadPerBit = 0.0001;    ///< Dock pose yaw.

/// The two configurable base ids.
struct Ids {
  std::uint32_t chassis_base = kDefaultChassisBaseId;
  std::uint32_t host_base = kDefaultHostBaseId;
};

/// True when every id of both ranges is an 11-bit id (chassis_base + 0x15 <= 0x7FF, host_base + 0x02 <= 0x7FF)
/// and the two ranges [chassis_base, +0x15] and [host_base, +0x02] do not overlap. O(1).
bool ids_valid(const Ids& ids);

/// Every v1 message, in id order within each base. kUnknown: an id of neither range.
enum class MessageKind : std::uint8_t {
  kUnknown = 0,
  kWheelCmdA,
  kWheelCmdB,
  kChargeRequest,
  kWheelFbA,
  kWheelFbB,
  kEncoderA,
  kEncoderB,
  kPower,
  kChassisStatus,
  kHostCommand,
  kDockStatus,
  kDockPose,
  kCount  ///< Number of entries (array sizes).
};

/// Frame name as in the DBC ("WheelCmdA", ...); "unknown" for kUnknown. Never null. O(1).
const char* to_string(MessageKind k);
/// The message an 11-bit id belongs to with these bases (ids in a range but at an unused offset: kUnknown). O(1).
MessageKind classify(const Ids& ids, std::uint32_t id);
/// The id of message `k` (0 for kUnknown / kCount). O(1).
std::uint32_t id_of(const Ids& ids, MessageKind k);
/// Documented nominal period of `k` in milliseconds; 0 = sent on demand only. O(1).
std::uint32_t period_ms(MessageKind k);
/// True for the messages the chassis base sends (feedback, encoders, power, status). O(1).
bool sent_by_base(MessageKind k);

/// CRC-8 of v1 frames: polynomial 0x2F, initial value 0xFF, no reflection, final XOR 0xFF (the AUTOSAR "CRC8H2F";
/// check value over ASCII "123456789" = 0xDF), computed over the byte sequence
///   id & 0xFF, (id >> 8) & 0x07, data[0], ..., data[n-1]
/// — n = 7 for v1 frames. Covering the id catches a frame sent with the wrong base. O(n).
std::uint8_t crc8(std::uint32_t id, const std::uint8_t* data, std::size_t n);
/// Plain CRC8H2F over `n` bytes (init 0xFF, final XOR 0xFF); crc8() is this over the id bytes then the data. O(n).
std::uint8_t crc8_h2f(const std::uint8_t* bytes, std::size_t n);

// ---------------------------------------------------------------------------------------------------------------
// Messages, in wire units (the unit is in every name). `counter` is the 4-bit rolling counter (encode masks it).

/// WheelCmdA (wheels 0, 1) / WheelCmdB (wheels 2, 3): commanded wheel rim speeds, mm/s, positive drives the robot
/// forward (wheel order of kinematics.hpp). A four-wheel drive sends A and B every tick with the same counter value;
/// the base applies a pair only when both halves with equal counters arrived.
struct WheelCommandFrame {
  bool rear = false;                 ///< false: WheelCmdA (wheels 0, 1); true: WheelCmdB (wheels 2, 3).
  std::int16_t wheel_mmps[2] = {0, 0};
  bool enable = false;               ///< Drive enabled. false: the base holds zero speed whatever the speeds say.
  bool four_wheel = false;           ///< The sender drives four wheels (a B frame belongs to this tick).
  std::uint8_t counter = 0;
};

/// ChargeRequest: switch the charger relay / charge path on the base on or off. Sent every 100 ms and on change;
/// the base opens the relay when none arrived for 500 ms.
struct ChargeRequestFrame {
  bool enable = false;
  std::uint8_t counter = 0;
};

/// WheelFbA / WheelFbB: measured wheel rim speeds, mm/s, same order and sign as the command.
struct WheelFeedbackFrame {
  bool rear = false;
  std::int16_t wheel_mmps[2] = {0, 0};
  std::uint8_t counter = 0;
};

/// EncoderA / EncoderB: wrapping encoder counts, 24 bits each (two's complement, -2^23 .. 2^23-1); the receiver
/// sign-extends and unwraps by differences. encode() takes the low 24 bits of any int32.
struct EncoderFrame {
  bool rear = false;
  std::int32_t counts[2] = {0, 0};
  std::uint8_t counter = 0;
};

/// Power: battery voltage 10 mV/bit, current 10 mA/bit signed (positive = into the battery, i.e. charging), state of
/// charge in % (0..100; 255 = unknown), charging contacts closed, charge relay closed.
struct PowerFrame {
  std::uint16_t voltage_10mv = 0;
  std::int16_t current_10ma = 0;
  std::uint8_t soc_pct = 255;
  bool contact = false;
  bool charge_relay = false;
  std::uint8_t counter = 0;
};

/// Base mode (ChassisStatus byte 0).
enum class ChassisMode : std::uint8_t { kStandby = 0, kCanControl = 1, kManual = 2, kFault = 3 };

/// ChassisStatus fault bits (byte 2..3).
constexpr std::uint16_t kFaultDrive = 1u << 0;         ///< Motor driver fault.
constexpr std::uint16_t kFaultOvercurrent = 1u << 1;
constexpr std::uint16_t kFaultOvertemp = 1u << 2;
constexpr std::uint16_t kFaultBatteryLow = 1u << 3;
constexpr std::uint16_t kFaultCmdTimeout = 1u << 4;    ///< No wheel command for 500 ms: the base stopped itself.
constexpr std::uint16_t kFaultCharger = 1u << 5;

/// ChassisStatus: mode, e-stop, fault bits, and the counter of the last wheel command the base applied
/// (0..15, 255 = none yet) so a log shows command-to-base latency. The rolling counter is the heartbeat.
struct ChassisStatusFrame {
  std::uint8_t mode = 0;  ///< ChassisMode.
  bool estop = false;
  std::uint16_t fault_bits = 0;
  std::uint8_t last_cmd_counter = 255;
  std::uint8_t counter = 0;
};

/// HostCommand: command code (HostCommandType: 1 dock, 2 cancel, 3 undock, 4 test_mode), dock id, and a 16-bit
/// sequence number that must increase (mod 2^16, by 1..32767) from one command to the next; dockd rejects replays
/// and out-of-order sequences (counted).
struct HostCommandFrame {
  std::uint8_t command = 0;
  std::uint16_t dock_id = 0;
  std::uint16_t sequence = 0;
  std::uint8_t counter = 0;
};

/// DockStatus: TaskState, controller phase in ALIGN, FaultCode (0 or 177..), retries used, CommandResult of the last
/// host command, and the sequence's low 8 bits of that command (so a host sees which command it answers).
struct DockStatusFrame {
  std::uint8_t task_state = 0;
  std::uint8_t align_phase = 0;
  std::uint16_t fault_code = 0;
  std::uint8_t retries = 0;
  std::uint8_t last_result = 0;  ///< CommandResult, low nibble on the wire (0..15).
  std::uint8_t last_seq_lo = 0;  ///< Low nibble on the wire: sequence & 0x0F of the last command.
  std::uint8_t counter = 0;
};

/// DockPose: dock estimate in the robot frame: x, y in mm (±32.767 m), yaw in 0.1 mrad (±3.2767 rad), valid flag.
struct DockPoseFrame {
  std::int16_t x_mm = 0;
  std::int16_t y_mm = 0;
  std::int16_t yaw_100urad = 0;
  bool valid = false;
  std::uint8_t counter = 0;
};

// Encoders: the complete frame (id from `ids`, DLC 8, counter, CRC). O(1).
CanFrame encode(const Ids& ids, const WheelCommandFrame& m);
CanFrame encode(const Ids& ids, const ChargeRequestFrame& m);
CanFrame encode(const Ids& ids, const WheelFeedbackFrame& m);
CanFrame encode(const Ids& ids, const EncoderFrame& m);
CanFrame encode(const Ids& ids, const PowerFrame& m);
CanFrame encode(const Ids& ids, const ChassisStatusFrame& m);
CanFrame encode(const Ids& ids, const HostCommandFrame& m);
CanFrame encode(const Ids& ids, const DockStatusFrame& m);
CanFrame encode(const Ids& ids, const DockPoseFrame& m);

// Decoders: check id (WheelCmd/WheelFb/Encoder accept either half and set `rear`), 11-bit format, DLC 8 and CRC, in
// that order; the first failure is returned and `out` is untouched. Counters are not judged here. O(1).
CanV1Error decode(const Ids& ids, const CanFrame& f, WheelCommandFrame& out);
CanV1Error decode(const Ids& ids, const CanFrame& f, ChargeRequestFrame& out);
CanV1Error decode(const Ids& ids, const CanFrame& f, WheelFeedbackFrame& out);
CanV1Error decode(const Ids& ids, const CanFrame& f, EncoderFrame& out);
CanV1Error decode(const Ids& ids, const CanFrame& f, PowerFrame& out);
CanV1Error decode(const Ids& ids, const CanFrame& f, ChassisStatusFrame& out);
CanV1Error decode(const Ids& ids, const CanFrame& f, HostCommandFrame& out);
CanV1Error decode(const Ids& ids, const CanFrame& f, DockStatusFrame& out);
CanV1Error decode(const Ids& ids, const CanFrame& f, DockPoseFrame& out);

/// Format, length and CRC check of a frame whose id is already known to be a v1 id (no id check). O(1).
CanV1Error check_frame(const CanFrame& f);

/// The 4-bit rolling counter of one v1 frame (byte 6 bits 0..3); 0 when DLC < 7. O(1).
inline std::uint8_t frame_counter(const CanFrame& f) {
  return f.dlc >= 7 ? static_cast<std::uint8_t>(f.data[6] & 0x0Fu) : static_cast<std::uint8_t>(0);
}

/// Rolling-counter judgement for one id. Let d = (counter - last) mod 16: d = 1 ok; d = 2..8 jump (d-1 frames lost,
/// frame accepted); d = 0 duplicate (rejected); d = 9..15 stale/replayed (rejected). The first frame after
/// construction or reset() is accepted. Every frame, accepted or not (except duplicates), becomes the new `last`,
/// so a sender that restarted at another counter value costs one rejected frame, not a lock-out. O(1).
class CounterTracker {
 public:
  /// Judges `counter` (low 4 bits used) and updates the counts. Returns kOk, kCounterJump, kCounterDuplicate or
  /// kCounterStale.
  CanV1Error accept(std::uint8_t counter);
  /// Forget the last counter (e.g. after the sender was silent long enough to have restarted).
  void reset() { have_last_ = false; }

  std::uint32_t ok() const { return ok_; }
  std::uint32_t jumps() const { return jumps_; }
  std::uint32_t lost_frames() const { return lost_; }  ///< Sum over jumps of the frames skipped.
  std::uint32_t duplicates() const { return duplicates_; }
  std::uint32_t stale() const { return stale_; }

 private:
  bool have_last_ = false;
  std::uint8_t last_ = 0;
  std::uint32_t ok_ = 0, jumps_ = 0, lost_ = 0, duplicates_ = 0, stale_ = 0;
};

/// Receive-side checks for every v1 id: classify, format/length/CRC, then the id's CounterTracker. Keeps a count of
/// every result per message kind. A frame with an unknown id returns kWrongId (counted in unknown_ids()).
class FrameChecker {
 public:
  explicit FrameChecker(const Ids& ids = Ids{}) : ids_(ids) {}
  /// Full check of one received frame; `kind` receives the message kind (kUnknown for foreign ids). Failing frames
  /// do not touch the tracker except as CounterTracker documents. O(1).
  CanV1Error check(const CanFrame& f, MessageKind& kind);
  /// Reset one kind's counter tracker (sender restarted / silent). O(1).
  void reset(MessageKind k);
  const Ids& ids() const { return ids_; }
  const CounterTracker& tracker(MessageKind k) const;
  /// Frames of kind `k` that ended with result `e`.
  std::uint32_t count(MessageKind k, CanV1Error e) const;
  /// Frames ending in `e` over all kinds.
  std::uint32_t total(CanV1Error e) const;
  std::uint32_t unknown_ids() const { return unknown_; }

 private:
  static constexpr std::size_t kKinds = static_cast<std::size_t>(MessageKind::kCount);
  static constexpr std::size_t kResults = 8;
  Ids ids_;
  CounterTracker trackers_[kKinds];
  std::uint32_t counts_[kKinds][kResults] = {};
  std::uint32_t unknown_ = 0;
};

}  // namespace dockcore::can_v1
