// Names joined into one piece of text, for messages and reports.
#pragma once

#include <string>
#include <vector>

namespace tt::core {

/// The names joined by `separator`: "a, b, c"; "" when there are none.
inline std::string joined(const std::vector<std::string>& names,
                          const std::string& separator = ", ") {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) out += (i ? separator : "") + names[i];
  return out;
}

}  // namespace tt::core
