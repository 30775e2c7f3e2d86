// The measured-data reader and writer (docs/measured-data.md): every rejection the format lists,
// with the file, line and column (or JSON key) in the message; missing readings kept as NaN;
// units converted to SI; the shipped fl-thermal-measured data set read whole.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/errors.hpp"
#include "io/measured_data.hpp"

namespace fs = std::filesystem;
using tt::io::MeasuredReadLimits;
using tt::io::read_measured_run;

namespace {

const char* kMeta = R"({
  "format": "thermal-measurement/1",
  "machine": "SB-1",
  "run": "unit test",
  "time_unit": "s",
  "temperature_unit": "degC",
  "displacement_unit": "um",
  "sensors": [ {"id": "T07", "position": [-0.08, 0.30, 0.20]}, {"id": "T10", "position": null} ],
  "displacements": [ {"id": "dy", "point": [0.0, 0.18, 0.58], "direction": [0, 2, 0]} ],
  "inputs": [ {"id": "speed_rpm", "unit": "rpm"} ],
  "initial_temperature_degC": 20.0,
  "nominal_ambient_degC": null,
  "provenance": {"operator": "test", "notes": ["kept"]}
})";

const char* kCsv =
    "time_s,speed_rpm,T07,dy,T10\n"
    "0,0,20.0,0.0,21\n"
    "60,2000,20.5,1.5,\n"
    "120,2000,21.0,,21.5\n";

