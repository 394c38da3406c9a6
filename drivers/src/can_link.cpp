// CanLink: the chassis link (dockcore CAN v1 or AgileX V2) and the host link (dockcore v1 host frames) over one
// hal::CanBus. Conversions and rules: docs/can.md "CanLink".
#include <cmath>
#include <cstring>
#include <limits>

#include "dockcore/drivers/can_link.hpp"
#include "dockcore/protocols/can/can_agilex_v2.hpp"
#include "dockcore/protocols/can/can_dockcore_v1.hpp"

namespace dockcore::drivers {

namespace {

namespace v1 = dockcore::can_v1;
namespace agx = dockcore::agilex_v2;

constexpr std::uint64_t kChargeRepeatUs = 100000;  // ChargeRequest keep-alive (base times out after 500 ms)
constexpr std::uint64_t kAgxEnableRepeatUs = 100000;  // 0x421 while the base is not in CAN mode
constexpr std::size_t kQueue = 8;

// Rounds `v` to the nearest integer and saturates to int16; NaN gives 0.
std::int16_t sat16(double v) {
  if (!(v == v)) return 0;
  const double r = std::nearbyint(v);
  if (r > 32767.0) return 32767;
  if (r < -32768.0) return -32768;
  return static_cast<std::int16_t>(r);
}

class CanLinkImpl final : public CanLink {
 public:
  CanLinkImpl(hal::CanBus& bus, const CanLinkOptions& o)
      : bus_(bus), opt_(o), ids_{o.chassis_base_id, o.host_base_id}, checker_(ids_) {
    rx_count_ = can_link_rx_ids(o, rx_, sizeof rx_ / sizeof rx_[0]);
  }

  // ---- ChassisLink ----
  bool send_wheels(const hal::WheelCommand& cmd) override {
    const std::size_t n = cmd.count > 4 ? 4 : cmd.count;
    bool finite = true;
    for (std::size_t i = 0; i < n; ++i) finite = finite && std::isfinite(static_cast<double>(cmd.radps[i]));
    const double r = static_cast<double>(opt_.drive.wheel_radius_m);
    if (opt_.protocol == ChassisProtocol::kDockcoreV1) {
      v1::WheelCommandFrame a;
      a.four_wheel = n > 2;
      a.enable = finite;
      a.counter = wheel_counter_;
      for (std::size_t i = 0; i < 2 && i < n; ++i)
        a.wheel_mmps[i] = finite ? sat16(static_cast<double>(cmd.radps[i]) * r * 1000.0) : std::int16_t(0);
      bool ok = send(v1::encode(ids_, a));
      if (n > 2) {
        v1::WheelCommandFrame b = a;
        b.rear = true;
        for (std::size_t i = 2; i < n; ++i)
          b.wheel_mmps[i - 2] = finite ? sat16(static_cast<double>(cmd.radps[i]) * r * 1000.0) : std::int16_t(0);
        ok = send(v1::encode(ids_, b)) && ok;
      }
      wheel_counter_ = static_cast<std::uint8_t>((wheel_counter_ + 1) & 0x0F);
      return ok;
    }
    agx::MotionCommandFrame m;
    if (finite) {
      WheelSpeeds w;
      w.count = drive_wheel_count(opt_.drive.kind);
      for (std::size_t i = 0; i < w.count && i < n; ++i) w.radps[i] = cmd.radps[i];
      const Twist2 t = wheels_to_twist(opt_.drive, w);
      m.linear_mmps = sat16(static_cast<double>(t.vx_mps) * 1000.0);
      m.angular_mradps = sat16(static_cast<double>(t.wz_radps) * 1000.0);
      m.lateral_mmps = sat16(static_cast<double>(t.vy_mps) * 1000.0);
    }
    return send(agx::encode(m));
  }

  bool request_charging(bool on) override {
    charge_on_ = on;
    charge_requested_ = true;
    if (opt_.protocol != ChassisProtocol::kDockcoreV1) return true;  // AgileX: no relay frame; contacts are passive
    return send_charge();
  }

  const hal::ChassisFeedback& poll() override {
    CanFrame f;
    std::uint64_t stamp = 0;
    // Bounded: at most one queue-full of frames per call so a flooding node cannot hold the control loop.
    for (int i = 0; i < 512 && bus_.receive(f, stamp); ++i) {
      ++counters_.frames_received;
      dispatch(f, stamp);
    }
    const hal::CanBusCounters& b = bus_.counters();
    counters_.send_failures = b.send_failures;
    counters_.bus_errors = b.bus_errors;
    counters_.bus_off = b.bus_off;
    counters_.rx_overflows = b.rx_overflows;
    return fb_;
  }

