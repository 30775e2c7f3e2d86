// Hostile numbers in case files: each gets a clear typed error naming the value. NaN and
// infinities, a time step longer than the run, zero conductivity, a heat source on a region with
// no elements. Measured data: test_hostile_data.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/errors.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"
#include "solvers/thermal.hpp"
#include "tests/common/case_toml.hpp"

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

// bdf2 used to be read and refused only by the stepper, after meshing: a scheme the solver cannot
// run is refused when the case is read, naming the file, the key and the value.
TEST(HostileCase, SchemeTheSolverCannotRunIsRefusedWhenRead) {
  const std::string msg =
      case_error(coarse_with("scheme = \"backward_euler\"", "scheme = \"bdf2\""));
  EXPECT_NE(msg.find("sb1_coarse.toml"), std::string::npos) << msg;
  EXPECT_NE(msg.find("thermal.scheme = \"bdf2\""), std::string::npos) << msg;
  EXPECT_NE(msg.find("'backward_euler', 'crank_nicolson'"), std::string::npos) << msg;
  EXPECT_EQ(case_error(coarse_with("scheme = \"backward_euler\"", "scheme = \"crank_nicolson\"")),
            "");
}

TEST(HostileCase, HeatSourceOnARegionWithoutElementsIsRefused) {
  // Two boxes, the source on the second; then every tet is given to the first, as a mesh that
  // lost a thin body would be.
  const std::string text =
      test_toml::header("empty region") + test_toml::steel() +
      test_toml::box_body("block", "steel", "0.05", "[0.0, 0.0, 0.0]", "[0.1, 0.1, 0.1]") +
      test_toml::box_body("pad", "steel", "0.05", "[0.1, 0.0, 0.0]", "[0.15, 0.1, 0.1]") +
      R"(
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
    solvers::thermal_system(m, spec);
    ADD_FAILURE() << "a source on a body with no elements was accepted";
  } catch (const core::SolverError& e) {
    EXPECT_NE(std::string(e.what()).find("pad heat"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no elements"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tt::reliability_test
