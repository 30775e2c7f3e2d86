// Hostile numbers from the shop floor: each gets a clear typed error naming the value, or is
// handled within bounded memory. NaN and infinities in case files and measured data, a time step
// longer than the run, zero conductivity, a heat source on a region with no elements, 10 000
// sensors, and a data.csv beyond its size or row limit (the 1 GB file is in test_big_csv, long).
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/errors.hpp"
#include "io/case_reader.hpp"
#include "io/measured_data.hpp"
#include "mesh/mesher.hpp"
#include "solvers/thermal.hpp"

namespace tt::reliability_test {
namespace {

namespace fs = std::filesystem;

const fs::path kCoarse = fs::path(TT_SOURCE_DIR) / "cases" / "sb1_coarse.toml";

std::string coarse_text() {
  std::ifstream in(kCoarse);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The coarse SB-1 case with `from` replaced by `to`.
std::string coarse_with(const std::string& from, const std::string& to) {
  std::string t = coarse_text();
  const auto at = t.find(from);
  if (at == std::string::npos)
    ADD_FAILURE() << "'" << from << "' is not in " << kCoarse;
  else
    t.replace(at, from.size(), to);
  return t;
}

/// The message of the CaseError that reading `text` throws ("" when it reads).
std::string case_error(const std::string& text) {
  try {
    io::case_from_toml(text, kCoarse);
  } catch (const core::CaseError& e) {
    return e.what();
  }
  return "";
}

TEST(HostileCase, NonFiniteNumbersAreRefusedByName) {
  const struct {
    const char *from, *to, *key;
  } cases[] = {
      {"conductivity_W_mK = 46.0", "conductivity_W_mK = nan", "conductivity_W_mK"},
      {"density_kg_m3 = 7250.0", "density_kg_m3 = inf", "density_kg_m3"},
      {"step_s = 12.0", "step_s = +inf", "step_s"},
      {"h_W_m2K = 8.0", "h_W_m2K = -inf", "h_W_m2K"},
      {"sink_degC = 20.0", "sink_degC = nan", "sink_degC"},
      {"power_ref_W = 80.0", "power_ref_W = inf", "power_ref_W"},
      {"end_s = 7200.0", "end_s = nan", "end_s"},
      {"{ start_s = 600.0, speed_rpm = 0.0 }", "{ start_s = 600.0, speed_rpm = nan }", "speed_rpm"},
      {"position = [0.0, 0.3, 0.04]", "position = [0.0, nan, 0.04]", "position"},
      {"max_edge = 0.045", "max_edge = inf", "max_edge"},
  };
  for (const auto& c : cases) {
    const std::string msg = case_error(coarse_with(c.from, c.to));
    EXPECT_NE(msg.find(c.key), std::string::npos) << c.to << " -> " << msg;
    EXPECT_TRUE(msg.find("finite") != std::string::npos || msg.find("> 0") != std::string::npos ||
                msg.find("must") != std::string::npos)
        << c.to << " -> " << msg;
  }
}

TEST(HostileCase, NonFiniteSpeedInADutyCycleCsvIsRefused) {
  const fs::path dir = fs::path(TT_BINARY_DIR) / "reliability_scratch" / "duty_csv";
  fs::create_directories(dir);
  std::ofstream(dir / "duty.csv") << "time_s,speed_rpm\n0,3000\n600,nan\n";
  std::string text = coarse_text();
  const auto from = text.find("segments = [");
  const auto to = text.find("]\n", from) + 2;
  text.replace(from, to - from, "csv = \"duty.csv\"\n");
  std::string msg;
  try {
    io::case_from_toml(text, dir / "case.toml");
  } catch (const core::CaseError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("finite"), std::string::npos) << msg;
  EXPECT_NE(msg.find("duty.csv"), std::string::npos) << msg;
}

TEST(HostileCase, StepLongerThanTheRunIsRefused) {
  const std::string msg = case_error(coarse_with("step_s = 12.0", "step_s = 8000.0"));
  EXPECT_NE(msg.find("thermal.step_s = 8000"), std::string::npos) << msg;
  EXPECT_NE(msg.find("must not exceed the run"), std::string::npos) << msg;
}

TEST(HostileCase, ZeroConductivityIsRefused) {
  const std::string msg =
      case_error(coarse_with("conductivity_W_mK = 46.0", "conductivity_W_mK = 0.0"));
  EXPECT_NE(msg.find("conductivity_W_mK = 0"), std::string::npos) << msg;
  EXPECT_NE(msg.find("must be > 0"), std::string::npos) << msg;
}

TEST(HostileCase, HeatSourceOnARegionWithoutElementsIsRefused) {
  // Two boxes, the source on the second; then every tet is given to the first, as a mesh that
  // lost a thin body would be.
  const std::string text = R"(
[case]
name = "empty region"
[geometry]
length_unit = "m"
[materials.steel]
density_kg_m3 = 7850.0
specific_heat_J_kgK = 460.0
conductivity_W_mK = 42.0
youngs_modulus_Pa = 2.1e11
poisson_ratio = 0.3
expansion_per_K = 1.2e-5
[[bodies]]
name = "block"
material = "steel"
max_edge = 0.05
add = [ { box = { min = [0.0, 0.0, 0.0], max = [0.1, 0.1, 0.1] } } ]
[[bodies]]
name = "pad"
material = "steel"
max_edge = 0.05
add = [ { box = { min = [0.1, 0.0, 0.0], max = [0.15, 0.1, 0.1] } } ]
[[boundary]]
name = "all"
rest = true
select = [ { bodies = ["block", "pad"] } ]
[thermal]
step_s = 10.0
[[thermal.convection]]
group = "all"
h_W_m2K = 10.0
sink_degC = 20.0
[[thermal.heat_sources]]
name = "pad heat"
body = "pad"
law = "constant"
power_ref_W = 10.0
[duty_cycle]
end_s = 100.0
segments = [ { start_s = 0.0, speed_rpm = 0.0 } ]
[mechanical]
enabled = false
)";
  const core::CaseSpec spec = io::case_from_toml(text, "empty_region.toml");
  mesh::TetMesh m = mesh::mesh_case(spec);
  const auto pad = core::RegionId(1);  // tet_region holds body indices: "pad" is body 1
  ASSERT_GT(std::count(m.tet_region.begin(), m.tet_region.end(), pad), 0);
  for (auto& r : m.tet_region) r = core::RegionId(0);
  try {
    solvers::thermal_operators(m, spec);
    ADD_FAILURE() << "a source on a body with no elements was accepted";
  } catch (const core::SolverError& e) {
    EXPECT_NE(std::string(e.what()).find("pad heat"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no elements"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// Measured data

struct Folder {
  fs::path dir;
  explicit Folder(const std::string& name)
      : dir(fs::path(TT_BINARY_DIR) / "reliability_scratch" / name) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void write(const std::string& file, const std::string& text) const {
    std::ofstream(dir / file) << text;
  }
};

std::string meta_with_sensors(int n) {
  std::string m = R"({"format": "thermal-measurement/1", "machine": "bench", "run": "r1",
    "time_unit": "s", "temperature_unit": "degC", "displacement_unit": "um",
    "displacements": [], "inputs": [{"id": "speed_rpm", "unit": "rpm"}], "sensors": [)";
  for (int i = 0; i < n; ++i)
    m += (i ? ", " : "") + std::string("{\"id\": \"T") + std::to_string(i) +
         "\", \"position\": null}";
  return m + "]}";
}

std::string data_error(const Folder& f, const io::MeasuredReadLimits& limits = {}) {
  try {
    io::read_measured_run(f.dir, limits);
  } catch (const core::DataError& e) {
    return e.what();
  }
  return "";
}

TEST(HostileData, NonFiniteCellsAreRefusedWithLineAndColumn) {
  for (const std::string cell : {"nan", "NaN", "inf", "-inf", "1e999"}) {
    Folder f("data_nonfinite");
    f.write("meta.json", meta_with_sensors(2));
    f.write("data.csv", "time_s,speed_rpm,T0,T1\n0,0,20,20\n10,0,20.5," + cell + "\n");
    const std::string msg = data_error(f);
    EXPECT_NE(msg.find("data.csv"), std::string::npos) << cell << " -> " << msg;
    EXPECT_NE(msg.find(":3"), std::string::npos) << cell << " -> " << msg;
    EXPECT_NE(msg.find("T1"), std::string::npos) << cell << " -> " << msg;
  }
}

TEST(HostileData, NonFiniteTimeAndMetaNumbersAreRefused) {
  Folder f("data_nonfinite_time");
  f.write("meta.json", meta_with_sensors(1));
  f.write("data.csv", "time_s,speed_rpm,T0\n0,0,20\ninf,0,20\n");
  EXPECT_NE(data_error(f).find("time_s"), std::string::npos) << data_error(f);
  // JSON has no NaN: the reader names the file.
  std::string meta = meta_with_sensors(1);
  meta.insert(meta.size() - 1, ", \"initial_temperature_degC\": NaN");
  f.write("meta.json", meta);
  f.write("data.csv", "time_s,speed_rpm,T0\n0,0,20\n");
  EXPECT_NE(data_error(f).find("meta.json"), std::string::npos) << data_error(f);
}

TEST(HostileData, TenThousandSensorsReadInBoundedMemory) {
  constexpr int kSensors = 10000, kRows = 200;
  Folder f("data_10k_sensors");
  f.write("meta.json", meta_with_sensors(kSensors));
  std::string csv = "time_s,speed_rpm";
  for (int i = 0; i < kSensors; ++i) csv += ",T" + std::to_string(i);
  csv += "\n";
  for (int r = 0; r < kRows; ++r) {
    csv += std::to_string(10 * r) + ",3000";
    for (int i = 0; i < kSensors; ++i) csv += (i % 97 == 0) ? "," : ",20.25";
    csv += "\n";
  }
  f.write("data.csv", csv);
  rusage before{};
  getrusage(RUSAGE_SELF, &before);
  const io::MeasuredRun run = io::read_measured_run(f.dir);
  rusage after{};
  getrusage(RUSAGE_SELF, &after);
  ASSERT_EQ(run.temperature.rows(), kRows);
  ASSERT_EQ(run.temperature.cols(), kSensors);
  EXPECT_TRUE(std::isnan(run.temperature(5, 97)));  // empty cell: missing, never zero
  EXPECT_DOUBLE_EQ(run.temperature(5, 98), 20.25 + 273.15);
  // 2 M values are 16 MB; the reader may hold a few copies, never hundreds of MB.
  EXPECT_LT(after.ru_maxrss - before.ru_maxrss, 200 * 1024)
      << "peak RSS grew by " << after.ru_maxrss - before.ru_maxrss << " kB";
}

TEST(HostileData, CsvBeyondTheByteLimitIsRefusedBeforeReading) {
  Folder f("data_bytes");
  f.write("meta.json", meta_with_sensors(1));
  std::string csv = "time_s,speed_rpm,T0\n";
  for (int r = 0; r < 2000; ++r) csv += std::to_string(r) + ",0,20\n";
  f.write("data.csv", csv);
  io::MeasuredReadLimits limits;
  limits.max_bytes = 4096;
  const std::string msg = data_error(f, limits);
  EXPECT_NE(msg.find("exceeds the limit of 4096 bytes"), std::string::npos) << msg;
}

TEST(HostileData, CsvBeyondTheRowLimitIsRefusedAtThatRow) {
  Folder f("data_rows");
  f.write("meta.json", meta_with_sensors(1));
  std::string csv = "time_s,speed_rpm,T0\n";
  for (int r = 0; r < 2000; ++r) csv += std::to_string(r) + ",0,20\n";
  f.write("data.csv", csv);
  io::MeasuredReadLimits limits;
  limits.max_rows = 100;
  const std::string msg = data_error(f, limits);
  EXPECT_NE(msg.find("more than 100 rows"), std::string::npos) << msg;
  EXPECT_NE(msg.find(":102"), std::string::npos) << msg;  // header is line 1, row 101 is line 102
  limits.max_rows = 2000;
  EXPECT_EQ(io::read_measured_run(f.dir, limits).time.size(), 2000);
}

}  // namespace
}  // namespace tt::reliability_test
