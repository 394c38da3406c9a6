#pragma once
// Helpers and names the daemon's source files share (daemon.cpp and daemon_*.cpp: one job each). Not part of dockd's
// interface.
#include <cstdint>

#include "daemon.hpp"

namespace dockd::detail {

constexpr std::uint64_t kNominalTickUs = 20000;  ///< The control tick's period.

inline double deg(dockcore::Real rad) {
  return static_cast<double>(rad) * 180.0 / 3.14159265358979323846;
}

inline const char* level_name(LogLevel l) {
  switch (l) {
    case LogLevel::kError:
      return "error";
    case LogLevel::kWarn:
      return "warn";
    case LogLevel::kInfo:
      return "info";
    case LogLevel::kDebug:
      return "debug";
  }
  return "?";
}

/// States in which the core may be reconfigured (nothing runs). O(1).
inline bool idle_state(dockcore::TaskState s) {
  return s == dockcore::TaskState::kNotTasking || s == dockcore::TaskState::kFault;
}

}  // namespace dockd::detail

namespace dockd {

// Every daemon source file uses these names unqualified.
using namespace detail;
using dockcore::FaultCode;
using dockcore::HostCommandType;
using dockcore::Pose2;
using dockcore::Real;
using dockcore::TaskState;

}  // namespace dockd
