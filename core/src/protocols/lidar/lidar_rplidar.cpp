#include "dockcore/protocols/lidar/lidar_rplidar.hpp"

#include <cmath>

namespace dockcore {

namespace {

bool same7(const std::uint8_t* a, const std::uint8_t* b) {
  for (std::size_t i = 0; i < kRplidarDescriptorBytes; ++i)
    if (a[i] != b[i]) return false;
  return true;
}

// A 15-bit angle_q6 can say up to 512 deg; a real node never exceeds 360. Rejecting those tightens framing.
constexpr std::uint16_t kFullTurnQ6 = 360u * 64u;

const std::uint8_t* const kDescriptors[] = {kRplidarScanDescriptor, kRplidarHealthDescriptor, kRplidarInfoDescriptor};

enum class Overlap { kNo, kMaybe, kYes };

// Whether a known descriptor starts at b (avail bytes present): kMaybe while the bytes present match a prefix.
Overlap descriptor_at(const std::uint8_t* b, std::size_t avail) {
  Overlap r = Overlap::kNo;
  for (const std::uint8_t* d : kDescriptors) {
    const std::size_t n = avail < kRplidarDescriptorBytes ? avail : kRplidarDescriptorBytes;
    std::size_t i = 0;
    while (i < n && b[i] == d[i]) ++i;
    if (i < n) continue;
    if (n == kRplidarDescriptorBytes) return Overlap::kYes;
    r = Overlap::kMaybe;
  }
  return r;
}

// b - a wrapped to [-180, 180) deg, in 1/64 deg.
std::int32_t signed_step_q6(std::uint16_t a, std::uint16_t b) {
  std::int32_t d = static_cast<std::int32_t>(b) - static_cast<std::int32_t>(a);
  constexpr std::int32_t kTurn = kFullTurnQ6;
  if (d >= kTurn / 2) d -= kTurn;
  if (d < -kTurn / 2) d += kTurn;
  return d;
}

}  // namespace

std::size_t rplidar_encode_request(std::uint8_t cmd, std::uint8_t out[2]) {
  out[0] = kRplidarSync;
  out[1] = cmd;
  return 2;
}

void rplidar_encode_node(const RplidarNode& n, std::uint8_t out[kRplidarNodeBytes]) {
  const std::uint8_t q = static_cast<std::uint8_t>(n.quality > 63 ? 63 : n.quality);
  out[0] = static_cast<std::uint8_t>((static_cast<unsigned>(q) << 2u) | (n.start ? 0x01u : 0x02u));
  const auto a = static_cast<std::uint16_t>(((n.angle_q6 & 0x7FFFu) << 1) | 0x01u);
  out[1] = static_cast<std::uint8_t>(a & 0xFFu);
  out[2] = static_cast<std::uint8_t>(a >> 8);
  out[3] = static_cast<std::uint8_t>(n.distance_q2 & 0xFFu);
  out[4] = static_cast<std::uint8_t>(n.distance_q2 >> 8);
}

bool rplidar_decode_node(const std::uint8_t in[kRplidarNodeBytes], RplidarNode& out) {
  const bool s = (in[0] & 0x01u) != 0;
  const bool not_s = (in[0] & 0x02u) != 0;
  if (s == not_s || (in[1] & 0x01u) == 0) return false;
  const auto a = static_cast<std::uint16_t>((in[1] | (in[2] << 8)) >> 1);
  if (a >= kFullTurnQ6) return false;
  out.start = s;
  out.quality = static_cast<std::uint8_t>(in[0] >> 2);
  out.angle_q6 = a;
  out.distance_q2 = static_cast<std::uint16_t>(in[3] | (in[4] << 8));
  return true;
}

bool RplidarParser::configure(const RplidarConfig& cfg) {
  if (!out_.configure(cfg.bins_per_turn, cfg.angle_min_rad)) return false;
  cfg_ = cfg;
  len_ = 0;
  synced_ = scanning_ = turn_open_ = have_last_ = false;
  return true;
}

void RplidarParser::reset() {
  counters_.dropped_bytes += static_cast<std::uint32_t>(len_);
  len_ = 0;
  if (turn_open_) counters_.samples_discarded += out_.building().samples();
  synced_ = scanning_ = turn_open_ = have_last_ = false;
}

void RplidarParser::drop_first() {
  ++counters_.dropped_bytes;
  if (!scanning_ && cfg_.require_descriptor) ++counters_.idle_bytes;
  if (synced_) {
    ++counters_.resyncs;
    synced_ = false;
  }
  for (std::size_t i = 1; i < len_ && i < kBufBytes; ++i) {
    buf_[i - 1] = buf_[i];
    stamp_[i - 1] = stamp_[i];
  }
  --len_;
}

void RplidarParser::consume(std::size_t n) {
  counters_.bytes_accepted += n;
  synced_ = true;
  for (std::size_t i = n; i < len_ && i < kBufBytes; ++i) {
    buf_[i - n] = buf_[i];
    stamp_[i - n] = stamp_[i];
  }
  len_ -= n;
}

bool RplidarParser::feed(std::uint8_t byte, std::uint64_t stamp_us) {
  ++counters_.bytes;
  const std::uint32_t before = counters_.scans;
  buf_[len_] = byte;
  stamp_[len_] = stamp_us;
  ++len_;
  process();
  return counters_.scans != before;
}

std::size_t RplidarParser::feed(const std::uint8_t* data, std::size_t n, std::uint64_t stamp_us) {
  std::size_t scans = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (feed(data[i], stamp_us)) ++scans;
  return scans;
}

void RplidarParser::process() {
  while (len_ > 0) {
    if (buf_[0] == kRplidarSync) {
      if (len_ < 2) return;
      if (buf_[1] == kRplidarSync2) {  // never a valid node (0x5A has the check bit clear): a descriptor or noise
        if (len_ < kRplidarDescriptorBytes) return;
        if (same7(buf_, kRplidarScanDescriptor)) {
          ++counters_.descriptors;
          // A new scan session: a turn in progress belongs to the old one.
          if (turn_open_) counters_.samples_discarded += out_.building().samples();
          turn_open_ = have_last_ = false;
          scanning_ = true;
          consume(kRplidarDescriptorBytes);
          continue;
        }
        if (same7(buf_, kRplidarHealthDescriptor)) {
          if (len_ < kRplidarDescriptorBytes + kRplidarHealthBytes) return;
          health_.status = buf_[7];
          health_.error_code = static_cast<std::uint16_t>(buf_[8] | (buf_[9] << 8));
          ++counters_.health_packets;
          consume(kRplidarDescriptorBytes + kRplidarHealthBytes);
          continue;
        }
        if (same7(buf_, kRplidarInfoDescriptor)) {
          if (len_ < kRplidarDescriptorBytes + kRplidarInfoBytes) return;
          ++counters_.info_packets;
          consume(kRplidarDescriptorBytes + kRplidarInfoBytes);
          continue;
        }
        drop_first();
        continue;
      }
    }
    if (scanning_ || !cfg_.require_descriptor) {
      if (len_ < kRplidarNodeBytes) return;
      // A descriptor starting inside the candidate node wins; undecided until its bytes are in.
      Overlap overlap = Overlap::kNo;
      for (std::size_t k = 1; k < kRplidarNodeBytes && overlap != Overlap::kYes; ++k) {
        const Overlap o = descriptor_at(buf_ + k, len_ - k);
        if (o != Overlap::kNo) overlap = o;
      }
      if (overlap == Overlap::kMaybe) return;
      if (overlap == Overlap::kYes) {
        drop_first();
        continue;
      }
      RplidarNode n;
      if (rplidar_decode_node(buf_, n)) {
        const std::uint64_t stamp = stamp_[0];
        consume(kRplidarNodeBytes);
        on_node(n, stamp);
        continue;
      }
    }
    drop_first();
  }
}

void RplidarParser::on_node(const RplidarNode& n, std::uint64_t stamp_us) {
  ++counters_.packets;
  const std::int32_t step = have_last_ ? signed_step_q6(last_q6_, n.angle_q6) : 0;
  const bool in_sequence = have_last_ && step <= kRplidarMaxNodeStepQ6 && -step <= kRplidarMaxNodeStepQ6;
  if (n.start) {
    if (turn_open_ && !(in_sequence && sweep_q6_ >= kRplidarMinTurnSweepQ6)) {
      // Not a turn start: most likely a misaligned node, so neither its angle nor its range is used.
      ++counters_.stray_start;
      return;
    }
    if (turn_open_) out_.publish(counters_);
    out_.building().begin(stamp_us);
    turn_open_ = true;
    sweep_q6_ = 0;
  } else if (in_sequence) {
    sweep_q6_ += step;  // jumps (a misaligned node and the step back from it) are left out
  }
  last_q6_ = n.angle_q6;
  have_last_ = true;
  if (!turn_open_) {
    ++counters_.samples_discarded;
    return;
  }
  const Real deg = static_cast<Real>(n.angle_q6) / static_cast<Real>(64);
  const Real range_m = static_cast<Real>(n.distance_q2) / static_cast<Real>(4000);
  out_.building().add(cfg_.convention.to_core(deg_to_rad(deg)), range_m, static_cast<Real>(n.quality));
  ++counters_.samples;
}

RplidarByteAccount rplidar_byte_account(const LidarParserCounters& c, std::size_t pending_bytes) {
  RplidarByteAccount a;
  a.node_bytes = static_cast<std::uint64_t>(c.packets) * kRplidarNodeBytes;
  a.descriptor_bytes = static_cast<std::uint64_t>(c.descriptors) * kRplidarDescriptorBytes;
  a.response_bytes = static_cast<std::uint64_t>(c.health_packets) * (kRplidarDescriptorBytes + kRplidarHealthBytes) +
                     static_cast<std::uint64_t>(c.info_packets) * (kRplidarDescriptorBytes + kRplidarInfoBytes);
  a.idle_bytes = c.idle_bytes;
  a.resync_bytes = c.dropped_bytes - c.idle_bytes;
  a.pending_bytes = pending_bytes;
  return a;
}

std::size_t RplidarEncoder::write_descriptor(std::uint8_t out[kRplidarDescriptorBytes]) {
  for (std::size_t i = 0; i < kRplidarDescriptorBytes; ++i) out[i] = kRplidarScanDescriptor[i];
  return kRplidarDescriptorBytes;
}

std::size_t RplidarEncoder::write_health(const RplidarHealth& h,
                                         std::uint8_t out[kRplidarDescriptorBytes + kRplidarHealthBytes]) {
  for (std::size_t i = 0; i < kRplidarDescriptorBytes; ++i) out[i] = kRplidarHealthDescriptor[i];
  out[7] = h.status;
  out[8] = static_cast<std::uint8_t>(h.error_code & 0xFFu);
  out[9] = static_cast<std::uint8_t>(h.error_code >> 8);
  return kRplidarDescriptorBytes + kRplidarHealthBytes;
}

std::size_t RplidarEncoder::encode_scan(const ScanView& scan, std::uint8_t* out, std::size_t cap) {
  const std::uint32_t m = scan_points_per_turn(scan);
  std::size_t written = 0;
  for (std::uint32_t j = 0; j < m; ++j) {
    if (cap - written < kRplidarNodeBytes) {
      lost_ += m - j;
      break;
    }
    const auto q6 = static_cast<std::uint16_t>(
        std::round(static_cast<Real>(j) * static_cast<Real>(kFullTurnQ6) / static_cast<Real>(m)));
    Real r = 0;
    Real inten = 0;
    const Real core = conv_.to_core(deg_to_rad(static_cast<Real>(q6) / static_cast<Real>(64)));
    if (!scan_lookup(scan, core, &r, &inten)) r = inten = 0;
    RplidarNode n;
    n.start = j == 0;
    n.angle_q6 = static_cast<std::uint16_t>(q6 % kFullTurnQ6);
    if (is_valid_range(r)) {
      const Real v = std::round(r * static_cast<Real>(4000));
      n.distance_q2 = v >= static_cast<Real>(65536) ? 0 : static_cast<std::uint16_t>(v);
    }
    Real q = std::isfinite(inten) ? std::round(inten) : static_cast<Real>(0);
    n.quality = static_cast<std::uint8_t>(q < 0 ? 0 : (q > 63 ? 63 : q));
    rplidar_encode_node(n, out + written);
    written += kRplidarNodeBytes;
  }
  return written;
}

}  // namespace dockcore
