// fuzz-links: core
// AgileX V2: arbitrary frames into every decoder; a decoded frame re-encodes to the same bytes (every byte the
// decoder reads; unused bytes are zero on encode, so only those are compared).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "dockcore/protocols/can/can_agilex_v2.hpp"

using namespace dockcore;
using namespace dockcore::agilex_v2;

namespace {

template <class M>
void roundtrip(const CanFrame& f) {
  M m;
  if (decode(f, m) != AgxError::kOk) return;
  const CanFrame g = encode(m);
  M m2;
  if (decode(g, m2) != AgxError::kOk) std::abort();
  const CanFrame g2 = encode(m2);  // compared through the encoding: struct padding is indeterminate
  if (std::memcmp(g.data, g2.data, 8) != 0 || g.id != f.id) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::uint32_t ids[8] = {0x421, 0x111, 0x211, 0x221, 0x311, 0x361, 0x312, 0x7FF};
  for (std::size_t off = 0; off + 10 <= size; off += 10) {
    const std::uint8_t* r = data + off;
    CanFrame f;
    f.id = ids[r[0] & 7u];
    f.extended = (r[0] & 0x80u) != 0;
    f.dlc = r[1];
    std::memcpy(f.data, r + 2, 8);
    roundtrip<ControlModeFrame>(f);
    roundtrip<MotionCommandFrame>(f);
    roundtrip<SystemStateFrame>(f);
    roundtrip<MotionStateFrame>(f);
    roundtrip<OdometryFrame>(f);
    roundtrip<BmsFrame>(f);
    (void)frame_name(f.id);
    (void)period_ms(f.id);
  }
  return 0;
}
