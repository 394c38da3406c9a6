// Writes tests/data/can/docking_v1.log: a 4 s dockcore v1 docking session in candump -L form, made with core's
// encoders, with faults injected on purpose for dock-decode's test (tests/can/check_decode.py):
//   - WheelFbA skips one counter value at frame 100 (one counter_jump),
//   - ChassisStatus pauses from 2.0 s to 2.5 s (one gap > 2 x 100 ms),
//   - one CAN FD line, one RTR line, one comment, one malformed line (line number printed on stderr).
// Usage: make_can_log > tests/data/can/docking_v1.log
#include <cstdint>
#include <cstdio>
#include <algorithm>
#include <string>
#include <vector>

#include "dockcore/protocols/can/can_dockcore_v1.hpp"

namespace {

using dockcore::CanFrame;
namespace v1 = dockcore::can_v1;

struct Line {
  std::uint64_t t_us;
  std::string text;
};
std::vector<Line> lines;

void put(std::uint64_t t_us, const CanFrame& f) {
  char b[64];
  int n = std::snprintf(b, sizeof b, "(%llu.%06llu) vcan0 %03X#", 1700000000ull + t_us / 1000000u,
                        static_cast<unsigned long long>(t_us % 1000000u), f.id);
  for (int i = 0; i < f.dlc; ++i) n += std::snprintf(b + n, sizeof b - static_cast<std::size_t>(n), "%02X", f.data[i]);
  lines.push_back({t_us, b});
}

}  // namespace

int main() {
  const v1::Ids ids;
  std::uint8_t c_cmd = 0, c_fb = 0, c_enc = 0, c_pow = 0, c_st = 0, c_ds = 0, c_dp = 0, c_ch = 0;
  int fb_frames = 0;
  std::int32_t enc = 0;
  for (std::uint64_t t = 0; t < 4000000; t += 20000) {
    const double ts = static_cast<double>(t) * 1e-6;
    const std::int16_t v = (ts >= 0.5 && ts < 3.0) ? 200 : 0;  // mm/s
    put(t, v1::encode(ids, v1::WheelCommandFrame{false, {v, v}, true, false, c_cmd++}));
    if (++fb_frames == 100) ++c_fb;  // injected: one lost counter value
    const std::int16_t meas = (ts >= 0.55 && ts < 3.05) ? 198 : 0;
    put(t + 5000, v1::encode(ids, v1::WheelFeedbackFrame{false, {meas, meas}, c_fb++}));
    enc += meas / 10;
    put(t + 5100, v1::encode(ids, v1::EncoderFrame{false, {enc, enc}, c_enc++}));
    if (t % 100000 == 0) {
      const bool contact = ts >= 3.0;
      const std::int16_t cur = ts >= 3.2 ? 200 : -80;
      put(t + 7000, v1::encode(ids, v1::PowerFrame{2480, cur, 62, contact, ts >= 3.0, c_pow++}));
      if (ts < 2.0 || ts >= 2.5)  // injected: status pause 2.0..2.5 s
        put(t + 7100, v1::encode(ids, v1::ChassisStatusFrame{1, false, 0, static_cast<std::uint8_t>((c_cmd - 1) & 15), c_st++}));
      std::uint8_t state = 0;
      if (ts >= 0.2) state = 2;
      if (ts >= 0.5) state = 3;
      if (ts >= 3.0) state = 5;
      if (ts >= 3.5) state = 4;
      const std::uint8_t result = ts >= 0.2 ? 1 : 0;
      put(t + 9000, v1::encode(ids, v1::DockStatusFrame{state, static_cast<std::uint8_t>(state == 3 ? 1 : 0), 0, 0, result,
                                                         static_cast<std::uint8_t>(ts >= 0.2 ? 1 : 0), c_ds++}));
      const std::int16_t x = static_cast<std::int16_t>(ts < 3.0 ? 1000 - static_cast<int>(ts * 300) : 100);
      put(t + 9100, v1::encode(ids, v1::DockPoseFrame{x, 5, -120, ts >= 0.2, c_dp++}));
      if (ts >= 3.0) put(t + 9200, v1::encode(ids, v1::ChargeRequestFrame{true, c_ch++}));
    }
    if (t == 100000) put(t + 12000, v1::encode(ids, v1::HostCommandFrame{1, 1, 1, 0}));
  }
  lines.push_back({1500000, "(1700000001.500000) vcan0 123##1DEADBEEF"});
  lines.push_back({1600000, "(1700000001.600000) vcan0 7FF#R"});
  lines.push_back({1700000, "(1700000001.700000) vcan0 1X0#0011"});
  std::stable_sort(lines.begin(), lines.end(), [](const Line& a, const Line& b) { return a.t_us < b.t_us; });
  std::printf("# dockcore v1 docking session (tests/can/make_can_log.cpp): counter jump, status gap, FD/RTR/malformed lines\n");
  int n = 1;
  for (const Line& l : lines) {
    ++n;
    if (l.text.find("1X0#") != std::string::npos) std::fprintf(stderr, "malformed line: %d\n", n);
    std::printf("%s\n", l.text.c_str());
  }
  return 0;
}
