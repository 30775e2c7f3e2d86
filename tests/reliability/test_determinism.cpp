// The same case gives bit for bit the same temperatures and displacements with 1 and 2 OpenMP
// threads and on a repeated run (BLAS pinned to one thread). The mesh has more than 50 000 tets so
// that the parallel element loops really split: assembly concatenates per-chunk results in a
// fixed order whatever the thread count.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/common/case_toml.hpp"
#include "tests/reliability/process.hpp"

namespace tt::reliability_test {
namespace {

// A heated steel bar on a fixed base: order 1, max_edge small enough for > 50 000 tets, ten steps.
const std::string kBarCase =
    test_toml::header("determinism bar", "seed = 7\n") + test_toml::steel() +
    test_toml::box_body("bar", "steel", "0.009", "[0.0, 0.0, 0.0]", "[0.24, 0.1, 0.1]") +
    test_toml::box_body("heater", "steel", "0.009", "[0.24, 0.0, 0.0]", "[0.28, 0.1, 0.1]") +
    R"(
[mesh]
order = 1

[[boundary]]
name = "base"
select = [ { bodies = ["bar"], plane = { normal = [-1.0, 0.0, 0.0], offset = 0.0 } } ]

[[boundary]]
name = "rest"
rest = true
select = [ { bodies = ["bar", "heater"] } ]

[thermal]
initial_temperature_degC = 20.0
scheme = "crank_nicolson"
step_s = 30.0
output_interval_s = 60.0

[[thermal.convection]]
group = "rest"
h_W_m2K = 12.0
sink_degC = 20.0

[[thermal.heat_sources]]
name = "heater"
body = "heater"
law = "speed_power"
power_ref_W = 150.0
ref_speed_rpm = 3000.0
exponent = 1.0

[duty_cycle]
end_s = 300.0
segments = [ { start_s = 0.0, speed_rpm = 3000.0 }, { start_s = 150.0, speed_rpm = 1500.0 } ]

[mechanical]
enabled = true
reference_temperature_degC = 20.0
fixed = ["base"]

[outputs]
fields = false
)";

TEST(Determinism, OneAndTwoThreadsAndRepeatedRunsAgreeBitForBit) {
  const fs::path dir = scratch("determinism");
  const fs::path case_file = dir / "bar.toml";
  std::ofstream(case_file) << kBarCase;
  const auto run_with = [&](const std::string& name, int threads) {
    const fs::path out = dir / name;
    const int rc = run({"run", case_file.string(), "--out", out.string(), "--quiet", "--dump",
                        (dir / (name + ".bin")).string()},
                       {"OMP_NUM_THREADS=" + std::to_string(threads), "TT_BLAS_THREADS=1"},
                       dir / (name + ".log"));
    EXPECT_EQ(rc, 0) << read_text(dir / (name + ".log"));
    return out;
  };
  const fs::path one = run_with("omp1", 1);
  run_with("omp2", 2);
  run_with("omp2_again", 2);

  const auto summary = nlohmann::json::parse(read_text(one / "summary.json"));
  EXPECT_GE(summary.at("tets").get<long>(), 50000)
      << "the mesh must be large enough to split loops";

  const std::string a = read_text(dir / "omp1.bin");
  ASSERT_GT(a.size(), 1000000u);
  ASSERT_EQ(read_dump(dir / "omp1.bin").size(), 2u);  // temperatures and displacements
  EXPECT_TRUE(a == read_text(dir / "omp2.bin")) << "1 and 2 threads differ";
  EXPECT_TRUE(a == read_text(dir / "omp2_again.bin")) << "two runs with 2 threads differ";
  EXPECT_EQ(read_text(one / "temperatures.csv"), read_text(dir / "omp2" / "temperatures.csv"));
}

}  // namespace
}  // namespace tt::reliability_test
