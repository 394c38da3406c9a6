#include "dockcore/protocols/lidar/lidar_ld06.hpp"

#include <cmath>

namespace dockcore {

namespace {

// Length of a packet of this kind, 0 for an unknown kind.
std::size_t ld06_length(std::uint8_t kind) {
  switch (kind) {
    case kLd06DataKind: return kLd06PacketBytes;
    case kLd06HealthKind: return kLd06HealthBytes;
    case kLd06InfoKind: return kLd06InfoBytes;
    default: return 0;
  }
}

}  // namespace

namespace {
// 256-byte table built at compile time from the polynomial (no copied vendor table): one lookup per byte instead of
// 8 shift steps, which made the CRC two thirds of the parser's cost.
struct CrcTable {
  std::uint8_t v[256] = {};
  constexpr CrcTable() {
    for (unsigned i = 0; i < 256; ++i) {
      unsigned crc = i;
      for (int b = 0; b < 8; ++b) crc = (crc & 0x80u) != 0 ? ((crc << 1) ^ 0x4Du) & 0xFFu : (crc << 1) & 0xFFu;
      v[i] = static_cast<std::uint8_t>(crc);
    }
  }
};
constexpr CrcTable kCrcTable{};

void decode_fields(const std::uint8_t* in, Ld06Packet& out) {
  out.speed_dps = read_le16(in + 2);
  out.start_cdeg = read_le16(in + 4);
  for (std::size_t i = 0; i < kLd06PointsPerPacket; ++i) {
    out.distance_mm[i] = read_le16(in + 6 + 3 * i);
    out.intensity[i] = in[8 + 3 * i];
  }
  out.end_cdeg = read_le16(in + 42);
  out.timestamp_ms = read_le16(in + 44);
}
}  // namespace

std::uint8_t ld06_crc8(const std::uint8_t* data, std::size_t n) {
  std::uint8_t crc = 0;
  for (std::size_t i = 0; i < n; ++i) crc = kCrcTable.v[crc ^ data[i]];
  return crc;
}

void ld06_encode_packet(const Ld06Packet& p, std::uint8_t out[kLd06PacketBytes]) {
  out[0] = kLd06Header;
  out[1] = kLd06DataKind;
  write_le16(out + 2, p.speed_dps);
  write_le16(out + 4, p.start_cdeg);
  for (std::size_t i = 0; i < kLd06PointsPerPacket; ++i) {
    write_le16(out + 6 + 3 * i, p.distance_mm[i]);
    out[8 + 3 * i] = p.intensity[i];
  }
  write_le16(out + 42, p.end_cdeg);
  write_le16(out + 44, p.timestamp_ms);
  out[46] = ld06_crc8(out, 46);
}

bool ld06_decode_packet(const std::uint8_t in[kLd06PacketBytes], Ld06Packet& out) {
  if (in[0] != kLd06Header || in[1] != kLd06DataKind || ld06_crc8(in, 46) != in[46]) return false;
  decode_fields(in, out);
  return true;
}

Real ld06_point_angle_cdeg(std::uint16_t start_cdeg, std::uint16_t end_cdeg, std::size_t i) {
  const std::uint32_t span = (static_cast<std::uint32_t>(end_cdeg) + 36000u - start_cdeg % 36000u) % 36000u;
  Real a = static_cast<Real>(start_cdeg % 36000u) +
           static_cast<Real>(span) * static_cast<Real>(i) / static_cast<Real>(kLd06PointsPerPacket - 1);
  if (a >= static_cast<Real>(36000)) a -= static_cast<Real>(36000);
  return a;
}

bool Ld06Parser::configure(const Ld06Config& cfg) {
  if (!(cfg.point_rate_hz > 0) || !std::isfinite(cfg.point_rate_hz)) return false;
  if (!out_.configure(cfg.bins_per_turn, cfg.angle_min_rad)) return false;
  cfg_ = cfg;
  len_ = 0;
  synced_ = have_prev_ = turn_open_ = turn_from_wrap_ = clock_valid_ = clock_frozen_ = false;
  still_steps_ = 0;
  return true;
}

void Ld06Parser::reset() {
  counters_.dropped_bytes += static_cast<std::uint32_t>(len_);
  len_ = 0;
  synced_ = false;
  if (turn_open_) counters_.samples_discarded += out_.building().samples();
  have_prev_ = turn_open_ = turn_from_wrap_ = clock_valid_ = clock_frozen_ = false;  // the sensor may have restarted
  still_steps_ = 0;
}

std::uint64_t Ld06Parser::map_sensor_clock(std::uint16_t ts_ms, std::uint64_t arrival_us) {
  if (!cfg_.sensor_clock || clock_frozen_) return arrival_us;
  const std::uint32_t ts = ts_ms % kLd06TimestampWrapMs;
  // Packets are 2-3 ms apart, so the ms timestamp steps on (nearly) every one; a sensor (or clone) whose stamp does
  // not move would pin every turn to the first one's time and look stale forever: fall back to arrival stamps.
  if (clock_valid_ && ts == prev_ts_ms_) {
    if (++still_steps_ >= kFrozenClockPackets) {
      clock_frozen_ = true;
      ++counters_.clock_resyncs;
      return arrival_us;
    }
  } else {
    still_steps_ = 0;
  }
  if (clock_valid_) {
    // Unwrap: the step is taken forward modulo the wrap, so a timestamp going back reads as a ~30 s step.
    const std::uint32_t step_ms = (ts + kLd06TimestampWrapMs - prev_ts_ms_) % kLd06TimestampWrapMs;
    if (step_ms > cfg_.sensor_clock_max_step_ms) {
      clock_valid_ = false;
      ++counters_.clock_resyncs;
    } else {
      const std::uint64_t step_us = static_cast<std::uint64_t>(step_ms) * 1000u;
      sensor_us_ += step_us;
      const std::int64_t off = static_cast<std::int64_t>(arrival_us) - static_cast<std::int64_t>(sensor_us_);
      const auto creep = static_cast<std::int64_t>(step_us * cfg_.sensor_clock_drift_ppm / 1000000u);
      offset_us_ = off < offset_us_ + creep ? off : offset_us_ + creep;
    }
  }
  prev_ts_ms_ = static_cast<std::uint16_t>(ts);
  if (!clock_valid_) {
    clock_valid_ = true;
    lagging_ = false;
    sensor_us_ = arrival_us;
    offset_us_ = 0;
  }
  const std::int64_t host_signed = static_cast<std::int64_t>(sensor_us_) + offset_us_;
  const std::uint64_t host = host_signed > 0 ? static_cast<std::uint64_t>(host_signed) : 0;
  // A backlog drains: its lag is transient. A lag that persists for sensor_clock_relock_ms of host time means the
  // sensor clock paused or slowed (a restarted or stalled sensor that kept its count): restart from arrival.
  if (arrival_us > host + static_cast<std::uint64_t>(cfg_.sensor_clock_lag_ms) * 1000u) {
    if (!lagging_) {
      lagging_ = true;
      lag_since_us_ = arrival_us;
    } else if (arrival_us - lag_since_us_ > static_cast<std::uint64_t>(cfg_.sensor_clock_relock_ms) * 1000u) {
      lagging_ = false;
      sensor_us_ = arrival_us;
      offset_us_ = 0;
      ++counters_.clock_resyncs;
      return arrival_us;
    }
  } else {
    lagging_ = false;
  }
  return host;
}

void Ld06Parser::drop_first() {
  ++counters_.dropped_bytes;
  if (synced_) {
    ++counters_.resyncs;
    synced_ = false;
  }
  for (std::size_t i = 1; i < len_ && i < kLd06PacketBytes; ++i) {
    buf_[i - 1] = buf_[i];
    stamp_[i - 1] = stamp_[i];
  }
  --len_;
}

void Ld06Parser::consume(std::size_t n) {
  counters_.bytes_accepted += n;
  synced_ = true;
  for (std::size_t i = n; i < len_ && i < kLd06PacketBytes; ++i) {
    buf_[i - n] = buf_[i];
    stamp_[i - n] = stamp_[i];
  }
  len_ -= n;
}

bool Ld06Parser::feed(std::uint8_t byte, std::uint64_t stamp_us) {
  ++counters_.bytes;
  const std::uint32_t scans_before = counters_.scans;
  buf_[len_] = byte;
  stamp_[len_] = stamp_us;
  ++len_;
  process();
  return counters_.scans != scans_before;
}

std::size_t Ld06Parser::feed(const std::uint8_t* data, std::size_t n, std::uint64_t stamp_us) {
  std::size_t scans = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (feed(data[i], stamp_us)) ++scans;
  return scans;
}

void Ld06Parser::process() {
  while (len_ > 0) {
    if (buf_[0] != kLd06Header) {
      drop_first();
      continue;
    }
    if (len_ < 2) return;
    const std::size_t need = ld06_length(buf_[1]);
    if (need == 0) {
      drop_first();
      continue;
    }
    if (len_ < need) return;
    if (ld06_crc8(buf_, need - 1) != buf_[need - 1]) {
      ++counters_.crc_errors;
      drop_first();  // rescan the other need-1 bytes: a good packet may start inside them
      continue;
    }
    if (buf_[1] == kLd06DataKind) {
      Ld06Packet p;
      decode_fields(buf_, p);  // CRC already checked above
      const std::uint64_t stamp = stamp_[0];
      consume(need);
      on_data_packet(p, stamp);
    } else {
      if (buf_[1] == kLd06HealthKind) {
        ++counters_.health_packets;
        health_error_ = buf_[2];
      } else {
        ++counters_.info_packets;
      }
      consume(need);
    }
  }
}

void Ld06Parser::on_data_packet(const Ld06Packet& p, std::uint64_t stamp_us) {
  if (p.start_cdeg >= 36000u || p.end_cdeg >= 36000u) {
    ++counters_.bad_span;
    return;
  }
  const std::uint32_t span = (static_cast<std::uint32_t>(p.end_cdeg) + 36000u - p.start_cdeg) % 36000u;
  if (cfg_.span_tolerance > 0) {
    // speed (deg/s) * 12 points / point rate (1/s) = degrees one packet should cover; x100 for 0.01 deg.
    const Real expected_cdeg = static_cast<Real>(p.speed_dps) * static_cast<Real>(kLd06PointsPerPacket) /
                               cfg_.point_rate_hz * static_cast<Real>(100);
    if (static_cast<Real>(span) > cfg_.span_tolerance * expected_cdeg) {
      ++counters_.bad_span;
      return;
    }
  }
  ++counters_.packets;
  last_ = p;
  stamp_us = map_sensor_clock(p.timestamp_ms, stamp_us);
  const Real period_us = static_cast<Real>(1e6) / cfg_.point_rate_hz;
  for (std::size_t i = 0; i < kLd06PointsPerPacket; ++i) {
    const Real deg = ld06_point_angle_cdeg(p.start_cdeg, p.end_cdeg, i) / static_cast<Real>(100);
    // The packet leaves after its 12 points were measured: point i is (12 - i) point periods older than its first
    // byte's arrival.
    const auto back = static_cast<std::uint64_t>(static_cast<Real>(kLd06PointsPerPacket - i) * period_us);
    const std::uint64_t t = stamp_us > back ? stamp_us - back : 0;
    add_point(deg, static_cast<Real>(p.distance_mm[i]) / static_cast<Real>(1000), static_cast<Real>(p.intensity[i]), t);
  }
}

void Ld06Parser::add_point(Real sensor_deg, Real range_m, Real intensity, std::uint64_t stamp_us) {
  if (have_prev_ && sensor_deg < prev_deg_ - static_cast<Real>(180)) {
    end_turn();
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

void Ld06Parser::end_turn() {
  if (!turn_open_) return;
  turn_open_ = false;
  if (turn_from_wrap_ || turn_first_deg_ <= cfg_.first_turn_max_start_deg) {
    out_.publish(counters_);
  } else {
    counters_.samples_discarded += out_.building().samples();
  }
}

void Ld06StreamEncoder::configure(const LidarAngleConvention& convention, std::uint16_t speed_dps) {
  conv_ = convention;
  speed_dps_ = speed_dps;
  pending_ = 0;
}

std::size_t Ld06StreamEncoder::encode_scan(const ScanView& scan, std::uint16_t timestamp_ms, std::uint8_t* out,
                                            std::size_t cap) {
  const std::uint32_t m = scan_points_per_turn(scan);
  std::size_t written = 0;
  for (std::uint32_t j = 0; j < m; ++j) {
    const auto cdeg = static_cast<std::uint32_t>(
        std::round(static_cast<Real>(j) * static_cast<Real>(36000) / static_cast<Real>(m)));
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
    if (iv < 0) iv = 0;
    if (iv > static_cast<Real>(255)) iv = 255;
    pend_angle_[pending_] = static_cast<std::uint16_t>(cdeg % 36000u);
    pend_dist_[pending_] = mm;
    pend_int_[pending_] = static_cast<std::uint8_t>(iv);
    if (++pending_ < kLd06PointsPerPacket) continue;
    pending_ = 0;
    if (cap - written < kLd06PacketBytes) {
      lost_ += static_cast<std::uint32_t>(kLd06PointsPerPacket);
      continue;
    }
    Ld06Packet p;
    p.speed_dps = speed_dps_;
    p.start_cdeg = pend_angle_[0];
    p.end_cdeg = pend_angle_[kLd06PointsPerPacket - 1];
    // The packet leaves when its last point (j) was measured: j + 1 point periods after the scan's first point.
    const std::uint64_t after_ms = speed_dps_ > 0 ? (static_cast<std::uint64_t>(j) + 1u) * 360000u /
                                                        (static_cast<std::uint64_t>(speed_dps_) * m)
                                                  : 0;
    p.timestamp_ms = static_cast<std::uint16_t>((timestamp_ms + after_ms) % kLd06TimestampWrapMs);
    for (std::size_t i = 0; i < kLd06PointsPerPacket; ++i) {
      p.distance_mm[i] = pend_dist_[i];
      p.intensity[i] = pend_int_[i];
    }
    ld06_encode_packet(p, out + written);
    written += kLd06PacketBytes;
  }
  return written;
}

}  // namespace dockcore
