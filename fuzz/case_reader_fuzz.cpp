// Fuzz target: any text given to the case reader either becomes a spec or a typed error. A spec
// that reads must also survive the documented round trip (its resolved TOML reads back).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "core/errors.hpp"
#include "io/case_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  // A folder that holds no surface or CSV files: names in the input resolve to nothing.
  const std::filesystem::path file = "/nonexistent-tt-fuzz/case.toml";
  tt::core::CaseSpec spec;
  try {
    spec = tt::io::case_from_toml(text, file);
  } catch (const tt::core::Error&) {
    return 0;  // a typed rejection is the expected answer to most inputs
  }
  // Uncaught: a spec the reader accepted but cannot read back is a bug, so libFuzzer reports it.
  const tt::core::CaseSpec again = tt::io::case_from_toml(tt::io::resolved_case_toml(spec), file);
  if (again.bodies.size() != spec.bodies.size() || again.groups.size() != spec.groups.size() ||
      again.duty_cycle.segments.size() != spec.duty_cycle.segments.size())
    std::abort();
  return 0;
}