  int fd() const override { return bus_.fd(); }
  const hal::ChassisCounters& counters() const override { return counters_; }

  // ---- HostLink ----
  bool poll_command(hal::HostCommandMessage& out) override {
    if (q_count_ == 0) return false;
    out = queue_[q_head_];
    q_head_ = (q_head_ + 1) % kQueue;
    --q_count_;
    return true;
  }

  bool send_status(const hal::StatusMessage& s) override {
    v1::DockStatusFrame st;
    st.task_state = s.task_state;
    st.align_phase = s.align_phase;
    st.fault_code = s.fault_code;
    st.retries = s.retries;
    st.last_result = s.last_result;
    st.last_seq_lo = static_cast<std::uint8_t>(last_seq_ & 0x0F);
    st.counter = status_counter_;
    status_counter_ = static_cast<std::uint8_t>((status_counter_ + 1) & 0x0F);
    v1::DockPoseFrame p;
    p.valid = s.dock_valid;
    p.x_mm = sat16(static_cast<double>(s.dock_in_robot.x_m) * 1000.0);
    p.y_mm = sat16(static_cast<double>(s.dock_in_robot.y_m) * 1000.0);
    p.yaw_100urad = sat16(static_cast<double>(s.dock_in_robot.yaw_rad) / v1::kYawRadPerBit);
    p.counter = pose_counter_;
    pose_counter_ = static_cast<std::uint8_t>((pose_counter_ + 1) & 0x0F);
    const bool a = send(v1::encode(ids_, st));
    const bool b = send(v1::encode(ids_, p));
    return a && b;
  }

  // ---- CanLink ----
  void service(std::uint64_t now_us) override {
    if (opt_.protocol == ChassisProtocol::kDockcoreV1) {
      if (charge_requested_ && now_us >= last_charge_us_ + kChargeRepeatUs) {
        send_charge();
        last_charge_us_ = now_us;
      }
      return;
    }
    // AgileX: 0x421 = CAN command mode until 0x211 reports control mode 1.
    if (!agx_can_mode_ && (last_enable_us_ == 0 || now_us >= last_enable_us_ + kAgxEnableRepeatUs)) {
      send(agx::encode(agx::ControlModeFrame{1}));
      last_enable_us_ = now_us == 0 ? 1 : now_us;
    }
  }

  const std::uint32_t* rx_ids(std::size_t& count) const override {
    count = rx_count_;
    return rx_;
  }

  std::uint32_t host_commands_rejected() const override { return rejected_; }

 private:
  bool send(const CanFrame& f) {
    if (bus_.send(f)) {
      ++counters_.frames_sent;
      return true;
    }
    ++counters_.send_failures;
    return false;
  }

  bool send_charge() {
    v1::ChargeRequestFrame c{charge_on_, charge_counter_};
    charge_counter_ = static_cast<std::uint8_t>((charge_counter_ + 1) & 0x0F);
    return send(v1::encode(ids_, c));
  }

  bool in_host_range(std::uint32_t id) const {
    return id >= ids_.host_base && id <= ids_.host_base + v1::kOffDockPose;
  }
  bool in_chassis_range(std::uint32_t id) const {
    return id >= ids_.chassis_base && id <= ids_.chassis_base + v1::kOffChassisStatus;
  }

