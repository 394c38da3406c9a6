#include "dockcore/task/input_watch.hpp"

namespace dockcore {

void InputWatch::reset() {
  const WatchdogParams p = p_;
  const std::uint32_t late = late_scans_;
  const std::uint32_t lidar = lidar_trips_;
  const std::uint32_t chassis = chassis_trips_;
  *this = InputWatch{};
  p_ = p;
  late_scans_ = late;
  lidar_trips_ = lidar;
  chassis_trips_ = chassis;
}

bool InputWatch::on_scan(std::uint64_t stamp_us, std::uint64_t now_us) {
  const std::uint64_t stale_us = static_cast<std::uint64_t>(p_.lidar_stale_ms) * 1000u;
  // Stamps further apart than this are a gap, not the period.
  const std::uint64_t max_period_us = stale_us > 500000u ? stale_us : 500000u;
  if (prev_stamp_us_ != 0 && stamp_us > prev_stamp_us_ && stamp_us - prev_stamp_us_ <= max_period_us) {
    period_us_ = stamp_us - prev_stamp_us_;
  }
  prev_stamp_us_ = stamp_us;
  const std::uint64_t turn_end = now_us < stamp_us + period_us_ ? now_us : stamp_us + period_us_;
  if (now_us - turn_end > stale_us) {
    ++late_scans_;
    return false;
  }
  have_scan_ = true;
  scan_read_us_ = now_us;
  // Until the period is known the read time stands for the turn's end: it cannot have ended later. (Its stamp, the
  // turn's start, would make a first scan look one turn old and trip the watchdog before the second arrives.)
  const std::uint64_t end = period_us_ != 0 ? turn_end : now_us;
  if (end > turn_end_us_) turn_end_us_ = end;
  return true;
}

InputWatch::Change InputWatch::update(std::uint64_t now_us, bool chassis_valid, std::uint64_t chassis_stamp_us) {
  const std::uint64_t lidar_lim = static_cast<std::uint64_t>(p_.lidar_stale_ms) * 1000u;
  const std::uint64_t chassis_lim = static_cast<std::uint64_t>(p_.chassis_stale_ms) * 1000u;
  const bool lidar = !have_scan_ || now_us - turn_end_us_ > lidar_lim;
  const bool chassis = !chassis_valid || (now_us > chassis_stamp_us && now_us - chassis_stamp_us > chassis_lim);
  Change c;
  c.lidar = lidar != lidar_stale_;
  c.chassis = chassis != chassis_stale_;
  if (lidar && !lidar_stale_) {
    lidar_since_us_ = now_us;
    ++lidar_trips_;
  }
  if (chassis && !chassis_stale_) {
    chassis_since_us_ = now_us;
    ++chassis_trips_;
  }
  lidar_stale_ = lidar;
  chassis_stale_ = chassis;
  if (lidar || chassis) fresh_since_us_ = now_us;
  return c;
}

}  // namespace dockcore
