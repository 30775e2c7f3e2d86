#include "studies/calibrate_with_model.hpp"

#include <chrono>

#include "core/timing.hpp"
#include "mesh/mesher.hpp"

namespace tt::studies {
namespace {

/// The model the candidates' responses are marched on: reduced (its basis holds the channels'
/// Krylov vectors, so that every candidate's response at the channels is kept) unless `full`.
calibration::MarchModel march_model(const mesh::TetMesh& mesh, const ModelCalibrationInput& in,
                                    const calibration::Readout& r, ModelUsed& used,
                                    const Progress& say) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string nodes = std::to_string(mesh.nodes.rows());
  say(in.full ? "model: full order (" + nodes + " nodes), as --full asks"
              : "model: building the reduced model on the channels (--full for the full order)");
  calibration::MarchModel model =
      in.full ? calibration::MarchModel(mesh, in.declared)
              : calibration::MarchModel(mesh, in.declared, r, solvers::ReductionOptions{});
  used.reduced = model.is_reduced();
  used.nodes = mesh.nodes.rows();
  used.order = model.order();
  used.build_s = core::seconds_since(t0);
  if (model.is_reduced()) {
    say("model: reduced, order " + std::to_string(model.order()) + " of " + nodes + " nodes");
    // Trust: the full-order residual of the declared model's base state on the first training
    // run, at a few output steps (backward Euler only).
    const core::CaseSpec first = calibration::case_for_run(in.declared, in.train.front());
    if (first.thermal.scheme == core::TimeScheme::backward_euler)
      used.indicator = IndicatorCheck{
          in.train.front().run, solvers::twin_indicator(model.full(), *model.reduced(), first, 3)};
  }
  return model;
}

/// Each channel's test figures before and after, over the finite samples of all test runs.
std::vector<ChannelTestFigures> channel_test_figures(const calibration::CalibrationResult& res,
                                                     const calibration::Readout& r) {
  std::vector<Eigen::MatrixXd> measured, before, after;
  for (const auto& t : res.tests) {
    measured.push_back(t.measured);
    before.push_back(t.before);
    after.push_back(t.after);
  }
  std::vector<ChannelTestFigures> channels;
  for (int c = 0; c < r.channels(); ++c)
    channels.push_back({r.ids[static_cast<std::size_t>(c)], c < r.sensors,
                        calibration::channel_figures(measured, before, c),
                        calibration::channel_figures(measured, after, c)});
  return channels;
}

}  // namespace

ModelCalibrationReport calibrate_with_model(const ModelCalibrationInput& in, const Progress& say,
                                            const solvers::Progress& stepping) {
  const auto t0 = std::chrono::steady_clock::now();
  const Progress tell = [&](const std::string& line) {
    if (say) say(line);
  };
  tell("meshing " + in.declared.name);
  const mesh::TetMesh mesh = mesh::mesh_case(in.declared);
  calibration::CalibrationOptions options;
  options.seed = in.declared.seed;
  if (!in.refit) options.refit_max_iterations = 0;
  tell(std::to_string(mesh.nodes.rows()) +
       " nodes; locating the channels (probes: elastic influence rows)");
  const calibration::Readout r = calibration::readout(mesh, in.declared, in.train.front());
  ModelCalibrationReport report;
  const calibration::MarchModel model = march_model(mesh, in, r, report.model, tell);
  tell(std::to_string(r.channels()) + " channels, responses on " + std::to_string(in.train.size()) +
       " training runs");
  const calibration::Catalogue cat =
      calibration::catalogue(model, in.declared, r, in.train, options, false, stepping);
  tell(std::to_string(cat.candidates.size()) + " candidate effects; choosing, then the test runs");
  report.result = calibration::calibrate(model, in.declared, cat, in.test, options);
  report.case_name = in.declared.name;
  for (const auto& t : in.train) report.training_runs.push_back(t.run);
  report.channels = channel_test_figures(report.result, r);
  report.runtime_s = core::seconds_since(t0);
  return report;
}

}  // namespace tt::studies
