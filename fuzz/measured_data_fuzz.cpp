// Fuzz target: any meta.json + data.csv pair is either read as a run or rejected with a typed
// error, within bounded memory. The input is meta.json, a line "=====", then data.csv (no such
// line: all meta.json, empty data.csv); the files go to a folder of this process under /dev/shm.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "core/errors.hpp"
#include "io/measured_data.hpp"

namespace {

const std::filesystem::path& folder() {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::path("/dev/shm") / ("tt-fuzz-measured-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

void write(const std::filesystem::path& path, std::string_view text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::string_view separator = "\n=====\n";
  const auto cut = input.find(separator);
  const std::string_view meta = input.substr(0, cut);
  const std::string_view csv =
      cut == std::string_view::npos ? std::string_view() : input.substr(cut + separator.size());
  write(folder() / "meta.json", meta);
  write(folder() / "data.csv", csv);

  // Small limits so that the limit checks are reached; a machine box on every other input.
  tt::io::MeasuredReadLimits limits;
  limits.max_bytes = 64 * 1024;
  limits.max_rows = 500;
  if (size % 2 == 0)
    limits.machine_box = Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1));
  try {
    const tt::io::MeasuredRun run = tt::io::read_measured_run(folder(), limits);
    // What the header promises of an accepted run.
    const auto n = run.time.size();
    if (run.temperature.rows() != n || run.displacement.rows() != n ||
        run.input_values.rows() != n ||
        run.temperature.cols() != static_cast<Eigen::Index>(run.sensors.size()) ||
        run.displacement.cols() != static_cast<Eigen::Index>(run.displacements.size()) ||
        run.input_values.cols() != static_cast<Eigen::Index>(run.inputs.size()))
      std::abort();
    for (Eigen::Index i = 1; i < n; ++i)
      if (!(run.time[i] > run.time[i - 1])) std::abort();
    if (n > 0 && !run.time.allFinite()) std::abort();
  } catch (const tt::core::Error&) {
    // a typed rejection is the expected answer to most inputs
  }
  return 0;
}
