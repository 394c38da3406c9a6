#include "dockcore/protocols/lidar/lidar_lakibeam.hpp"

#include <cmath>

namespace dockcore {

namespace {
constexpr std::size_t kTrailer = kLakibeamBlocks * kLakibeamBlockBytes;  // timestamp at 1200, 0x40 0x37 at 1204
}  // namespace

bool LakibeamParser::configure(const LakibeamConfig& cfg) {
  if (!out_.configure(cfg.bins_per_turn, cfg.angle_min_rad)) return false;
  cfg_ = cfg;
  have_prev_ = turn_open_ = turn_from_wrap_ = false;
  return true;
}

void LakibeamParser::reset() {
  if (turn_open_) counters_.samples_discarded += out_.building().samples();
  have_prev_ = turn_open_ = turn_from_wrap_ = false;
}

std::size_t LakibeamParser::feed_datagram(const std::uint8_t* data, std::size_t n, std::uint64_t stamp_us) {
  counters_.bytes += n;
  bool ok = data != nullptr && n == kLakibeamDatagramBytes;
  if (ok) ok = data[kTrailer + 4] == 0x40 && data[kTrailer + 5] == 0x37;
  for (std::size_t b = 0; ok && b < kLakibeamBlocks; ++b) {
    const std::uint8_t* blk = data + b * kLakibeamBlockBytes;
    ok = blk[0] == 0xFF && blk[1] == 0xEE && read_le16(blk + 2) < 36000u;
  }
  if (!ok) {
    ++counters_.bad_packets;
    counters_.dropped_bytes += static_cast<std::uint32_t>(n);
    return 0;
  }
  counters_.bytes_accepted += n;
  ++counters_.packets;
  last_timestamp_ = static_cast<std::uint32_t>(data[kTrailer]) | (static_cast<std::uint32_t>(data[kTrailer + 1]) << 8) |
                    (static_cast<std::uint32_t>(data[kTrailer + 2]) << 16) |
                    (static_cast<std::uint32_t>(data[kTrailer + 3]) << 24);
  const std::uint32_t scans_before = counters_.scans;
  std::uint32_t step16 = 0;  // azimuth step over one block, 0.01 deg
  for (std::size_t b = 0; b < kLakibeamBlocks; ++b) {
    const std::uint8_t* blk = data + b * kLakibeamBlockBytes;
    const std::uint32_t az = read_le16(blk + 2);
    if (b + 1 < kLakibeamBlocks) step16 = (read_le16(blk + kLakibeamBlockBytes + 2) + 36000u - az) % 36000u;
    for (std::size_t k = 0; k < kLakibeamPointsPerBlock; ++k) {
      const std::uint8_t* pt = blk + 4 + 6 * k;
      Real cdeg = static_cast<Real>(az) + static_cast<Real>(step16) * static_cast<Real>(k) /
                                              static_cast<Real>(kLakibeamPointsPerBlock);
      if (cdeg >= static_cast<Real>(36000)) cdeg -= static_cast<Real>(36000);
      add_point(cdeg / static_cast<Real>(100), static_cast<Real>(read_le16(pt)) / static_cast<Real>(1000),
                static_cast<Real>(pt[2]), stamp_us);
    }
  }
  return counters_.scans - scans_before;
}

void LakibeamParser::add_point(Real sensor_deg, Real range_m, Real intensity, std::uint64_t stamp_us) {
  if (have_prev_ && sensor_deg < prev_deg_ - static_cast<Real>(180)) {
    if (turn_open_) {
      if (turn_from_wrap_ || turn_first_deg_ <= cfg_.first_turn_max_start_deg) {
        out_.publish(counters_);
      } else {
        counters_.samples_discarded += out_.building().samples();
      }
      turn_open_ = false;
    }
    turn_from_wrap_ = true;
  }
  if (!turn_open_) {
    out_.building().begin(stamp_us);
    turn_open_ = true;
    turn_first_deg_ = sensor_deg;
  }
  have_prev_ = true;
  prev_deg_ = sensor_deg;
  out_.building().add(cfg_.convention.to_core(deg_to_rad(sensor_deg)), range_m, intensity);
  ++counters_.samples;
}

std::size_t LakibeamEncoder::encode_scan(const ScanView& scan, std::uint32_t timestamp,
                                         void (*emit)(const std::uint8_t*, std::size_t, void*), void* user) {
  const std::uint32_t m = scan_points_per_turn(scan);
  std::size_t emitted = 0;
  for (std::uint32_t j = 0; j < m; ++j) {
    const auto cdeg = static_cast<std::uint32_t>(
        std::round(static_cast<Real>(j) * static_cast<Real>(36000) / static_cast<Real>(m))) % 36000u;
    Real r = 0;
    Real inten = 0;
    const Real core = conv_.to_core(deg_to_rad(static_cast<Real>(cdeg) / static_cast<Real>(100)));
    if (!scan_lookup(scan, core, &r, &inten)) r = inten = 0;
    std::uint16_t mm = 0;
    if (is_valid_range(r)) {
      const Real v = std::round(r * static_cast<Real>(1000));
      mm = v > static_cast<Real>(65535) ? 0 : static_cast<std::uint16_t>(v);
    }
    Real iv = std::isfinite(inten) ? std::round(inten) : static_cast<Real>(0);
    const auto rssi = static_cast<std::uint8_t>(iv < 0 ? 0 : (iv > 255 ? 255 : iv));
    const std::size_t b = pending_ / kLakibeamPointsPerBlock;
    const std::size_t k = pending_ % kLakibeamPointsPerBlock;
    std::uint8_t* blk = dgram_ + b * kLakibeamBlockBytes;
    if (k == 0) {
      blk[0] = 0xFF;
      blk[1] = 0xEE;
      write_le16(blk + 2, static_cast<std::uint16_t>(cdeg));
    }
    std::uint8_t* pt = blk + 4 + 6 * k;
    write_le16(pt, mm);
    pt[2] = rssi;
    write_le16(pt + 3, mm);
    pt[5] = rssi;
    if (++pending_ < kLakibeamPointsPerDatagram) continue;
    pending_ = 0;
    dgram_[kTrailer] = static_cast<std::uint8_t>(timestamp & 0xFFu);
    dgram_[kTrailer + 1] = static_cast<std::uint8_t>((timestamp >> 8) & 0xFFu);
    dgram_[kTrailer + 2] = static_cast<std::uint8_t>((timestamp >> 16) & 0xFFu);
    dgram_[kTrailer + 3] = static_cast<std::uint8_t>(timestamp >> 24);
    dgram_[kTrailer + 4] = 0x40;
    dgram_[kTrailer + 5] = 0x37;
    if (emit != nullptr) emit(dgram_, kLakibeamDatagramBytes, user);
    ++emitted;
  }
  return emitted;
}

}  // namespace dockcore