MeasuredReadLimits sb1_box() {
  MeasuredReadLimits limits;
  limits.machine_box =
      Eigen::AlignedBox3d(Eigen::Vector3d(-0.16, 0.0, -0.04), Eigen::Vector3d(0.16, 0.30, 0.58));
  return limits;
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

class Measured : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(TT_BINARY_DIR) / "test_measured" /
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  /// Writes meta.json and data.csv and returns the message of the DataError the read throws.
  std::string rejection(const std::string& meta, const std::string& csv,
                        const MeasuredReadLimits& limits = sb1_box()) {
    write_text(dir_ / "meta.json", meta);
    write_text(dir_ / "data.csv", csv);
    try {
      read_measured_run(dir_, limits);
    } catch (const tt::core::DataError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no DataError for\n" << meta << "\n" << csv;
    return {};
  }
  fs::path dir_;
};

TEST_F(Measured, ReadsUnitsInSiAndKeepsMissingAsNan) {
  write_text(dir_ / "meta.json", kMeta);
  write_text(dir_ / "data.csv", kCsv);
  const auto run = read_measured_run(dir_, sb1_box());
  ASSERT_EQ(run.time.size(), 3);
  EXPECT_EQ(run.machine, "SB-1");
  EXPECT_EQ(run.run, "unit test");
  ASSERT_EQ(run.sensors.size(), 2u);
  EXPECT_FALSE(run.sensors[1].position.has_value());
  EXPECT_DOUBLE_EQ((*run.sensors[0].position)(1), 0.30);
  EXPECT_DOUBLE_EQ((*run.displacements[0].direction)(1), 1.0);  // normalised
  EXPECT_EQ(run.inputs, std::vector<std::string>{"speed_rpm"});
  EXPECT_DOUBLE_EQ(run.input_values(1, 0), 2000.0);
  EXPECT_DOUBLE_EQ(run.temperature(1, 0), 20.5 + 273.15);  // columns follow meta.json, not the file
  EXPECT_DOUBLE_EQ(run.temperature(0, 1), 21.0 + 273.15);
  EXPECT_TRUE(std::isnan(run.temperature(1, 1)));  // missing, never zero
  EXPECT_NEAR(run.displacement(1, 0), 1.5e-6, 1e-18);
  EXPECT_TRUE(std::isnan(run.displacement(2, 0)));
  EXPECT_EQ(run.initial_temperature_c, 20.0);
  EXPECT_FALSE(run.nominal_ambient_c.has_value());
  EXPECT_EQ(run.meta["provenance"]["notes"][0], "kept");
}

TEST_F(Measured, WriteThenReadGivesTheSameRun) {
  write_text(dir_ / "meta.json", kMeta);
  write_text(dir_ / "data.csv", kCsv);
  const auto run = read_measured_run(dir_, sb1_box());
  const fs::path copy = dir_ / "copy";
  tt::io::write_measured_run(copy, run);
  const auto back = read_measured_run(copy, sb1_box());
  EXPECT_EQ(back.time, run.time);
  EXPECT_EQ(back.input_values, run.input_values);
  for (Eigen::Index i = 0; i < run.temperature.size(); ++i) {
    const double a = run.temperature(i), b = back.temperature(i);
    EXPECT_TRUE((std::isnan(a) && std::isnan(b)) || std::abs(a - b) < 1e-12) << i;
  }
  EXPECT_TRUE(std::isnan(back.displacement(2, 0)));
  EXPECT_NEAR(back.displacement(1, 0), 1.5e-6, 1e-18);
  EXPECT_EQ(back.meta["provenance"], run.meta["provenance"]);
  EXPECT_FALSE(back.sensors[1].position.has_value());
  EXPECT_EQ(back.initial_temperature_c, run.initial_temperature_c);
}

TEST_F(Measured, RejectsMissingColumn) {
  const auto m = rejection(kMeta, "time_s,speed_rpm,T07,dy\n0,0,20,0\n");
  EXPECT_NE(m.find("data.csv:1:"), std::string::npos) << m;
  EXPECT_NE(m.find("missing column 'T10'"), std::string::npos) << m;
}

TEST_F(Measured, RejectsDuplicatedColumn) {
  const auto m = rejection(kMeta, "time_s,speed_rpm,T07,dy,T10,T07\n0,0,20,0,21,20\n");
  EXPECT_NE(m.find("data.csv:1: column 6 'T07': duplicated column (also column 3)"),
            std::string::npos)
      << m;
}

TEST_F(Measured, RejectsUnknownColumn) {
  const auto m = rejection(kMeta, "time_s,speed_rpm,T07,dy,T10,T99\n0,0,20,0,21,20\n");
  EXPECT_NE(m.find("data.csv:1: column 6 'T99': unknown column"), std::string::npos) << m;
}

TEST_F(Measured, RejectsTimeNotFirst) {
  const auto m = rejection(kMeta, "speed_rpm,time_s,T07,dy,T10\n0,0,20,0,21\n");
  EXPECT_NE(m.find("data.csv:1: column 1 'speed_rpm': the first column must be time_s"),
            std::string::npos)
      << m;
}

TEST_F(Measured, RejectsTimeThatDoesNotIncrease) {
  auto m = rejection(kMeta, replaced(kCsv, "120,2000", "60,2000"));
  EXPECT_NE(m.find("data.csv:4: column 1 'time_s': time 60 s does not increase"), std::string::npos)
      << m;
  m = rejection(kMeta, replaced(kCsv, "120,2000", "30,2000"));
  EXPECT_NE(m.find("data.csv:4:"), std::string::npos) << m;
}

TEST_F(Measured, RejectsTextInANumberCell) {
  auto m = rejection(kMeta, replaced(kCsv, "20.5,1.5", "20.5,1.5um"));
  EXPECT_NE(m.find("data.csv:3: column 4 'dy': '1.5um' is not a number"), std::string::npos) << m;
  m = rejection(kMeta, replaced(kCsv, "20.5,1.5", "\"warm\",1.5"));  // quoted, still text
  EXPECT_NE(m.find("data.csv:3: column 3 'T07': 'warm' is not a number"), std::string::npos) << m;
}

TEST_F(Measured, RejectsNonFiniteNumbers) {
  for (const std::string bad : {"nan", "inf", "-inf", "1e999"}) {
    const auto m = rejection(kMeta, replaced(kCsv, "20.5,1.5", bad + ",1.5"));
    EXPECT_NE(m.find("data.csv:3: column 3 'T07':"), std::string::npos) << m;
    EXPECT_NE(m.find("not a"), std::string::npos) << m;
  }
}

TEST_F(Measured, RejectsEmptyTimeAndRaggedRows) {
  auto m = rejection(kMeta, replaced(kCsv, "60,2000", ",2000"));
  EXPECT_NE(m.find("data.csv:3: column 1 'time_s': empty time"), std::string::npos) << m;
  m = rejection(kMeta, replaced(kCsv, "120,2000,21.0,,21.5", "120,2000,21.0,"));
  EXPECT_NE(m.find("data.csv:4:"), std::string::npos) << m;
  EXPECT_NE(m.find("row has 4 cells: expected 5"), std::string::npos) << m;
  m = rejection(kMeta, replaced(kCsv, "120,2000,21.0,,21.5", "120,2000,21.0,,21.5,7"));
  EXPECT_NE(m.find("data.csv:4: column 6: more cells"), std::string::npos) << m;
}

TEST_F(Measured, RejectsPositionOutsideTheMachineBox) {
  auto m = rejection(replaced(kMeta, "[-0.08, 0.30, 0.20]", "[-0.08, 0.31, 0.20]"), kCsv);
  EXPECT_NE(m.find("meta.json: key sensors[0].position:"), std::string::npos) << m;
  EXPECT_NE(m.find("outside machine SB-1's bounding box"), std::string::npos) << m;
  m = rejection(replaced(kMeta, "[0.0, 0.18, 0.58]", "[0.0, 0.18, 0.60]"), kCsv);
  EXPECT_NE(m.find("key displacements[0].point:"), std::string::npos) << m;
  // Without a known machine the same position is accepted.
  write_text(dir_ / "meta.json", replaced(kMeta, "[-0.08, 0.30, 0.20]", "[-0.08, 0.31, 0.20]"));
  write_text(dir_ / "data.csv", kCsv);
  EXPECT_NO_THROW(read_measured_run(dir_));
}

TEST_F(Measured, TheMachineBoxCanComeWithTheData) {
  // meta.json's machine_box_m checks the positions as a caller's box does, and is written back.
  const std::string boxed =
      replaced(kMeta, "\"run\": \"unit test\",",
               "\"run\": \"unit test\", \"machine_box_m\": {\"min\": [-0.16, 0.0, -0.04], "
               "\"max\": [0.16, 0.30, 0.58]},");
  auto m = rejection(replaced(boxed, "[-0.08, 0.30, 0.20]", "[-0.08, 0.31, 0.20]"), kCsv, {});
  EXPECT_NE(m.find("key sensors[0].position:"), std::string::npos) << m;
  EXPECT_NE(m.find("outside machine SB-1's bounding box"), std::string::npos) << m;
  write_text(dir_ / "meta.json", boxed);
  write_text(dir_ / "data.csv", kCsv);
  const auto run = read_measured_run(dir_);
  ASSERT_TRUE(run.machine_box.has_value());
  EXPECT_DOUBLE_EQ(run.machine_box->max()(2), 0.58);
  const fs::path copy = dir_ / "copy";
  tt::io::write_measured_run(copy, run);
  const auto again = read_measured_run(copy);
  ASSERT_TRUE(again.machine_box.has_value());
  EXPECT_TRUE(again.machine_box->isApprox(*run.machine_box));
  // A box that is not one is refused, naming the key.
  m = rejection(replaced(boxed, "\"max\": [0.16, 0.30, 0.58]", "\"max\": [0.16, -0.30, 0.58]"),
                kCsv, {});
  EXPECT_NE(m.find("key machine_box_m:"), std::string::npos) << m;
  m = rejection(replaced(boxed, "\"min\": [-0.16, 0.0, -0.04]", "\"low\": 1"), kCsv, {});
  EXPECT_NE(m.find("key machine_box_m:"), std::string::npos) << m;
}

TEST_F(Measured, PublishedFigureIsReadAndChecked) {
  const std::string published =
      replaced(kMeta, "\"run\": \"unit test\",",
               "\"run\": \"unit test\", \"published\": {\"model\": \"GRU\", \"source\": \"paper\", "
               "\"test_window_s\": [60, 120], \"mae_um\": {\"dy\": 3.5}, "
               "\"others_mae_um\": {\"forest\": {\"dy\": 6.0}}},");
  write_text(dir_ / "meta.json", published);
  write_text(dir_ / "data.csv", kCsv);
  const auto run = read_measured_run(dir_);
  ASSERT_TRUE(run.published.has_value());
  EXPECT_EQ(run.published->model, "GRU");
  EXPECT_DOUBLE_EQ(run.published->from_s, 60.0);
  EXPECT_DOUBLE_EQ(run.published->to_s, 120.0);
  EXPECT_DOUBLE_EQ(run.published->mae_um.at("dy"), 3.5);
  EXPECT_DOUBLE_EQ(run.published->others_mae_um.at("forest").at("dy"), 6.0);
  auto m = rejection(replaced(published, "{\"dy\": 3.5}", "{\"dz\": 3.5}"), kCsv);
  EXPECT_NE(m.find("key published.mae_um.dz: 'dz' is not the id of a displacement"),
            std::string::npos)
      << m;
  m = rejection(replaced(published, "[60, 120]", "[120, 60]"), kCsv);
  EXPECT_NE(m.find("key published.test_window_s:"), std::string::npos) << m;
  m = rejection(replaced(published, "\"model\": \"GRU\", ", ""), kCsv);
  EXPECT_NE(m.find("published.model"), std::string::npos) << m;
}

TEST_F(Measured, RejectsUnknownUnits) {
  auto m = rejection(replaced(kMeta, R"("temperature_unit": "degC")", R"("temperature_unit": "K")"),
                     kCsv);
  EXPECT_NE(m.find("meta.json: key temperature_unit: unknown unit 'K'"), std::string::npos) << m;
  m = rejection(replaced(kMeta, R"("displacement_unit": "um")", R"("displacement_unit": "mm")"),
                kCsv);
  EXPECT_NE(m.find("key displacement_unit: unknown unit 'mm'"), std::string::npos) << m;
  m = rejection(replaced(kMeta, R"("time_unit": "s")", R"("time_unit": "min")"), kCsv);
  EXPECT_NE(m.find("key time_unit: unknown unit 'min'"), std::string::npos) << m;
  m = rejection(replaced(kMeta, R"("unit": "rpm")", R"("unit": "rad/s")"), kCsv);
  EXPECT_NE(m.find("key inputs[0].unit: unknown unit 'rad/s'"), std::string::npos) << m;
}

TEST_F(Measured, RejectsUnknownFormat) {
  const auto m = rejection(replaced(kMeta, "thermal-measurement/1", "thermal-measurement/2"), kCsv);
  EXPECT_NE(m.find("meta.json: key format: unknown format 'thermal-measurement/2'"),
            std::string::npos)
      << m;
}

TEST_F(Measured, RejectsBadMetaKeys) {
  auto m = rejection(replaced(kMeta, R"("id": "T10")", R"("id": "T07")"), kCsv);
  EXPECT_NE(m.find("key sensors[1].id: id 'T07' is used twice"), std::string::npos) << m;
  m = rejection(replaced(kMeta, R"("position": null)", R"("position": [1, 2])"), kCsv);
  EXPECT_NE(m.find("key sensors[1].position:"), std::string::npos) << m;
  m = rejection(replaced(kMeta, R"("machine": "SB-1",)", ""), kCsv);
  EXPECT_NE(m.find("key machine: missing"), std::string::npos) << m;
  m = rejection(
      replaced(kMeta, R"("run": "unit test",)", R"("run": "x", "ambient_sensor": "T99",)"), kCsv);
  EXPECT_NE(m.find("key ambient_sensor: 'T99' is not the id of one of sensors"), std::string::npos)
      << m;
  m = rejection(
      replaced(kMeta, "\"nominal_ambient_degC\": null", "\"nominal_ambient_degC\": \"warm\""),
      kCsv);
  EXPECT_NE(m.find("key nominal_ambient_degC:"), std::string::npos) << m;
  m = rejection(replaced(kMeta, R"("machine": "SB-1",)", R"("machine": "SB-1",,)"), kCsv);
  EXPECT_NE(m.find("meta.json: not valid JSON"), std::string::npos) << m;
}

TEST_F(Measured, RejectsFilesBeyondTheSizeAndRowLimits) {
  MeasuredReadLimits limits = sb1_box();
  limits.max_bytes = 40;
  auto m = rejection(kMeta, kCsv, limits);
  EXPECT_NE(m.find("data.csv: file size"), std::string::npos) << m;
  EXPECT_NE(m.find("exceeds the limit of 40 bytes"), std::string::npos) << m;
  limits = sb1_box();
  limits.max_rows = 2;
  m = rejection(kMeta, kCsv, limits);
  EXPECT_NE(m.find("data.csv:4: more than 2 rows"), std::string::npos) << m;
  limits.max_rows = 3;
  write_text(dir_ / "data.csv", kCsv);
  EXPECT_NO_THROW(read_measured_run(dir_, limits));
}

TEST_F(Measured, MissingFilesAreIoErrors) {
  EXPECT_THROW(read_measured_run(dir_ / "nowhere"), tt::core::IoError);
  write_text(dir_ / "meta.json", kMeta);
  EXPECT_THROW(read_measured_run(dir_), tt::core::IoError);
}

TEST_F(Measured, AcceptsCrlfBomBlankLinesUnevenStepsAndQuotedFields) {
  // A spreadsheet's export quotes names and numbers alike; "" is an empty cell (missing).
  write_text(dir_ / "meta.json", kMeta);
  write_text(dir_ / "data.csv",
             "\xEF\xBB\xBF\"time_s\", speed_rpm "
             ",\"T07\",dy,T10\r\n0,0,\"20.5\",0,21\r\n\r\n0.5,+10,20,\"\",21\r\n"
             "7,10,20,\" -1e0 \",21");
  const auto run = read_measured_run(dir_, sb1_box());
  ASSERT_EQ(run.time.size(), 3);
  EXPECT_DOUBLE_EQ(run.time(2), 7.0);
  EXPECT_DOUBLE_EQ(run.temperature(0, 0), 20.5 + 273.15);
  EXPECT_DOUBLE_EQ(run.input_values(1, 0), 10.0);
  EXPECT_TRUE(std::isnan(run.displacement(1, 0)));
  EXPECT_NEAR(run.displacement(2, 0), -1e-6, 1e-20);
}

/// The shipped data set: 11115 rows of 23 columns, 46.3 h, null positions.
TEST(MeasuredShipped, ReadsFlThermalMeasured) {
  const fs::path folder = fs::path(TT_SOURCE_DIR) / "data" / "fl-thermal-measured";
  const auto start = std::chrono::steady_clock::now();
  const auto run = read_measured_run(folder);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(run.time.size(), 11115);
  EXPECT_EQ(run.sensors.size(), 16u);
  EXPECT_EQ(run.displacements.size(), 5u);
  EXPECT_DOUBLE_EQ(run.time(run.time.size() - 1), 166710.0);
  EXPECT_FALSE(run.initial_temperature_c.has_value());
  EXPECT_TRUE(run.meta.contains("source"));
  ASSERT_TRUE(run.published.has_value());  // the published figure lives with the data
  EXPECT_DOUBLE_EQ(run.published->mae_um.at("ch5"), 4.284);
  EXPECT_GT(run.temperature.minCoeff(), 273.15 + 15.0);
  EXPECT_LT(run.temperature.maxCoeff(), 273.15 + 50.0);
  EXPECT_LT(run.displacement.cwiseAbs().maxCoeff(), 200e-6);
  EXPECT_LT(seconds, 5.0);
  std::cout << "fl-thermal-measured read in " << seconds * 1e3 << " ms\n";
}

}  // namespace
