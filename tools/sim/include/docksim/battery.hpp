#pragma once
// Battery model for the simulated chassis: coulomb counting, open-circuit voltage from a SOC table and an internal
// resistance. Host-side (tools/), header-only, no allocation; deterministic.
#include <algorithm>
#include <array>
#include <cstddef>

namespace docksim {

/// Points in the open-circuit-voltage table: SOC 0, 0.1, ..., 1.0.
constexpr std::size_t kOcvTablePoints = 11;

/// Battery parameters. Defaults: a 7S Li-ion (NMC) pack, "24 V class", 20 Ah.
struct BatteryParams {
  double capacity_ah = 20.0;               ///< Usable capacity, ampere-hours (> 0).
  double initial_soc = 0.5;                ///< State of charge at construction, 0..1.
  double internal_resistance_ohm = 0.08;   ///< Series resistance: terminal V = OCV + I·R (I > 0 charging).
  /// Open-circuit voltage in volts at SOC = 0, 0.1, ..., 1.0 (piecewise linear between points; must not decrease).
  /// Default: a typical NMC cell curve (3.00 … 4.20 V per cell) times 7 cells.
  std::array<double, kOcvTablePoints> ocv_v = {21.00, 24.15, 25.06, 25.55, 25.90, 26.25,
                                               26.60, 27.09, 27.65, 28.35, 29.40};
};

/// Open-circuit voltage for `soc` (clamped to 0..1) by linear interpolation in `p.ocv_v`. O(1).
inline double battery_ocv_v(const BatteryParams& p, double soc) {
  const double s = std::clamp(soc, 0.0, 1.0) * static_cast<double>(kOcvTablePoints - 1);
  const std::size_t i = std::min(static_cast<std::size_t>(s), kOcvTablePoints - 2);
  const double f = s - static_cast<double>(i);
  return p.ocv_v[i] + f * (p.ocv_v[i + 1] - p.ocv_v[i]);
}

/// Coulomb-counting battery. Sign convention everywhere: current > 0 charges, < 0 discharges.
class Battery {
 public:
  explicit Battery(const BatteryParams& p = BatteryParams{}) : p_(p), soc_(std::clamp(p.initial_soc, 0.0, 1.0)) {}

  /// Advances by dt_s seconds with a constant terminal current current_a (A, + charging). SOC saturates at 0 and 1
  /// (a full pack accepts no more charge; an empty one still reports its current so the caller sees the draw). O(1).
  void step(double current_a, double dt_s) {
    current_a_ = current_a;
    soc_ = std::clamp(soc_ + current_a * dt_s / (3600.0 * p_.capacity_ah), 0.0, 1.0);
  }
  /// Forces the state of charge (clamped to 0..1), e.g. to script a low battery. O(1).
  void set_soc(double soc) { soc_ = std::clamp(soc, 0.0, 1.0); }

  double soc() const { return soc_; }                 ///< State of charge, 0..1.
  double current_a() const { return current_a_; }     ///< Last terminal current, A (+ charging).
  double ocv_v() const { return battery_ocv_v(p_, soc_); }  ///< Open-circuit voltage, V.
  /// Terminal voltage, V: OCV plus the drop across the internal resistance (rises while charging).
  double voltage_v() const { return ocv_v() + current_a_ * p_.internal_resistance_ohm; }
  const BatteryParams& params() const { return p_; }

 private:
  BatteryParams p_;
  double soc_ = 0.5;
  double current_a_ = 0.0;
};

}  // namespace docksim
