// core intensity check: which scans are flat or absent, the window's vote and its hysteresis, sampling of long scans,
// and how Dockcore carries the verdict across configurations.
#include <cmath>
#include <cstdint>
#include <memory>

#include "dockcore/control/controllers.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "dockcore/perception/intensity_check.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;

namespace {

/// A 360-beam scan, every beam a return at 1.5 m, whose intensities come from `value(i)`.
template <typename F>
LaserScan make_scan(F value, std::size_t n = 360) {
  LaserScan s;
  s.reset(n, -kPi, 2 * kPi / static_cast<Real>(n), 0);
  for (std::size_t i = 0; i < n; ++i) {
    s.ranges_m[i] = static_cast<Real>(1.5);
    s.intensities[i] = static_cast<Real>(value(i));
  }
  return s;
}

/// Intensities spread as a diffuse room gives them on an LD06: 60..250, no value twice in a row.
LaserScan varied_scan(std::uint32_t seed) {
  return make_scan([seed](std::size_t i) { return 60 + (static_cast<std::uint32_t>(i) * 37u + seed * 11u) % 191u; });
}

/// A real RPLIDAR A1's standard-scan quality: 15 on nearly every return, a few lower (grazing, far).
LaserScan a1_scan() {
  return make_scan([](std::size_t i) { return i % 10 == 4 ? 9 : 15; });
}

void feed(IntensityCheck& c, const LaserScan& s, int n) {
  for (int i = 0; i < n; ++i) c.add(s.view());
}

}  // namespace

TEST_GROUP(IntensityCheck){};

TEST(IntensityCheck, VariedIntensitiesAreUsableOnceTheWindowIsFull) {
  IntensityCheck c;
  for (int i = 0; i < 15; ++i) {
    const IntensityScan r = c.add(varied_scan(static_cast<std::uint32_t>(i)).view());
    CHECK(r.judged);
    CHECK(!r.flat);
    CHECK(r.share < 0.1);
    CHECK(IntensityVerdict::kUnknown == c.verdict());  // 16 judged scans are needed
  }
  c.add(varied_scan(99).view());
  CHECK(IntensityVerdict::kUsable == c.verdict());
  CHECK(c.usable());
  STRCMP_EQUAL("usable", to_string(c.verdict()));
  CHECK_EQUAL(16u, c.scans_judged());
  CHECK_EQUAL(0u, c.scans_flat());
}

TEST(IntensityCheck, ASaturatedQualityIsFlat) {
  IntensityCheck c;
  const IntensityScan r = c.add(a1_scan().view());
  CHECK(r.judged);
  CHECK(r.flat);
  CHECK(!r.absent);
  DOUBLES_EQUAL(15.0, static_cast<double>(r.mode), 0.0);
  // 360 beams are sampled at a stride of 2: every fifth sampled return reads 9, 6 away from 15 (outside ±flat_band).
  DOUBLES_EQUAL(0.8, static_cast<double>(r.share), 1e-6);
  feed(c, a1_scan(), 15);
  CHECK(IntensityVerdict::kFlat == c.verdict());
  CHECK(!c.usable());
}

TEST(IntensityCheck, AConstantAndANoisyConstantAreFlat) {
  IntensityCheck c;
  feed(c, make_scan([](std::size_t) { return 47; }), 16);  // RPLIDAR express / dense modes
  CHECK(IntensityVerdict::kFlat == c.verdict());
  IntensityCheck d;
  // No value holds a majority, but every return lies within ±1 of both.
  const IntensityScan r = d.add(make_scan([](std::size_t i) { return i % 2 == 0 ? 14 : 15; }).view());
  CHECK(r.flat);
  DOUBLES_EQUAL(1.0, static_cast<double>(r.share), 1e-6);
}

TEST(IntensityCheck, ZerosOrNoIntensitiesAreAbsent) {
  IntensityCheck c;
  feed(c, make_scan([](std::size_t) { return 0; }), 16);
  CHECK(IntensityVerdict::kAbsent == c.verdict());
  STRCMP_EQUAL("absent", to_string(c.verdict()));
  IntensityCheck d;
  LaserScan s = varied_scan(1);
  ScanView v = s.view();
  v.intensities = nullptr;
  for (int i = 0; i < 16; ++i) CHECK(d.add(v).absent);
  CHECK(IntensityVerdict::kAbsent == d.verdict());
}

TEST(IntensityCheck, NoReturnsAreNotCountedAndTooFewScansAreNotJudged) {
  IntensityCheck c;
  // Varied intensities on beams with no return must not make a flat scan usable.
  LaserScan s = make_scan([](std::size_t i) { return i % 2 == 0 ? 15 : 100 + i % 100; });
  for (std::size_t i = 1; i < s.count; i += 2) s.ranges_m[i] = i % 4 == 1 ? 0 : std::nan("");
  IntensityScan r = c.add(s.view());
  CHECK(r.flat);
  CHECK_EQUAL(180u, static_cast<unsigned>(r.returns));
  // 19 returns: below min_returns (20), not judged, no vote.
  LaserScan few = varied_scan(3);
  for (std::size_t i = 19; i < few.count; ++i) few.ranges_m[i] = 0;
  r = c.add(few.view());
  CHECK(!r.judged);
  CHECK_EQUAL(2u, c.scans());
  CHECK_EQUAL(1u, c.scans_judged());
}

