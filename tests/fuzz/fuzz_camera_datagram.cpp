// fuzz-links: core drivers
// Camera datagrams (docs/dockd.md): parse_camera_datagram must never crash, and a refused datagram never yields a
// valid target.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "dockcore/drivers/udp_camera.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace dockcore::drivers;
  dockcore::CameraTarget t;
  std::uint16_t id = 0;
  const CameraDatagramError e =
      parse_camera_datagram(reinterpret_cast<const char*>(data), size, 5000000, 500000, -1, t, id);
  if (e != CameraDatagramError::kOk && t.valid) __builtin_trap();
  if (e == CameraDatagramError::kOk && (!std::isfinite(static_cast<double>(t.u_px)) || t.confidence < 0 || t.confidence > 1)) {
    __builtin_trap();
  }
  return 0;
}