  void dispatch(const CanFrame& f, std::uint64_t stamp) {
    if (opt_.protocol == ChassisProtocol::kAgilexV2 && !f.extended && agx::frame_name(f.id) != nullptr) {
      dispatch_agilex(f, stamp);
      return;
    }
    const bool ours = !f.extended && (in_host_range(f.id) ||
                                      (opt_.protocol == ChassisProtocol::kDockcoreV1 && in_chassis_range(f.id)));
    if (!ours) return;  // foreign traffic (only seen without a kernel filter): not ours to judge
    v1::MessageKind kind = v1::MessageKind::kUnknown;
    const v1::CanV1Error e = checker_.check(f, kind);
    if (!v1::accepted(e)) {
      ++counters_.bad_frames;
      return;
    }
    const double r = static_cast<double>(opt_.drive.wheel_radius_m);
    switch (kind) {
      case v1::MessageKind::kWheelFbA:
      case v1::MessageKind::kWheelFbB: {
        v1::WheelFeedbackFrame m;
        v1::decode(ids_, f, m);
        const int base = m.rear ? 2 : 0;
        for (int i = 0; i < 2; ++i)
          fb_.wheel_radps[base + i] = static_cast<Real>(m.wheel_mmps[i] * v1::kWheelMpsPerBit / r);
        fb_.wheels_stamp_us = stamp;
        break;
      }
      case v1::MessageKind::kEncoderA:
      case v1::MessageKind::kEncoderB: {
        v1::EncoderFrame m;
        v1::decode(ids_, f, m);
        const int base = m.rear ? 2 : 0;
        for (int i = 0; i < 2; ++i) {
          const int w = base + i;
          if (!enc_seen_[w]) {
            fb_.encoder_counts[w] = m.counts[i];
            enc_seen_[w] = true;
          } else {
            // 24-bit difference, sign-extended, added to the wrapping 32-bit count.
            std::uint32_t d = (static_cast<std::uint32_t>(m.counts[i]) - static_cast<std::uint32_t>(enc_raw_[w])) & 0xFFFFFFu;
            if (d & 0x800000u) d |= 0xFF000000u;
            fb_.encoder_counts[w] = static_cast<std::int32_t>(static_cast<std::uint32_t>(fb_.encoder_counts[w]) + d);
          }
          enc_raw_[w] = m.counts[i];
        }
        fb_.wheels_stamp_us = stamp;
        break;
      }
      case v1::MessageKind::kPower: {
        v1::PowerFrame m;
        v1::decode(ids_, f, m);
        fb_.battery_voltage_v = static_cast<Real>(m.voltage_10mv * v1::kVoltsPerBit);
        fb_.battery_current_a = static_cast<Real>(m.current_10ma * v1::kAmpsPerBit);
        if (m.soc_pct <= 100) fb_.soc = static_cast<Real>(m.soc_pct) / static_cast<Real>(100);
        fb_.charging_contact = m.contact;
        fb_.power_stamp_us = stamp;
        break;
      }
      case v1::MessageKind::kChassisStatus: {
        v1::ChassisStatusFrame m;
        v1::decode(ids_, f, m);
        fb_.estop = m.estop;
        fb_.fault_bits = m.fault_bits;
        fb_.status_stamp_us = stamp;
        break;
      }
      case v1::MessageKind::kHostCommand: {
        v1::HostCommandFrame m;
        v1::decode(ids_, f, m);
        host_command(m, stamp);
        break;
      }
      default:
        break;  // frames this side sends (wheel commands, status) heard from another node: ignored
    }
  }

  void host_command(const v1::HostCommandFrame& m, std::uint64_t stamp) {
    if (have_seq_) {
      const std::uint16_t d = static_cast<std::uint16_t>(m.sequence - last_seq_);
      if (d == 0 || d > 32767) {  // replay (same) or older (out of order)
        ++rejected_;
        return;
      }
    }
    if (q_count_ == kQueue) {
      ++rejected_;
      return;
    }
    have_seq_ = true;
    last_seq_ = m.sequence;
    hal::HostCommandMessage& q = queue_[(q_head_ + q_count_) % kQueue];
    q.command = m.command;
    q.dock_id = m.dock_id;
    q.sequence = m.sequence;
    q.stamp_us = stamp;
    ++q_count_;
  }

