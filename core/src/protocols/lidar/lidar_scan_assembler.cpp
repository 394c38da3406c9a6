#include "dockcore/protocols/lidar/lidar_scan_assembler.hpp"

#include <cmath>

namespace dockcore {

Real wrap_angle_positive(Real angle_rad) {
  Real a = std::fmod(angle_rad, kTwoPi);
  if (a < 0) a += kTwoPi;
  // fmod of a tiny negative value plus 2 pi can round up to exactly 2 pi.
  if (a >= kTwoPi) a = 0;
  return a;
}

Real LidarAngleConvention::to_sensor(Real core_rad) const {
  const Real d = core_rad - zero_offset_rad;
  return wrap_angle_positive(clockwise ? -d : d);
}

std::uint32_t scan_points_per_turn(const ScanView& scan) {
  const Real inc = std::fabs(scan.angle_increment_rad);
  if (!(inc > 0) || !std::isfinite(inc)) return 1;
  const Real m = std::round(kTwoPi / inc);
  if (!(m >= 1)) return 1;
  if (m > static_cast<Real>(65535)) return 65535;
  return static_cast<std::uint32_t>(m);
}

bool scan_lookup(const ScanView& scan, Real angle_rad, Real* range_m, Real* intensity) {
  const Real inc = scan.angle_increment_rad;
  if (scan.count == 0 || scan.ranges_m == nullptr || !(std::fabs(inc) > 0) || !std::isfinite(angle_rad)) return false;
  // Offset from the first beam measured in the scan's own direction, wrapped to one turn.
  Real d = wrap_angle_positive(inc > 0 ? angle_rad - scan.angle_min_rad : scan.angle_min_rad - angle_rad);
  const Real step = std::fabs(inc);
  Real k = std::round(d / step);
  const Real per_turn = static_cast<Real>(scan_points_per_turn(scan));
  if (k >= per_turn) k -= per_turn;
  if (!(k >= 0) || k >= static_cast<Real>(scan.count)) return false;
  const auto i = static_cast<std::size_t>(k);
  *range_m = scan.ranges_m[i];
  *intensity = scan.intensities != nullptr ? scan.intensities[i] : static_cast<Real>(0);
  return true;
}

bool LidarScanAssembler::configure(std::uint32_t bins_per_turn, Real angle_min_rad) {
  if (bins_per_turn < 1 || bins_per_turn > kMaxScanPoints || !std::isfinite(angle_min_rad)) return false;
  bins_ = bins_per_turn;
  angle_min_rad_ = angle_min_rad;
  increment_rad_ = kTwoPi / static_cast<Real>(bins_per_turn);
  scan_->reset(bins_per_turn, angle_min_rad, increment_rad_, 0);
  samples_ = collisions_ = 0;
  return true;
}

void LidarScanAssembler::begin(std::uint64_t stamp_us) {
  scan_->reset(bins_, angle_min_rad_, increment_rad_, stamp_us);
  samples_ = collisions_ = 0;
}

std::uint32_t LidarScanAssembler::bin_of(Real angle_rad) const {
  const Real a = wrap_angle_positive(angle_rad - angle_min_rad_);
  // Round to the nearest bin centre; the last half bin belongs to bin 0 (full turn).
  auto k = static_cast<std::uint32_t>(a / increment_rad_ + static_cast<Real>(0.5));
  if (k >= bins_) k -= bins_;
  if (k >= bins_) k = bins_ - 1;  // unreachable for finite input; keeps the index provably in range
  return k;
}

bool LidarScanAssembler::add(Real angle_rad, Real range_m, Real intensity) {
  if (bins_ == 0 || !std::isfinite(angle_rad)) return false;
  const std::uint32_t k = bin_of(angle_rad);
  const bool valid = is_valid_range(range_m);
  const Real r = valid ? range_m : static_cast<Real>(0);
  const Real inten = std::isfinite(intensity) ? intensity : static_cast<Real>(0);
  ++samples_;
  // A bin is "filled" once any sample reached it. A no-return sample marks its bin with intensity -0 (equal to 0
  // for every reader, normalised on publish) so a later sample in that bin still counts as a collision without a
  // second array.
  Real& slot_r = scan_->ranges_m[k];
  Real& slot_i = scan_->intensities[k];
  const bool slot_filled = slot_r > 0 || std::signbit(slot_i);
  if (!slot_filled) {
    slot_r = r;
    slot_i = valid ? inten : -static_cast<Real>(0);
    if (valid && inten == 0) slot_i = inten;
    return true;
  }
  ++collisions_;
  if (valid && (slot_r <= 0 || r < slot_r)) {
    slot_r = r;
    slot_i = inten;
  }
  return true;
}

bool LidarScanOutput::configure(std::uint32_t bins_per_turn, Real angle_min_rad) {
  if (!building_.configure(bins_per_turn, angle_min_rad)) return false;
  ready_ = false;
  return true;
}

void LidarScanOutput::publish(LidarParserCounters& c) {
  if (ready_) ++c.scans_overwritten;
  LaserScan& done = scans_[building_index_];
  // -0 sentinels (visited, no return) read as 0 everywhere, but normalise them so printed scans show plain 0.
  for (std::size_t i = 0; i < done.count; ++i)
    if (done.intensities[i] == 0) done.intensities[i] = 0;
  c.bin_collisions += building_.collisions();
  ready_index_ = building_index_;
  building_index_ ^= 1u;
  building_.retarget(&scans_[building_index_]);
  ready_ = true;
  ++c.scans;
}

const LaserScan* LidarScanOutput::take() {
  if (!ready_) return nullptr;
  ready_ = false;
  return &scans_[ready_index_];
}

bool LidarScanOutput::take(LaserScan& out) {
  const LaserScan* s = take();
  if (s == nullptr) return false;
  out = *s;
  return true;
}

}  // namespace dockcore
