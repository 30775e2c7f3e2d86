// Hostile measured data: NaN and infinities in data.csv and meta.json, 10 000 sensors, a data.csv
// beyond its size or row limit (the real 1 GB file is in test_big_csv, label long), and the inputs
// that made fuzz_measured_data fail.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cmath>
#include <string>

#include "core/errors.hpp"
#include "io/measured_data.hpp"
#include "tests/reliability/process.hpp"

namespace tt::reliability_test {
namespace {

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

TEST(HostileData, TemperaturesBelowAbsoluteZeroAreRefused) {
  Folder f("data_below_absolute_zero");
  f.write("meta.json", meta_with_sensors(2));
  f.write("data.csv", "time_s,speed_rpm,T0,T1\n0,0,20,20\n10,0,20.5,-300\n");
  std::string msg = data_error(f);
  EXPECT_NE(msg.find("data.csv:3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("T1"), std::string::npos) << msg;
  EXPECT_NE(msg.find("absolute zero"), std::string::npos) << msg;
  // A speed below -273.15 is not a temperature: only sensor columns are held to it.
  f.write("data.csv", "time_s,speed_rpm,T0,T1\n0,-300,20,20\n");
  EXPECT_EQ(data_error(f), "");
  std::string meta = meta_with_sensors(2);
  meta.insert(meta.size() - 1, ", \"initial_temperature_degC\": -274");
  f.write("meta.json", meta);
  msg = data_error(f);
  EXPECT_NE(msg.find("initial_temperature_degC"), std::string::npos) << msg;
  EXPECT_NE(msg.find("absolute zero"), std::string::npos) << msg;
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

/// A run of one sensor and `rows` rows, written into a new folder `name`.
Folder one_sensor_run(const std::string& name, int rows) {
  Folder f(name);
  f.write("meta.json", meta_with_sensors(1));
  std::string csv = "time_s,speed_rpm,T0\n";
  for (int r = 0; r < rows; ++r) csv += std::to_string(r) + ",0,20\n";
  f.write("data.csv", csv);
  return f;
}

TEST(HostileData, CsvBeyondTheByteLimitIsRefusedBeforeReading) {
  const Folder f = one_sensor_run("data_bytes", 2000);
  io::MeasuredReadLimits limits;
  limits.max_bytes = 4096;
  const std::string msg = data_error(f, limits);
  EXPECT_NE(msg.find("exceeds the limit of 4096 bytes"), std::string::npos) << msg;
}

TEST(HostileData, CsvBeyondTheRowLimitIsRefusedAtThatRow) {
  const Folder f = one_sensor_run("data_rows", 2000);
  io::MeasuredReadLimits limits;
  limits.max_rows = 100;
  const std::string msg = data_error(f, limits);
  EXPECT_NE(msg.find("more than 100 rows"), std::string::npos) << msg;
  EXPECT_NE(msg.find(":102"), std::string::npos) << msg;  // header is line 1, row 101 is line 102
  limits.max_rows = 2000;
  EXPECT_EQ(io::read_measured_run(f.dir, limits).time.size(), 2000);
}

TEST(HostileData, MetaJsonOrDataCsvThatIsAFolderIsADataErrorNamingIt) {
  const Folder f("hostile_folder_files");
  fs::create_directories(f.dir / "meta.json");
  f.write("data.csv", "time_s,speed_rpm,T0\n0,0,20\n");
  std::string msg = data_error(f);
  EXPECT_NE(msg.find((f.dir / "meta.json").string() + ": a folder"), std::string::npos) << msg;
  fs::remove(f.dir / "meta.json");
  f.write("meta.json", meta_with_sensors(1));
  fs::remove(f.dir / "data.csv");
  fs::create_directories(f.dir / "data.csv");
  msg = data_error(f);
  EXPECT_NE(msg.find((f.dir / "data.csv").string() + ": a folder"), std::string::npos) << msg;
}

TEST(HostileData, TheSameRunTwiceIsRefusedNamingIt) {
  const Folder a("hostile_twice_a"), b("hostile_twice_b");
  EXPECT_NO_THROW(io::require_distinct_runs({a.dir, b.dir}, "--data"));
  EXPECT_TRUE(io::same_run(a.dir, a.dir / "." / ""));
  EXPECT_FALSE(io::same_run(a.dir, b.dir));
  try {
    io::require_distinct_runs({a.dir, b.dir, a.dir / ".." / a.dir.filename()}, "--train");
    ADD_FAILURE() << "a run given twice was accepted";
  } catch (const core::DataError& e) {
    EXPECT_NE(std::string(e.what()).find("given twice as --train"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(a.dir.string()), std::string::npos) << e.what();
  }
}

TEST(FuzzRegressions, MeasuredDataReader) {
  const auto files = fuzz_regressions("measured");
  EXPECT_FALSE(files.empty());
  const fs::path dir = scratch("fuzz_measured");
  for (const auto& f : files) {
    // Same split and limits as fuzz/measured_data_fuzz.cpp.
    const std::string input = read_text(f), separator = "\n=====\n";
    const auto cut = input.find(separator);
    std::ofstream(dir / "meta.json", std::ios::binary) << input.substr(0, cut);
    std::ofstream(dir / "data.csv", std::ios::binary)
        << (cut == std::string::npos ? std::string() : input.substr(cut + separator.size()));
    io::MeasuredReadLimits limits;
    limits.max_bytes = 64 * 1024;
    limits.max_rows = 500;
    if (input.size() % 2 == 0)
      limits.machine_box =
          Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1));
    EXPECT_EQ(escaped([&] { io::read_measured_run(dir, limits); }), "") << f;
  }
}

}  // namespace
}  // namespace tt::reliability_test
