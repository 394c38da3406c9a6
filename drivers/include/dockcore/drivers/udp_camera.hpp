#pragma once
/// @file Camera target input (hal::CameraTargetSource): any vision process sends one JSON object per UDP datagram,
///   {"stamp_us": 123456789, "u": 321.5, "v": 240.0, "id": 3, "confidence": 0.92}
/// (docs/dockd.md, "Camera datagram"). stamp_us is the image time on the receiving host's CLOCK_MONOTONIC in µs (the
/// vision process runs on the same board; 0 or absent = receive time). Malformed, out-of-range, future (> 100 ms
/// ahead) or old (> max_age_ms) datagrams are refused and counted and change nothing. Heap only at open.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "dockcore/control/controller.hpp"
#include "dockcore/hal/camera.hpp"

namespace dockcore::drivers {

/// Largest accepted camera datagram, bytes.
constexpr std::size_t kMaxCameraDatagram = 256;

/// Why a camera datagram was refused.
enum class CameraDatagramError : std::uint8_t {
  kOk = 0,
  kTooLong,      ///< Longer than kMaxCameraDatagram.
  kMalformed,    ///< Not a flat JSON object.
  kMissingField, ///< u, v or confidence missing.
  kBadField,     ///< A field of the wrong type, out of range (u, v within ±100000 px, confidence 0..1, id 0..65535,
                 ///< stamp_us >= 0), or an unknown field.
  kFuture,       ///< stamp_us more than 100 ms after the receive time.
  kStale,        ///< stamp_us older than max_age_us at receipt.
  kWrongId,      ///< id differs from the configured target id.
};

const char* to_string(CameraDatagramError e);

/// Parses one datagram received at `now_us`. `expected_id` < 0 accepts any id. On success `out` is valid with
/// stamp_us set (receive time when absent or 0). O(len).
CameraDatagramError parse_camera_datagram(const char* data, std::size_t len, std::uint64_t now_us,
                                          std::uint64_t max_age_us, std::int32_t expected_id, CameraTarget& out,
                                          std::uint16_t& id_out);

struct UdpCameraOptions {
  std::string bind_address = "127.0.0.1";
  std::uint16_t port = 7301;          ///< 0 = any free port (tests).
  std::int32_t target_id = -1;        ///< Accept only this marker id; -1 = any.
  std::uint32_t max_age_ms = 500;     ///< Older images are refused.
};

struct UdpCameraCounters {
  std::uint32_t datagrams = 0;
  std::uint32_t accepted = 0;
  std::uint32_t malformed = 0;   ///< kTooLong, kMalformed, kMissingField, kBadField.
  std::uint32_t stale = 0;       ///< kStale, kFuture.
  std::uint32_t wrong_id = 0;
  std::uint32_t not_allowed = 0; ///< From a peer other than 127.0.0.1.
};

class UdpCamera : public hal::CameraTargetSource {
 public:
  virtual ~UdpCamera() = default;
  /// Reads pending datagrams (at most 64 per call) and keeps the newest valid one. `now_us`: CLOCK_MONOTONIC µs.
  virtual void service(std::uint64_t now_us) = 0;
  virtual const UdpCameraCounters& counters() const = 0;
  virtual std::uint16_t bound_port() const = 0;
};

/// nullptr + message in `error` when the address is bad or the socket cannot be bound.
std::unique_ptr<UdpCamera> open_udp_camera(const UdpCameraOptions& options, std::string& error);

}  // namespace dockcore::drivers
