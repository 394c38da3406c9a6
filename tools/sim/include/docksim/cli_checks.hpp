#pragma once
// CLI11 checks shared by the host tools (dock-sim, lidar-emu, chassis-sim, lidar-dump). Header-only: only the tools,
// which link CLI11, include it; dockcore_sim itself does not use CLI11.
#include <string>

#include <CLI/CLI.hpp>

namespace docksim {

/// Check for an option read into a 64-bit unsigned integer (a seed, a count): refuses a negative number, which CLI11
/// would otherwise wrap to 2^64 - N without a word. O(length of the text).
inline CLI::Validator non_negative_integer() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const std::size_t first = text.find_first_not_of(" \t");
        if (first != std::string::npos && text[first] == '-') {
          return "must be a non-negative integer (0 to 18446744073709551615), not " + text;
        }
        return std::string();
      },
      "UINT >= 0", "NON_NEGATIVE_INTEGER");
}

}  // namespace docksim
