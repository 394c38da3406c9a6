#include "dockcore/perception/intensity_check.hpp"

#include <cmath>

namespace dockcore {

namespace {

bool is_return(Real range_m) {
  return std::isfinite(range_m) && range_m > 0;
}

std::uint8_t count_bits(std::uint32_t v) {
  std::uint8_t n = 0;
  for (; v != 0; v &= v - 1) ++n;
  return n;
}

}  // namespace

const char* to_string(IntensityVerdict v) {
  switch (v) {
    case IntensityVerdict::kUnknown:
      return "unknown";
    case IntensityVerdict::kUsable:
      return "usable";
    case IntensityVerdict::kFlat:
      return "flat";
    case IntensityVerdict::kAbsent:
      return "absent";
  }
  return "unknown";
}

void IntensityCheck::configure(const IntensityCheckParams& p) {
  IntensityCheckParams q = p;
  const Real half = static_cast<Real>(0.5);
  if (!(q.flat_share > half)) q.flat_share = half;
  if (q.flat_share > 1) q.flat_share = 1;
  if (!(q.flat_band >= 0)) q.flat_band = 0;
  if (q.min_returns < 1) q.min_returns = 1;
  if (q.window_scans < 1) q.window_scans = 1;
  if (q.window_scans > kMaxWindow) q.window_scans = kMaxWindow;
  if (!(q.decide_share > half)) q.decide_share = half;
  if (q.decide_share > 1) q.decide_share = 1;
  if (q.window_scans != p_.window_scans) {
    flat_bits_ = absent_bits_ = 0;
    filled_ = 0;
  }
  p_ = q;
}

void IntensityCheck::reset() {
  flat_bits_ = absent_bits_ = 0;
  filled_ = 0;
  verdict_ = IntensityVerdict::kUnknown;
  last_ = IntensityScan{};
}

IntensityScan IntensityCheck::add(const ScanView& scan) {
  ++scans_;
  IntensityScan r;
  const std::size_t stride = scan.count > kMaxSamples ? (scan.count + kMaxSamples - 1) / kMaxSamples : 1;
  // A sampled beam's intensity (0 when the scan has none or it is not finite).
  auto intensity_at = [&scan](std::size_t i) {
    return scan.intensities != nullptr && std::isfinite(scan.intensities[i]) ? scan.intensities[i]
                                                                             : static_cast<Real>(0);
  };
  // Majority vote (Boyer-Moore): if one value holds over half the sampled returns, it is the candidate left.
  Real candidate = 0;
  std::size_t votes = 0;
  std::size_t n = 0;
  bool all_zero = true;
  for (std::size_t i = 0; i < scan.count; i += stride) {
    if (!is_return(scan.ranges_m[i])) continue;
    const Real v = intensity_at(i);
    ++n;
    if (v != 0) all_zero = false;
    if (votes == 0) {
      candidate = v;
      votes = 1;
    } else if (v == candidate) {
      ++votes;
    } else {
      --votes;
    }
  }
  r.returns = static_cast<std::uint16_t>(n);
  if (n < p_.min_returns) {
    last_ = r;
    return r;
  }
  std::size_t near = 0;
  for (std::size_t i = 0; i < scan.count; i += stride) {
    if (!is_return(scan.ranges_m[i])) continue;
    const Real v = intensity_at(i);
    if (std::fabs(v - candidate) <= p_.flat_band) ++near;
  }
  r.judged = true;
  r.mode = candidate;
  r.share = static_cast<Real>(near) / static_cast<Real>(n);
  r.absent = all_zero;
  r.flat = all_zero || r.share >= p_.flat_share;
  ++judged_;
  if (r.flat) ++flat_scans_;

  const std::uint32_t mask =
      p_.window_scans >= kMaxWindow ? 0xFFFFFFFFu : (static_cast<std::uint32_t>(1) << p_.window_scans) - 1u;
  flat_bits_ = ((flat_bits_ << 1) | (r.flat ? 1u : 0u)) & mask;
  absent_bits_ = ((absent_bits_ << 1) | (r.absent ? 1u : 0u)) & mask;
  if (filled_ < p_.window_scans) ++filled_;
  if (filled_ == p_.window_scans) {
    // At least decide_share of the window, in whole scans.
    const Real need_real = std::ceil(p_.decide_share * static_cast<Real>(p_.window_scans) - static_cast<Real>(1e-6));
    const std::uint8_t need = static_cast<std::uint8_t>(need_real);
    const std::uint8_t flat = count_bits(flat_bits_);
    IntensityVerdict next = verdict_;
    if (count_bits(absent_bits_) >= need) {
      next = IntensityVerdict::kAbsent;
    } else if (flat >= need) {
      next = IntensityVerdict::kFlat;
    } else if (p_.window_scans - flat >= need) {
      next = IntensityVerdict::kUsable;
    }
    if (next != verdict_) {
      verdict_ = next;
      ++changes_;
    }
  }
  last_ = r;
  return r;
}

}  // namespace dockcore
