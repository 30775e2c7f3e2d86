// fit.json, the section 8 record and the compensation CSV, read back.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "io/fitting_out.hpp"
#include "tests/fitting/synthetic.hpp"

using namespace tt::fitting;
using tt::fitting::test::campaign;
using tt::fitting::test::increment;
namespace fs = std::filesystem;

namespace {

constexpr double um = 1e-6;

std::string text_of(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Fixture {
  std::vector<Group> groups;
  std::vector<Evaluation> evaluations;
  SensorCountTable table;
};

Fixture fixture() {
  auto truth = [](const Group& g) {
    return Eigen::VectorXd(2.0 * um * increment(g, 0).array() - um * increment(g, 2).array());
  };
  Fixture f;
  f.groups = campaign(5, 81, truth, 0.3 * um, 4);
  const Split split{{0, 1}, {2}, {3, 4}};
  std::vector<ModelSpec> specs(2);
  specs[1].kind = ModelKind::projection_pursuit;
  specs[1].ppr.max_terms = 1;
  specs[1].ppr.directions = 50;
  const std::vector<SensorSet> sets{{"correlation", {0}}, {"correlation", {0, 2}}};
  f.evaluations = evaluations(f.groups, split, sets, specs);
  f.table = sensor_count_table(f.groups, split, 0, sets, specs, 0.5 * um);
  return f;
}

}  // namespace

TEST(FittingOut, FitJsonHoldsEveryCandidateAndTheTestedChoice) {
  const Fixture f = fixture();
  const fs::path dir = fs::path(TT_BINARY_DIR) / "test_fitting_out";
  fs::create_directories(dir);
  tt::io::write_fit_json(dir / "fit.json", f.evaluations, {f.table});
  EXPECT_FALSE(fs::exists(dir / "fit.json.tmp"));
  const auto j = nlohmann::json::parse(text_of(dir / "fit.json"));
  ASSERT_EQ(j["targets"].size(), 1u);
  const auto& t = j["targets"][0];
  EXPECT_EQ(t["target"], "z");
  EXPECT_EQ(t["groups"]["fitting"], (std::vector<std::string>{"run0", "run1"}));
  EXPECT_EQ(t["groups"]["validation"], (std::vector<std::string>{"run2"}));
  EXPECT_EQ(t["groups"]["test"], (std::vector<std::string>{"run3", "run4"}));
  ASSERT_EQ(t["candidates"].size(), 4u);
  EXPECT_EQ(t["candidates"][3]["kind"], "projection_pursuit");
  EXPECT_TRUE(t["candidates"][3]["coefficients"].contains("ridge_functions"));
  const Evaluation& e = f.evaluations[0];
  EXPECT_NEAR(t["chosen"]["test"]["SM_um"].get<double>(), e.test.sm / um, 1e-9);
  EXPECT_NEAR(t["chosen"]["test"]["S_um"]["run4"].get<double>(), e.test.s[1] / um, 1e-9);
  EXPECT_EQ(t["chosen"]["m"], 2);
  if (e.model.spec.kind == ModelKind::least_squares) {
    const auto& terms = t["chosen"]["coefficients"]["terms"];
    EXPECT_EQ(terms[0]["name"], "dT[t1]");
    EXPECT_NEAR(terms[0]["um_per_K"].get<double>(), 2.0, 0.05);
  }
  EXPECT_TRUE(t["candidates"][0]["validation"]["S_sigma_um"].is_null());  // one validation group
  EXPECT_EQ(j["sensor_count"][0]["smallest_m_by_validation"]["correlation"], 2);
}

TEST(FittingOut, ModellingRecordStatesSection8) {
  const Fixture f = fixture();
  tt::io::ModellingConditions c;
  c.machine_model = "SB-1 virtual";
  c.machine_number = "0001";
  c.travel_x = 0.8;
  c.travel_y = 0.5;
  c.travel_z = 0.5;
  c.modelling_date = "2026-11-21";
  c.initial_ambient_temperature = 293.15;
  c.max_spindle_speed = 12000.0 * 2.0 * std::numbers::pi / 60.0;
  c.max_feed_rate = 30.0 / 60.0;
  const fs::path dir = fs::path(TT_BINARY_DIR) / "test_fitting_out";
  fs::create_directories(dir);
  tt::io::write_modelling_record(dir / "record.json", dir / "record.md", c, f.evaluations);
  const auto j = nlohmann::json::parse(text_of(dir / "record.json"));
  EXPECT_EQ(j["machine"]["model"], "SB-1 virtual");
  EXPECT_NEAR(j["machine"]["travel_mm"]["x"].get<double>(), 800.0, 1e-9);
  EXPECT_NEAR(j["initial_ambient_temperature_degC"].get<double>(), 20.0, 1e-9);
  EXPECT_NEAR(j["max_spindle_speed_rpm"].get<double>(), 12000.0, 1e-6);
  EXPECT_NEAR(j["max_feed_rate_mm_per_min"].get<double>(), 30000.0, 1e-6);
  EXPECT_EQ(j["modelling_date"], "2026-11-21");
  EXPECT_FALSE(j.contains("cutting"));
  ASSERT_EQ(j["models"].size(), 1u);
  const std::string md = text_of(dir / "record.md");
  EXPECT_NE(md.find("| machine model | SB-1 virtual |"), std::string::npos);
  EXPECT_NE(md.find("## Target z"), std::string::npos);
  EXPECT_NE(md.find("S_M ="), std::string::npos);
}

TEST(FittingOut, ModellingDateIsTodayOrTheSourceDateEpoch) {
  ::setenv("SOURCE_DATE_EPOCH", "1795651200", 1);  // 2026-11-26 00:00:00 UTC
  EXPECT_EQ(tt::io::modelling_date_today(), "2026-11-26");
  ::unsetenv("SOURCE_DATE_EPOCH");
  const std::string today = tt::io::modelling_date_today();
  ASSERT_EQ(today.size(), 10u);
  EXPECT_EQ(today[4], '-');
  EXPECT_GE(today, std::string("2026-11-26"));
}

TEST(FittingOut, CompensationCsvIsMinusThePrediction) {
  const Fixture f = fixture();
  const FittedModel& model = f.evaluations[0].model;
  const std::string csv = tt::io::compensation_csv({model}, f.groups);
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line,
            "group,time_s,target,measured_um,predicted_um,compensation_um,"
            "residual_after_compensation_um");
  std::size_t rows = 0;
  double sum_squares = 0.0;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string group, time, target, measured, predicted, compensation, residual;
    std::getline(fields, group, ',');
    std::getline(fields, time, ',');
    std::getline(fields, target, ',');
    std::getline(fields, measured, ',');
    std::getline(fields, predicted, ',');
    std::getline(fields, compensation, ',');
    std::getline(fields, residual, ',');
    EXPECT_NEAR(std::stod(compensation), -std::stod(predicted), 1e-9);
    EXPECT_NEAR(std::stod(residual), std::stod(measured) + std::stod(compensation), 1e-6);
    sum_squares += std::stod(residual) * std::stod(residual);
    ++rows;
  }
  std::size_t samples = 0;
  for (const auto& g : f.groups) samples += static_cast<std::size_t>(g.time.size());
  EXPECT_EQ(rows, samples);
  EXPECT_LT(std::sqrt(sum_squares / static_cast<double>(rows)), 0.5);  // µm, close to the noise
  const fs::path dir = fs::path(TT_BINARY_DIR) / "test_fitting_out";
  fs::create_directories(dir);
  tt::io::write_compensation_csv(dir / "compensation.csv", {model}, f.groups);
  EXPECT_EQ(text_of(dir / "compensation.csv"), csv);
}