TEST(IntensityCheck, TheVerdictChangesOnlyWhenThreeQuartersOfTheWindowAgree) {
  IntensityCheck c;
  feed(c, varied_scan(1), 16);
  CHECK(IntensityVerdict::kUsable == c.verdict());
  // 11 flat scans of 16: below 12, still usable; the 12th turns it.
  feed(c, a1_scan(), 11);
  CHECK(IntensityVerdict::kUsable == c.verdict());
  feed(c, a1_scan(), 1);
  CHECK(IntensityVerdict::kFlat == c.verdict());
  // Back: 12 varied scans of 16 are needed.
  feed(c, varied_scan(2), 11);
  CHECK(IntensityVerdict::kFlat == c.verdict());
  feed(c, varied_scan(3), 1);
  CHECK(IntensityVerdict::kUsable == c.verdict());
  CHECK_EQUAL(3u, c.verdict_changes());
  // Alternating scans never reach three quarters: the verdict stays.
  for (int i = 0; i < 40; ++i) c.add(i % 2 == 0 ? a1_scan().view() : varied_scan(4).view());
  CHECK(IntensityVerdict::kUsable == c.verdict());
  CHECK_EQUAL(3u, c.verdict_changes());
}

TEST(IntensityCheck, LongScansAreSampled) {
  IntensityCheck c;
  // 4096 beams: at most kMaxSamples are read, at an even stride (16), so the share is that of the whole scan.
  const LaserScan s = make_scan([](std::size_t i) { return i % 5 == 0 ? 200 : 15; }, kMaxScanPoints);
  const IntensityScan r = c.add(s.view());
  CHECK(r.returns <= IntensityCheck::kMaxSamples);
  CHECK(r.returns >= IntensityCheck::kMaxSamples - 1);
  DOUBLES_EQUAL(0.8, static_cast<double>(r.share), 0.01);
  CHECK(r.flat);
}

TEST(IntensityCheck, ConfigurationClampsAndANewWindowForgetsTheVotes) {
  IntensityCheck c;
  IntensityCheckParams p;
  p.window_scans = 200;  // beyond the vote history
  p.flat_share = static_cast<Real>(0.2);
  p.decide_share = 0;
  c.configure(p);
  CHECK_EQUAL(IntensityCheck::kMaxWindow, c.params().window_scans);
  DOUBLES_EQUAL(0.5, static_cast<double>(c.params().flat_share), 0.0);
  DOUBLES_EQUAL(0.5, static_cast<double>(c.params().decide_share), 0.0);
  p = IntensityCheckParams{};
  p.window_scans = 4;
  c.configure(p);
  feed(c, a1_scan(), 3);
  CHECK(IntensityVerdict::kUnknown == c.verdict());
  feed(c, a1_scan(), 1);
  CHECK(IntensityVerdict::kFlat == c.verdict());
  c.configure(p);  // the same window: the votes stay
  CHECK(IntensityVerdict::kFlat == c.verdict());
  p.window_scans = 8;
  c.configure(p);  // a new window: the verdict stays until the new one is full
  feed(c, varied_scan(1), 7);
  CHECK(IntensityVerdict::kFlat == c.verdict());
  feed(c, varied_scan(1), 1);
  CHECK(IntensityVerdict::kUsable == c.verdict());
  c.reset();
  CHECK(IntensityVerdict::kUnknown == c.verdict());
}

TEST(IntensityCheck, DockcoreJudgesEveryScanItTakesAndKeepsTheVerdictAcrossConfigurations) {
  SmoothController ctrl;
  DockProfile plate, vmarker;
  CHECK(ProfileError::kOk == builtin_profile("plate-v", plate));
  CHECK(ProfileError::kOk == builtin_profile("v-marker", vmarker));
  auto core = std::make_unique<Dockcore>(ctrl);
  DockcoreConfig cfg;
  CHECK(core->configure(plate, cfg));
  const LaserScan s = a1_scan();
  std::uint64_t t = 1000000;
  for (int i = 0; i < 16; ++i, t += 100000) CHECK(core->on_scan(s.view(), t, t) != nullptr);
  CHECK(IntensityVerdict::kFlat == core->intensity().verdict());
  CHECK(core->configure(vmarker, cfg));
  CHECK(IntensityVerdict::kFlat == core->intensity().verdict());
  // A core that takes over the inputs (dockd's reload) takes the sensor's verdict with them.
  auto next = std::make_unique<Dockcore>(ctrl);
  next->take_inputs(*core);
  CHECK(next->configure(plate, cfg));
  CHECK(IntensityVerdict::kFlat == next->intensity().verdict());
  CHECK_EQUAL(16u, next->intensity().scans_judged());
}
