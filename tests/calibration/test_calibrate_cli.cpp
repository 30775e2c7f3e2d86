// `thermotwin calibrate --case` end to end (issue 15: the candidates marched on a reduced model
// by default): runs made by the generator on its own finer mesh with an undeclared heat input
// that follows the speed, two for training and one for testing; the command claims a heat input
// near the true place, lowers the test run's displacement RMS, says which model it marched and
// writes every file; a run folder given as --out is refused before any work.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "calibration/generator.hpp"
#include "core/rng.hpp"
#include "io/case_reader.hpp"
#include "io/measured_data.hpp"
#include "mesh/mesher.hpp"
#include "tests/common/calibration_json.hpp"
#include "tests/common/output_schema.hpp"
#include "tests/reliability/process.hpp"

namespace tt::calibration {
namespace {

namespace rt = reliability_test;
namespace fs = std::filesystem;

TEST(CalibrateCli, ReducedModelFindsAnUndeclaredHeatInput) {
  const fs::path dir = rt::scratch("calibrate_cli");
  const core::CaseSpec declared = io::read_case(rt::kCoarseCase);
  // The generator: finer than the declared mesh, but at 20 s steps to keep the test short.
  GeneratorOptions gopt;
  gopt.step_s = 20;
  const core::CaseSpec gen = generator_case(declared, gopt);
  const mesh::TetMesh gen_mesh = mesh::mesh_case(gen);
  Instrumentation inst;
  inst.sensor_points = {"T02", "T05", "T08", "T11", "T14", "T17", "T19", "T23",
                        "T27", "T31", "T35", "T40", "T44", "T48", "T52", "T54"};
  std::mt19937_64 rng = core::generator(20261125, 1);
  InjectedEffect effect =
      random_effect(EffectKind::heat_input, declared, gen_mesh, inst.sensor_points, rng);
  std::vector<std::string> runs;
  const double hours[] = {2, 3, 3};
  std::optional<TruthMachine> machine;  // one for the three runs (same effect, other duties)
  for (int k = 0; k < 3; ++k) {
    const core::DutyCycle duty = random_duty_cycle(hours[k], rng);
    const core::CaseSpec truth = truth_case(gen, effect, duty, k);
    const io::MeasuredRun run =
        with_noise(clean_run(machine_for(machine, gen_mesh, truth, inst), truth, {effect}, gopt,
                             "run " + std::to_string(k)),
                   gopt, rng);
    runs.push_back((dir / ("run_" + std::to_string(k))).string());
    io::write_measured_run(runs.back(), run);
  }
  const fs::path out = dir / "out", log = dir / "calibrate.log";
  ASSERT_EQ(rt::run({"calibrate", "--case", rt::kCoarseCase.string(), "--train", runs[0], runs[1],
                     "--test", runs[2], "--out", out.string()},
                    {}, log),
            0)
      << rt::read_text(log);
  const std::string progress = rt::read_text(log);
  EXPECT_NE(progress.find("model: reduced, order"), std::string::npos) << progress;
  EXPECT_NE(progress.find("calibrate responses 100 %"), std::string::npos) << progress;

  EXPECT_TRUE(tt::test::matches_output_schemas("calibrate", out));
  const auto j = nlohmann::json::parse(rt::read_text(out / "calibration.json"));
  EXPECT_EQ(j["mode"], "model (--case)");
  EXPECT_EQ(j["model"]["kind"], "reduced");
  EXPECT_LT(j["model"]["order"].get<int>(), j["model"]["nodes"].get<int>() / 10);
  EXPECT_FALSE(j["model"]["indicator"]["above_tolerance"].get<bool>());
  ASSERT_FALSE(j["effects"].empty()) << j.dump(1);
  const auto& first = j["effects"][0];
  EXPECT_EQ(first["kind"], "heat_input") << j.dump(1);
  const Eigen::Vector3d found = tt::test::effect_centre_m(first);
  std::printf(
      "[calibrate cli] heat input %.2f W at (%.3f, %.3f, %.3f), found %.2f W at "
      "(%.3f, %.3f, %.3f); u RMS %.3f -> %.3f um\n",
      effect.magnitude, effect.centre(0), effect.centre(1), effect.centre(2),
      first["parameters"]["power_W"].get<double>(), found(0), found(1), found(2),
      j["before"]["displacement_rms_um"].get<double>(),
      j["after"]["displacement_rms_um"].get<double>());
  EXPECT_LT((found - effect.centre).norm(), 0.06);
  EXPECT_LT(j["after"]["displacement_rms_um"].get<double>(),
            0.5 * j["before"]["displacement_rms_um"].get<double>());
  for (const char* f : {"report.md", "augmented_case.toml", "residuals.csv",
                        "sensor_corrections.json", ".thermotwin-result"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  EXPECT_NE(rt::read_text(out / "report.md").find("Model marched: reduced"), std::string::npos);
  // The augmented case reads back as a case.
  EXPECT_NO_THROW(io::read_case(out / "augmented_case.toml"));

  // A training run as --out is refused at once, and the run is left as it was.
  const auto before = rt::snapshot(runs[0]);
  EXPECT_NE(rt::run({"calibrate", "--case", rt::kCoarseCase.string(), "--train", runs[0], runs[1],
                     "--test", runs[2], "--out", runs[0]},
                    {}, dir / "refused.log"),
            0);
  EXPECT_EQ(rt::snapshot(runs[0]), before);
}

}  // namespace
}  // namespace tt::calibration
