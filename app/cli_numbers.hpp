// Numbers on the command line: CLI11 reads "nan" and "inf" as doubles, and its Range validator
// lets NaN through (every comparison with it is false). Each numeric option carries one of these,
// so a value that makes no sense is refused with the option's name before any work starts.
#pragma once

#include <CLI/CLI.hpp>
#include <charconv>
#include <cmath>
#include <string>

namespace tt::app {

/// Which finite numbers a validator takes.
enum class FiniteSign { any, positive, non_negative };

/// A finite number, > 0 or >= 0 as `sign` says; CLI11's error reads "--hours: nan: expected a
/// finite number > 0".
inline CLI::Validator finite_number(FiniteSign sign = FiniteSign::any) {
  const std::string expected = sign == FiniteSign::positive       ? "a finite number > 0"
                               : sign == FiniteSign::non_negative ? "a finite number >= 0"
                                                                  : "a finite number";
  return CLI::Validator(
      [sign, expected](std::string& text) -> std::string {
        double v = 0;
        const char* first = text.data();
        const char* last = first + text.size();
        if (first != last && *first == '+') ++first;
        const auto r = std::from_chars(first, last, v);
        if (r.ec != std::errc() || r.ptr != last || !std::isfinite(v) ||
            (sign == FiniteSign::positive && !(v > 0)) ||
            (sign == FiniteSign::non_negative && !(v >= 0)))
          return text + ": expected " + expected;
        return {};
      },
      expected, "FINITE");
}

/// A finite number >= 0: CLI11's NonNegativeNumber lets "nan" and "inf" through.
inline CLI::Validator non_negative_number() {
  return finite_number(FiniteSign::non_negative);
}

inline CLI::Validator positive_number() {
  return finite_number(FiniteSign::positive);
}

}  // namespace tt::app
