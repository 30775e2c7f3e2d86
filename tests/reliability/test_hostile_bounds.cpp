// Issue 14, items 4 and 5: no wrong number with exit 0, no size without a bound, meshing within
// bounds. Each input here once ran on: a time step whose count overflowed an int (5 steps, exit
// 0), a heat source of 1e308 W (NaN written as a result), campaigns and meshes that grew until
// memory ran out, TetGen runs that never finished.
#include <gtest/gtest.h>

#include <string>

#include "core/errors.hpp"
#include "io/case_reader.hpp"
#include "mesh/extrusion.hpp"
#include "mesh/mesher.hpp"
#include "solvers/campaign.hpp"
#include "solvers/loads.hpp"
#include "solvers/virtual_machine.hpp"
#include "tests/common/case_toml.hpp"

namespace tt::reliability_test {
namespace {

namespace fs = std::filesystem;

const fs::path kCases = fs::path(TT_SOURCE_DIR) / "cases";

core::CaseSpec coarse() {
  return io::read_case(kCases / "sb1_coarse.toml");
}

/// The message of the error of type E that `f` throws ("" when none).
template <class E, class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return "";
}

TEST(HostileBounds, TimeStepCountBeyondTheLimitIsRefusedNotWrapped) {
  core::CaseSpec spec = coarse();
  spec.thermal.step = 1e-7;  // 7.2e10 steps: once cast to int, it gave 5 steps
  const std::string msg =
      error_of<core::SolverError>([&] { solvers::time_grid(spec, spec.thermal.step); });
  EXPECT_NE(msg.find("thermal.step_s"), std::string::npos) << msg;
  EXPECT_NE(msg.find("5000000"), std::string::npos) << msg;
}

TEST(HostileBounds, OutputTimeCountBeyondTheLimitIsRefused) {
  core::CaseSpec spec = coarse();
  spec.thermal.output_interval = 1e-300;
  const std::string msg = error_of<core::SolverError>([&] { solvers::output_times(spec); });
  EXPECT_NE(msg.find("thermal.output_interval_s"), std::string::npos) << msg;
  EXPECT_NE(msg.find("200000"), std::string::npos) << msg;
}

TEST(HostileBounds, CampaignOfABillionHoursIsRefusedBeforeAllocating) {
  const core::CaseSpec spec = coarse();
  const std::string msg = error_of<core::CaseError>([&] { solvers::campaign_runs(spec, 1e9, 1); });
  EXPECT_NE(msg.find("--hours"), std::string::npos) << msg;
  EXPECT_NE(msg.find("time steps"), std::string::npos) << msg;
}

/// A 10 cm steel cube on a cold base, heated by a constant source of `power` W.
std::string cube_case(const std::string& power) {
  return test_toml::header("overflow") + test_toml::steel() +
         test_toml::box_body("block", "steel", "0.05", "[0.0, 0.0, 0.0]", "[0.1, 0.1, 0.1]") +
         R"(
[mesh]
order = 1
[[boundary]]
name = "base"
select = [ { plane = { normal = [0.0, 0.0, 1.0], offset = 0.0 } } ]
[[boundary]]
name = "rest"
rest = true
select = [ {} ]
[thermal]
step_s = 10.0
output_interval_s = 10.0
[[thermal.convection]]
group = "rest"
h_W_m2K = 10.0
sink_degC = 20.0
[[thermal.heat_sources]]
name = "runaway"
body = "block"
law = "constant"
power_ref_W = )" +
         power + R"(
[duty_cycle]
end_s = 30.0
segments = [ { start_s = 0.0, speed_rpm = 0.0 } ]
[mechanical]
fixed = ["base"]
)";
}

TEST(HostileBounds, HeatBeyondADoubleIsASolverErrorNotANaN) {
  const core::CaseSpec sane = io::case_from_toml(cube_case("100.0"), "cube.toml");
  const mesh::TetMesh m = mesh::mesh_case(sane);
  EXPECT_NO_THROW(solvers::simulate(m, sane));
  const core::CaseSpec spec = io::case_from_toml(cube_case("1e308"), "cube.toml");
  const std::string msg = error_of<core::SolverError>([&] { solvers::simulate(m, spec); });
  EXPECT_NE(msg.find("not finite"), std::string::npos) << msg;
  EXPECT_NE(msg.find("cube.toml"), std::string::npos) << msg;
  EXPECT_NE(msg.find("nothing is written"), std::string::npos) << msg;
}

TEST(HostileBounds, AMeshFarBeyondMaxTetsIsRefusedBeforeTetGen) {
  core::CaseSpec spec = coarse();
  for (auto& b : spec.bodies) b.max_edge = 0.0005;  // reached 7.8 GB in 4 minutes
  const std::string msg = error_of<core::MeshError>([&] { mesh::mesh_case(spec); });
  EXPECT_NE(msg.find("mesh.max_tets = 5e+06"), std::string::npos) << msg;
  EXPECT_NE(msg.find("max_edge"), std::string::npos) << msg;
}

TEST(HostileBounds, AHundredThousandCircleSegmentsAreRefusedBeforeTetGen) {
  core::CaseSpec spec = coarse();
  spec.mesh.circle_segments = 100000;  // did not finish in 300 s
  const std::string msg = error_of<core::MeshError>([&] { mesh::mesh_case(spec); });
  EXPECT_NE(msg.find("mesh.max_tets"), std::string::npos) << msg;
  EXPECT_NE(msg.find("circle_segments = 100000"), std::string::npos) << msg;
}

TEST(HostileBounds, EveryShippedCaseIsWithinTheDefaultMeshEstimate) {
  for (const char* name :
       {"sb1_coarse.toml", "sb1.toml", "sb1_refined.toml", "gm1_coarse.toml", "gm1.toml"}) {
    const core::CaseSpec spec = io::read_case(kCases / name);
    const mesh::MeshEstimate e = mesh::mesh_estimate(spec, mesh::extruded_plc(spec).plc);
    EXPECT_LT(e.tets(), spec.mesh.max_tets / 4) << name;
    RecordProperty(name, std::to_string(e.tets()));
  }
}

TEST(HostileBounds, TetGenIsEndedAtTheTimeLimit) {
  core::CaseSpec spec = io::read_case(kCases / "sb1.toml");  // several seconds of TetGen
  spec.mesh.time_limit_s = 0.3;
  const std::string msg = error_of<core::MeshError>([&] { mesh::mesh_case(spec); });
  EXPECT_NE(msg.find("mesh.time_limit_s = 0.3"), std::string::npos) << msg;
}

}  // namespace
}  // namespace tt::reliability_test
