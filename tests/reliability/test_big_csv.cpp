// Long (ctest -L long): a real 1 GB data.csv. Beyond the byte limit it is refused before it is
// read (memory does not grow); under the default limit it is read with peak memory bounded by a
// small multiple of the file. Writes 1 GB under the build tree and removes it.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/errors.hpp"
#include "io/measured_data.hpp"

namespace tt::reliability_test {
namespace {

namespace fs = std::filesystem;

long peak_rss_kb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

TEST(BigCsv, OneGigabyte) {
  const fs::path dir = fs::path(TT_BINARY_DIR) / "reliability_scratch" / "big_csv";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "meta.json")
      << R"({"format": "thermal-measurement/1", "machine": "bench", "run": "big", "time_unit": "s",
      "temperature_unit": "degC", "displacement_unit": "um", "displacements": [],
      "inputs": [{"id": "speed_rpm", "unit": "rpm"}],
      "sensors": [{"id": "T1", "position": null}, {"id": "T2", "position": null},
                  {"id": "T3", "position": null}, {"id": "T4", "position": null}]})";
  std::size_t bytes = 0, rows = 0;
  {
    std::FILE* out = std::fopen((dir / "data.csv").c_str(), "wb");
    ASSERT_NE(out, nullptr);
    bytes += std::fprintf(out, "time_s,speed_rpm,T1,T2,T3,T4\n");
    while (bytes < (std::size_t(1) << 30)) {
      bytes += std::fprintf(out, "%zu,3000,20.125,21.5,,22.75\n", rows);
      ++rows;
    }
    std::fclose(out);
  }
  const long before = peak_rss_kb();
  io::MeasuredReadLimits small;
  small.max_bytes = std::size_t(256) << 20;
  EXPECT_THROW(io::read_measured_run(dir, small), core::DataError);
  EXPECT_LT(peak_rss_kb() - before, 16 * 1024) << "refusing the file must not read it";

  const io::MeasuredRun run = io::read_measured_run(dir);
  EXPECT_EQ(static_cast<std::size_t>(run.time.size()), rows);
  // Values as doubles take about 1.2 x the text here; allow growth and the final copy.
  EXPECT_LT(peak_rss_kb() - before, static_cast<long>(3.5 * static_cast<double>(bytes) / 1024));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace tt::reliability_test
