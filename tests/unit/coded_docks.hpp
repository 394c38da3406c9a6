#pragma once
// Test helpers shared by the reflector suites: plate-v with tape on its face, and the LD06 model at a given noise.
// Include after the standard and Eigen headers (CppUTest's new macros).
#include <initializer_list>
#include <utility>

#include "dockcore/perception/dock_profile.hpp"
#include "docksim/lidar_sim.hpp"

#include <CppUTest/TestHarness.h>

namespace dockcore_test {

/// plate-v with retro-reflective stripes on its 0.30 m face (segment 1), at [from, to] metres along it.
inline dockcore::DockProfile coded_plate(std::initializer_list<std::pair<double, double>> stripes) {
  dockcore::DockProfile p;
  CHECK_EQUAL(static_cast<int>(dockcore::ProfileError::kOk), static_cast<int>(dockcore::builtin_profile("plate-v", p)));
  for (const auto& s : stripes) {
    dockcore::ReflectorStripe r;
    r.segment = 1;
    r.from_m = static_cast<dockcore::Real>(s.first);
    r.to_m = static_cast<dockcore::Real>(s.second);
    CHECK_EQUAL(static_cast<int>(dockcore::ProfileError::kOk), static_cast<int>(dockcore::add_reflector(p, r)));
  }
  return p;
}

/// The LD06 model with a constant range noise of `sigma_m` (no proportional part).
inline docksim::LidarModel ld06(double sigma_m) {
  docksim::LidarModel m;
  CHECK_TRUE(docksim::lidar_model("ld06", &m));
  m.sigma_const_m = sigma_m;
  m.sigma_prop = 0;
  return m;
}

}  // namespace dockcore_test
