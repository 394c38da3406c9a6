#include "dockcore/control/controller.hpp"

namespace dockcore {

const char* to_string(ControlStatus s) {
  switch (s) {
    case ControlStatus::kRunning: return "running";
    case ControlStatus::kArrived: return "arrived";
    case ControlStatus::kLost: return "lost";
    case ControlStatus::kFailed: return "failed";
  }
  return "unknown";
}

}  // namespace dockcore
