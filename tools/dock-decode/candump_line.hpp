#pragma once
// One line of a candump log (`candump -L` / `candump -l`, and dockd's session record, which uses the same form):
//   (1700000000.123456) vcan0 123#DEADBEEF        standard id: 3 hex digits; extended: 8; data 0..8 bytes in hex
//   (1700000000.123456) vcan0 123#R / 123#R4      remote request        -> kRtr (skipped, counted)
//   (1700000000.123456) vcan0 123##1DEADBEEF      CAN FD (flags nibble) -> kCanFd (skipped, counted)
//   (1700000000.123456) vcan0 20000004#00...      error frame (CAN_ERR_FLAG in an 8-digit id) -> kErrorFrame
// Blank lines and lines starting with '#' are kBlank. Anything else is kMalformed with a reason. Header-only and
// allocation-free so the fuzz target (tests/fuzz/fuzz_candump_line.cpp) and dock-decode share it. O(line length).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "dockcore/protocols/can/can_frame.hpp"

namespace dockdecode {

enum class LineKind : std::uint8_t { kFrame, kBlank, kRtr, kCanFd, kErrorFrame, kMalformed };

struct CandumpLine {
  std::uint64_t stamp_us = 0;   ///< Seconds.micros of the line as microseconds.
  char iface[17] = {0};         ///< Interface name, NUL-terminated (truncated to 16 characters).
  dockcore::CanFrame frame{};
  const char* reason = "";      ///< Why a line is kMalformed (static string).
};

namespace detail {
inline int hexval(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}
inline LineKind bad(CandumpLine& out, const char* why) {
  out.reason = why;
  return LineKind::kMalformed;
}
}  // namespace detail

/// Parses one line (without or with its trailing '\n' / "\r\n"). `out` is filled for kFrame; for other kinds only
/// stamp/iface/reason as far as parsed.
inline LineKind parse_candump_line(std::string_view s, CandumpLine& out) {
  using detail::bad;
  using detail::hexval;
  out = CandumpLine{};
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  std::size_t i = 0;
  while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
  if (i == s.size() || s[i] == '#') return LineKind::kBlank;
  if (s[i] != '(') return bad(out, "no '(' timestamp");
  ++i;
  std::uint64_t sec = 0;
  std::size_t digits = 0;
  while (i < s.size() && s[i] >= '0' && s[i] <= '9') {
    if (++digits > 12) return bad(out, "timestamp seconds too long");
    sec = sec * 10 + static_cast<std::uint64_t>(s[i] - '0');
    ++i;
  }
  if (digits == 0 || i >= s.size() || s[i] != '.') return bad(out, "timestamp is not seconds.micros");
  ++i;
  std::uint64_t frac = 0;
  std::size_t fd = 0;
  while (i < s.size() && s[i] >= '0' && s[i] <= '9') {
    if (fd < 6) frac = frac * 10 + static_cast<std::uint64_t>(s[i] - '0');
    ++fd;
    ++i;
  }
  if (fd == 0 || fd > 9) return bad(out, "timestamp fraction");
  for (std::size_t k = fd; k < 6; ++k) frac *= 10;
  if (i >= s.size() || s[i] != ')') return bad(out, "no ')' after timestamp");
  ++i;
  out.stamp_us = sec * 1000000u + frac;
  if (i >= s.size() || s[i] != ' ') return bad(out, "no interface");
  while (i < s.size() && s[i] == ' ') ++i;
  std::size_t n = 0;
  while (i < s.size() && s[i] != ' ' && s[i] != '\t') {
    if (s[i] < '!' || s[i] > '~') return bad(out, "interface name has a control character");
    if (n < 16) out.iface[n++] = s[i];
    ++i;
  }
  out.iface[n] = 0;
  if (n == 0) return bad(out, "no interface");
  while (i < s.size() && s[i] == ' ') ++i;
  // id
  std::uint32_t id = 0;
  std::size_t idd = 0;
  while (i < s.size() && s[i] != '#') {
    const int h = hexval(s[i]);
    if (h < 0) return bad(out, "id is not hex");
    if (++idd > 8) return bad(out, "id longer than 8 hex digits");
    id = (id << 4) | static_cast<std::uint32_t>(h);
    ++i;
  }
  if (i >= s.size()) return bad(out, "no '#'");
  if (idd != 3 && idd != 8) return bad(out, "id must have 3 (standard) or 8 (extended) hex digits");
  ++i;  // '#'
  if (idd == 3 && id > 0x7FF) return bad(out, "standard id above 0x7FF");
  if (i < s.size() && s[i] == '#') return LineKind::kCanFd;
  if (i < s.size() && (s[i] == 'R' || s[i] == 'r')) return LineKind::kRtr;
  if (idd == 8 && (id & 0x20000000u)) return LineKind::kErrorFrame;
  if (idd == 8 && id > 0x1FFFFFFFu) return bad(out, "extended id above 29 bits");
  out.frame.id = id;
  out.frame.extended = idd == 8;
  std::uint8_t len = 0;
  while (i < s.size()) {
    if (s[i] == '.') {  // candump may separate bytes with '.'
      ++i;
      continue;
    }
    if (i + 1 >= s.size()) return bad(out, "odd number of data hex digits");
    const int a = hexval(s[i]), b = hexval(s[i + 1]);
    if (a < 0 || b < 0) return bad(out, "data is not hex");
    if (len == 8) return bad(out, "more than 8 data bytes");
    out.frame.data[len++] = static_cast<std::uint8_t>((a << 4) | b);
    i += 2;
  }
  out.frame.dlc = len;
  return LineKind::kFrame;
}

}  // namespace dockdecode
