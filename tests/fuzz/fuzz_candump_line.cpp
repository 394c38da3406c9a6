// fuzz-links: core dockcore_candump
// dock-decode's candump line parser (tools/dock-decode/candump_line.hpp, header-only; the dockcore_candump interface
// target gives its include path). Input: text, split into lines at '\n'. Invariants: a kFrame has dlc <= 8 and an
// id within 11 / 29 bits; printing it back in candump form and parsing again gives the same frame and stamp.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "candump_line.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view all(reinterpret_cast<const char*>(data), size);
  while (!all.empty()) {
    const std::size_t nl = all.find('\n');
    const std::string_view line = all.substr(0, nl);
    all = nl == std::string_view::npos ? std::string_view() : all.substr(nl + 1);
    dockdecode::CandumpLine l;
    if (dockdecode::parse_candump_line(line, l) != dockdecode::LineKind::kFrame) continue;
    if (l.frame.dlc > 8) std::abort();
    if (l.frame.extended ? l.frame.id > 0x1FFFFFFFu : l.frame.id > 0x7FFu) std::abort();
    char buf[128];
    int n = std::snprintf(buf, sizeof buf, "(%llu.%06llu) %s %0*X#", static_cast<unsigned long long>(l.stamp_us / 1000000u),
                          static_cast<unsigned long long>(l.stamp_us % 1000000u), l.iface, l.frame.extended ? 8 : 3,
                          l.frame.id);
    for (int i = 0; i < l.frame.dlc; ++i) n += std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n), "%02X", l.frame.data[i]);
    dockdecode::CandumpLine back;
    if (dockdecode::parse_candump_line(std::string_view(buf, static_cast<std::size_t>(n)), back) != dockdecode::LineKind::kFrame)
      std::abort();
    if (back.stamp_us != l.stamp_us || back.frame.id != l.frame.id || back.frame.dlc != l.frame.dlc ||
        back.frame.extended != l.frame.extended || std::memcmp(back.frame.data, l.frame.data, l.frame.dlc) != 0)
      std::abort();
  }
  return 0;
}