  void dispatch_agilex(const CanFrame& f, std::uint64_t stamp) {
    switch (f.id) {
      case agx::kIdMotionState: {
        agx::MotionStateFrame m;
        if (agx::decode(f, m) != agx::AgxError::kOk) break;
        Twist2 t;
        t.vx_mps = static_cast<Real>(m.linear_mmps * agx::kMpsPerBit);
        t.vy_mps = static_cast<Real>(m.lateral_mmps * agx::kMpsPerBit);
        t.wz_radps = static_cast<Real>(m.angular_mradps * agx::kRadpsPerBit);
        const WheelSpeeds w = twist_to_wheels(opt_.drive, t);
        for (std::size_t i = 0; i < 4; ++i) fb_.wheel_radps[i] = i < w.count ? w.radps[i] : static_cast<Real>(0);
        fb_.wheels_stamp_us = stamp;
        return;
      }
      case agx::kIdOdometry: {
        agx::OdometryFrame m;
        if (agx::decode(f, m) != agx::AgxError::kOk) break;
        fb_.encoder_counts[0] = m.left_mm;  // AgileX: odometry in mm stands in for encoder counts
        fb_.encoder_counts[1] = m.right_mm;
        return;
      }
      case agx::kIdSystemState: {
        agx::SystemStateFrame m;
        if (agx::decode(f, m) != agx::AgxError::kOk) break;
        fb_.estop = m.vehicle_state == 1;
        fb_.fault_bits = m.error_code;
        fb_.battery_voltage_v = static_cast<Real>(m.voltage_100mv * agx::kVoltsPerBit);
        fb_.status_stamp_us = stamp;
        agx_can_mode_ = m.control_mode == 1;
        return;
      }
      case agx::kIdBms: {
        agx::BmsFrame m;
        if (agx::decode(f, m) != agx::AgxError::kOk) break;
        fb_.battery_voltage_v = static_cast<Real>(m.voltage_100mv * agx::kVoltsPerBit);
        fb_.battery_current_a = static_cast<Real>(m.current_100ma * agx::kAmpsPerBit);
        if (m.soc_pct <= 100) fb_.soc = static_cast<Real>(m.soc_pct) / static_cast<Real>(100);
        // No contact signal on AgileX: charging current stands in for it.
        fb_.charging_contact = m.current_100ma * agx::kAmpsPerBit > kAgxChargingA;
        fb_.power_stamp_us = stamp;
        return;
      }
      default:
        return;  // frames we send (0x111, 0x421)
    }
    ++counters_.bad_frames;  // an AgileX id with the wrong length or format
  }

  static constexpr double kAgxChargingA = 0.1;

  hal::CanBus& bus_;
  CanLinkOptions opt_;
  v1::Ids ids_;
  v1::FrameChecker checker_;
  hal::ChassisFeedback fb_{};
  hal::ChassisCounters counters_{};
  std::uint32_t rx_[16] = {};
  std::size_t rx_count_ = 0;
  std::uint8_t wheel_counter_ = 0, charge_counter_ = 0, status_counter_ = 0, pose_counter_ = 0;
  bool charge_on_ = false, charge_requested_ = false;
  std::uint64_t last_charge_us_ = 0;
  bool agx_can_mode_ = false;
  std::uint64_t last_enable_us_ = 0;
  bool enc_seen_[4] = {false, false, false, false};
  std::int32_t enc_raw_[4] = {0, 0, 0, 0};
  hal::HostCommandMessage queue_[kQueue];
  std::size_t q_head_ = 0, q_count_ = 0;
  bool have_seq_ = false;
  std::uint16_t last_seq_ = 0;
  std::uint32_t rejected_ = 0;
};

}  // namespace

std::optional<ChassisProtocol> parse_chassis_protocol(std::string_view name) {
  if (name == "dockcore-v1") return ChassisProtocol::kDockcoreV1;
  if (name == "agilex-v2") return ChassisProtocol::kAgilexV2;
  return std::nullopt;
}

bool switches_charger(ChassisProtocol p) {
  return p == ChassisProtocol::kDockcoreV1;
}

const char* to_string(ChassisProtocol p) {
  return p == ChassisProtocol::kAgilexV2 ? "agilex-v2" : "dockcore-v1";
}

std::size_t can_link_rx_ids(const CanLinkOptions& o, std::uint32_t* out, std::size_t capacity) {
  std::uint32_t ids[12];
  std::size_t n = 0;
  const v1::Ids v{o.chassis_base_id, o.host_base_id};
  if (o.protocol == ChassisProtocol::kDockcoreV1) {
    for (v1::MessageKind k : {v1::MessageKind::kWheelFbA, v1::MessageKind::kWheelFbB, v1::MessageKind::kEncoderA,
                              v1::MessageKind::kEncoderB, v1::MessageKind::kPower, v1::MessageKind::kChassisStatus})
      ids[n++] = v1::id_of(v, k);
  } else {
    for (std::uint32_t id : {agx::kIdSystemState, agx::kIdMotionState, agx::kIdOdometry, agx::kIdBms}) ids[n++] = id;
  }
  ids[n++] = v1::id_of(v, v1::MessageKind::kHostCommand);
  const std::size_t m = n < capacity ? n : capacity;
  for (std::size_t i = 0; i < m; ++i) out[i] = ids[i];
  return m;
}

std::unique_ptr<CanLink> make_can_link(hal::CanBus& bus, const CanLinkOptions& options) {
  return std::make_unique<CanLinkImpl>(bus, options);
}

}  // namespace dockcore::drivers
