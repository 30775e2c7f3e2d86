// Calibration's declared model and `run` step one system with one stepper (issue 15): on the
// gantry bar (heat moving with the feed axis, and a feed_power source), the channels that
// calibration's march reads equal thermal_history's read at the same points, under both schemes;
// and the march's columns are the linear responses of the declared model.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "calibration/model.hpp"
#include "core/errors.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"
#include "solvers/thermal.hpp"
#include "tests/common/gantry_bar.hpp"

namespace tt::calibration {
namespace {

/// A measured run of the bar: the spindle stands (the feed axis moves), four located sensors
/// (in the stroke, at its end, beyond it, in the feed_power source's pad), samples every 10 s.
io::MeasuredRun bar_run() {
  io::MeasuredRun run;
  run.run = "bar";
  run.inputs = {"speed_rpm"};
  const Eigen::Index n = 61;
  run.time = Eigen::VectorXd::LinSpaced(n, 0.0, 600.0);
  run.input_values = Eigen::MatrixXd::Zero(n, 1);
  for (const auto& [id, x] : std::vector<std::pair<std::string, double>>{
           {"mid", 0.5}, {"end", 0.8}, {"far", 0.97}, {"pad", -0.025}})
    run.sensors.push_back({id, Eigen::Vector3d(x, 0.025, 0.025)});
  run.temperature = Eigen::MatrixXd::Zero(n, 4);
  return run;
}

/// Largest |a - b| / |b| over the entries.
double max_relative(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return ((a - b).array().abs() / b.array().abs()).maxCoeff();
}

TEST(March, DeclaredChannelsEqualRunWithMovingAndFeedPowerHeat) {
  for (const char* scheme : {"backward_euler", "crank_nicolson"}) {
    const core::CaseSpec declared =
        io::case_from_toml(test_toml::gantry_bar(1, scheme), "bar.toml");
    const mesh::TetMesh m = mesh::mesh_case(declared);
    const io::MeasuredRun run = bar_run();
    const Readout r = readout(m, declared, run);
    ASSERT_EQ(r.channels(), 4);
    const core::CaseSpec spec = case_for_run(declared, run);
    const Responses march_out = march(m, spec, r, run.time, {}, {});

    // `run`'s path: thermal_history at every step end, read at the sensors.
    const solvers::ThermalHistory th =
        solvers::thermal_history(m, spec, solvers::thermal_system(m, spec));
    ASSERT_EQ(th.times.size(), static_cast<size_t>(run.time.size()));
    const Eigen::MatrixXd from_run = (r.temperature * th.temperature).transpose();
    const double gap = max_relative(march_out.base, from_run);
    std::printf("[march] %s: march vs thermal_history, max relative difference %.2e\n", scheme,
                gap);
    EXPECT_LE(gap, 1e-10) << scheme;
    EXPECT_LE(max_relative(simulated_channels(m, spec, r, run.time), from_run), 1e-10) << scheme;

    // The loads are there: the feed_power pad and the stroke warm up, the far end least.
    const double t0 = declared.thermal.initial_temperature_c + core::kCelsiusOffset;
    const Eigen::RowVectorXd rise = march_out.base.row(run.time.size() - 1).array() - t0;
    EXPECT_GT(rise(3), 0.01) << scheme;  // the pad's feed_power source (2.88 W for 300 s)
    EXPECT_GT(rise(0), rise(2) + 0.05) << scheme;
  }
}

TEST(March, ColumnsAreLinearResponses) {
  for (const char* scheme : {"backward_euler", "crank_nicolson"}) {
    const core::CaseSpec declared =
        io::case_from_toml(test_toml::gantry_bar(1, scheme), "bar.toml");
    const mesh::TetMesh m = mesh::mesh_case(declared);
    const io::MeasuredRun run = bar_run();
    const Readout r = readout(m, declared, run);
    const core::CaseSpec spec = case_for_run(declared, run);
    const solvers::FullThermalSystem sys = solvers::thermal_system(m, spec);
    const double h = spec.thermal.convection[0].h;
    // One kelvin more air: as a fixed shape, and as a load of the step.
    SeparableColumn air{"air", h * sys.film_area[0], [](double, double) { return 1.0; }};
    LoadColumn air_load{
        "air", [&](const solvers::StepView&) { return Eigen::VectorXd(h * sys.film_area[0]); }};
    const Responses out = march(m, spec, r, run.time, {air}, {air_load});
    ASSERT_EQ(out.columns.size(), 2u);
    core::CaseSpec warmer = spec;
    warmer.thermal.convection[0].sink.value[0] += 1;
    const Responses again = march(m, warmer, r, run.time, {}, {});
    const Eigen::MatrixXd difference = again.base - out.base;
    EXPECT_LE((out.columns[0] - difference).cwiseAbs().maxCoeff(), 1e-9) << scheme;
    EXPECT_LE((out.columns[1] - out.columns[0]).cwiseAbs().maxCoeff(), 1e-12) << scheme;
    EXPECT_GT(out.columns[0].bottomRows(1).minCoeff(), 0.05) << scheme;
  }
}

// On the reduced model whose basis holds the channels' Krylov vectors, the declared channels and
// the response of every kind of candidate load (a heat patch, a film change, an air hat, heat
// growing with a source's temperature, a conductivity change) equal the full model's at the
// channels: the loads were unknown when the basis was built.
TEST(March, ReducedOnChannelsKeepsEveryCandidateResponse) {
  const core::CaseSpec declared = io::case_from_toml(test_toml::gantry_bar(2), "bar.toml");
  const mesh::TetMesh m = mesh::mesh_case(declared);
  const io::MeasuredRun run = bar_run();
  const Readout r = readout(m, declared, run);
  const core::CaseSpec spec = case_for_run(declared, run);
  const MarchModel full(m, declared);
  const MarchModel reduced(m, declared, r, solvers::ReductionOptions{});
  ASSERT_TRUE(reduced.is_reduced());
  ASSERT_LT(reduced.order(), m.nodes.rows() / 4);

  // A patch of the bar's top face near x = 0.3 (the nodes' film areas there).
  Eigen::VectorXd patch = full.full().film_area[0];
  for (Eigen::Index i = 0; i < m.nodes.rows(); ++i)
    if (std::abs(m.nodes(i, 0) - 0.3) > 0.05 || m.nodes(i, 2) < 0.049) patch(i) = 0;
  ASSERT_GT(patch.sum(), 0);
  const std::vector<SeparableColumn> sep{
      {"patch", patch, [](double t, double) { return t < 300 ? 1.0 : 0.5; }}};
  const auto dk = std::make_shared<const Eigen::SparseMatrix<double>>(0.1 * full.full().conduction);
  OperatorChange fk;
  fk.full = dk;
  OperatorChange rk = fk;
  rk.reduced = std::make_shared<const Eigen::MatrixXd>(reduced.projected(*dk));
  const double t0_k = declared.thermal.initial_temperature_c + core::kCelsiusOffset;
  const auto loads = [&](const OperatorChange& k) {
    return std::vector<LoadColumn>{{"film", FilmChange{0, false, 1}},
                                   {"air", SinkHat{{0}, 300, 300}},
                                   {"nut heat", SourceGrowth{0, t0_k}},
                                   {"bearing heat", SourceGrowth{1, t0_k}},
                                   {"conductivity", k}};
  };
  const Responses a = march(full, spec, r, run.time, sep, loads(fk));
  const Responses b = march(reduced, spec, r, run.time, sep, loads(rk));
  const double base_gap = (a.base - b.base).cwiseAbs().maxCoeff();
  std::printf("[march] reduced order %d of %ld nodes: declared channels within %.2e K\n",
              reduced.order(), static_cast<long>(m.nodes.rows()), base_gap);
  EXPECT_LE(base_gap, 1e-3);
  ASSERT_EQ(a.columns.size(), b.columns.size());
  for (size_t k = 0; k < a.columns.size(); ++k) {
    const double peak = a.columns[k].cwiseAbs().maxCoeff();
    const double gap = (a.columns[k] - b.columns[k]).cwiseAbs().maxCoeff();
    std::printf("[march]   column %zu: peak %.3e, reduced off by %.2e (%.2e relative)\n", k, peak,
                gap, gap / peak);
    EXPECT_GT(peak, 0) << k;
    EXPECT_LE(gap, 1e-2 * peak) << k;
  }
  // Another case's operators on the same basis (a calibrated capacity and conductivity): it
  // starts from the uniform field and follows the full model of that case.
  core::CaseSpec changed = declared;
  changed.materials[0].density *= 0.65;
  changed.materials[0].conductivity *= 1.3;
  const core::CaseSpec changed_run = case_for_run(changed, run);
  const Responses fc = march(MarchModel(m, changed), changed_run, r, run.time, {}, {});
  const Responses rc = march(reduced.with_case(m, changed), changed_run, r, run.time, {}, {});
  const double t0 = declared.thermal.initial_temperature_c + core::kCelsiusOffset;
  EXPECT_LE((rc.base.row(0).array() - t0).abs().maxCoeff(), 1e-9);
  const double changed_gap = (fc.base - rc.base).cwiseAbs().maxCoeff();
  std::printf("[march] another capacity and conductivity on the basis: within %.2e K\n",
              changed_gap);
  EXPECT_LE(changed_gap, 1e-2);
  // A callback on the full system cannot be marched reduced: refused, not answered wrongly.
  const std::vector<LoadColumn> callback{
      {"cb", solvers::LoadCallback([&](const solvers::StepView&) {
         return Eigen::VectorXd(full.full().film_area[0]);
       })}};
  EXPECT_THROW(march(reduced, spec, r, run.time, {}, callback), core::SolverError);
}

// The probes' rows split by material are exact: doubling one material's expansion coefficient
// changes the rows by exactly that material's part (solved again with another elastic model).
TEST(Readout, ExpansionPartsAreExactPerMaterial) {
  const core::CaseSpec declared =
      io::read_case(std::string(TT_SOURCE_DIR) + "/cases/sb1_coarse.toml");
  const mesh::TetMesh m = mesh::mesh_case(declared);
  io::MeasuredRun run;
  run.run = "probes";
  for (const auto& [id, dir] : std::vector<std::pair<std::string, Eigen::Vector3d>>{
           {"tcp_dy", Eigen::Vector3d::UnitY()},
           {"tcp_dz", Eigen::Vector3d::UnitZ()},
           {"tcp_skew", Eigen::Vector3d(1, 1, 0).normalized()}})
    run.displacements.push_back({id, Eigen::Vector3d(0.0, 0.18, 0.58), dir});
  const Readout r = readout(m, declared, run);
  ASSERT_EQ(r.displacement.rows(), 3);
  ASSERT_EQ(r.expansion.size(), declared.materials.size());
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(3, m.nodes.rows());
  for (const auto& part : r.expansion) sum += part;
  const double scale = r.displacement.cwiseAbs().maxCoeff();
  EXPECT_LE((sum - r.displacement).cwiseAbs().maxCoeff(), 1e-12 * scale);
  int used = 0;
  for (size_t k = 0; k < declared.materials.size(); ++k) {
    if (r.expansion[k].cwiseAbs().maxCoeff() == 0) continue;  // a material no body uses
    ++used;
    core::CaseSpec doubled = declared;
    doubled.materials[k].expansion *= 2;
    const Readout r2 = readout(m, doubled, run);
    const double gap = (r2.displacement - r.displacement - r.expansion[k]).cwiseAbs().maxCoeff();
    std::printf("[readout] %s: part peak %.3e m/K, doubled minus base off by %.2e\n",
                declared.materials[k].name.c_str(), r.expansion[k].cwiseAbs().maxCoeff(), gap);
    EXPECT_LE(gap, 1e-9 * scale) << declared.materials[k].name;
    EXPECT_LE((displacement_with_expansions(r, declared, doubled) - r2.displacement)
                  .cwiseAbs()
                  .maxCoeff(),
              1e-9 * scale);
  }
  EXPECT_GE(used, 2);
}

}  // namespace
}  // namespace tt::calibration
