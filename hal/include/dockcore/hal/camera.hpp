#pragma once
/// @file HAL: the camera target from any vision process (a documented UDP datagram: stamp, u, v, id, confidence).

#include "dockcore/controller.hpp"

namespace dockcore::hal {

class CameraTargetSource {
 public:
  /// Newest target since the last call; false when none arrived (out untouched).
  virtual bool poll_target(CameraTarget& out) = 0;
  virtual int fd() const = 0;

 protected:
  ~CameraTargetSource() = default;
};

}  // namespace dockcore::hal
