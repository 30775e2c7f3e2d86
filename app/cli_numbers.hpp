// Numbers on the command line: CLI11 reads "nan" and "inf" as doubles, and its Range validator
// lets NaN through (every comparison with it is false). Each numeric option carries one of these,
// so a value that makes no sense is refused with the option's name before any work starts.
#pragma once

#include <CLI/CLI.hpp>
#include <charconv>
#include <cmath>
#include <string>

namespace tt::app {

/// A finite number, > 0 when `positive`; CLI11's error reads "--hours: nan: expected a finite
/// number > 0".
inline CLI::Validator finite_number(bool positive = false) {
  const std::string expected = positive ? "a finite number > 0" : "a finite number";
  return CLI::Validator(
      [positive, expected](std::string& text) -> std::string {
        double v = 0;
        const char* first = text.data();
        const char* last = first + text.size();
        if (first != last && *first == '+') ++first;
        const auto r = std::from_chars(first, last, v);
        if (r.ec != std::errc() || r.ptr != last || !std::isfinite(v) || (positive && !(v > 0)))
          return text + ": expected " + expected;
        return {};
      },
      expected, "FINITE");
}

inline CLI::Validator positive_number() {
  return finite_number(true);
}

}  // namespace tt::app
