// thermotwin observe CASE --rom DIR --data RUN --out DIR: the physics observer (docs/observer.md)
// on a measured run: a Kalman filter on the reduced model's states, fed with the run's spindle
// speed (its speed_rpm column) as the duty cycle and its sensors' readings, that predicts the
// drift at the tool (and the axis points) with its standard deviation and says when the
// innovations stop fitting the noise model (status `recalibrate`, with the time it started).
//   1. the case and the run; the case's duty cycle becomes the run's (calibration::case_for_run);
//   2. the reduced model, checked against the case and its mesh;
//   3. the observer's set-up: the sensors (--sensors, default: every sensor of the run that is a
//      named point of the model), their noise, the process noise, the consistency test;
//   4. the run through the filter;
//   5. observer.csv and observer.json, all or nothing.
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "app/commands.hpp"
#include "app/observer_options.hpp"
#include "calibration/model.hpp"
#include "core/errors.hpp"
#include "io/atomic_dir.hpp"
#include "io/case_reader.hpp"
#include "io/measured_data.hpp"
#include "io/reduced_model_io.hpp"
#include "io/reports.hpp"
#include "mesh/mesher.hpp"
#include "solvers/observer.hpp"

namespace tt::app {
namespace {

/// The run's columns of `sensors` (ids), or every sensor of the run that the model names.
std::vector<std::string> observed_sensors(const ObserveArgs& args, const io::MeasuredRun& run,
                                          const solvers::TwinOutputs& out) {
  if (!args.observer.sensors.empty()) return args.observer.sensors;
  std::vector<std::string> ids;
  const auto first = out.names.begin(), last = first + out.temperatures;
  for (const auto& s : run.sensors)
    if (std::find(first, last, s.id) != last) ids.push_back(s.id);
  if (ids.empty())
    throw core::DataError(run.folder.string() +
                          ": none of the run's sensors is a named point of the reduced model; "
                          "name them with --sensors");
  return ids;
}

Eigen::MatrixXd readings_of(const io::MeasuredRun& run, const std::vector<std::string>& ids) {
  Eigen::MatrixXd y(run.time.size(), static_cast<Eigen::Index>(ids.size()));
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const auto it = std::find_if(run.sensors.begin(), run.sensors.end(),
                                 [&](const auto& s) { return s.id == ids[k]; });
    if (it == run.sensors.end())
      throw core::DataError(run.folder.string() + ": --sensors names '" + ids[k] +
                            "', which is not a column of the run");
    y.col(static_cast<Eigen::Index>(k)) = run.temperature.col(it - run.sensors.begin());
  }
  return y;
}

}  // namespace

int observe_command(const ObserveArgs& args) {
  // 1. The case under the run's inputs.
  const core::CaseSpec declared = io::read_case(args.case_file);
  const io::MeasuredRun run = io::read_measured_run(args.data);
  const core::CaseSpec spec = calibration::case_for_run(declared, run);
  std::vector<std::filesystem::path> inputs = io::case_input_files(declared);
  inputs.push_back(args.rom);
  inputs.push_back(args.data);
  io::OutputDir out(args.out, inputs);
  // 2. The reduced model, built for this machine and mesh.
  const mesh::TetMesh mesh = mesh::mesh_case(declared);
  const io::ReducedModelFile rom = io::read_reduced_model(args.rom);
  io::check_reduced_model_fits(rom, io::reduced_model_key(declared, mesh), args.rom);
  // 3. The set-up.
  const std::vector<std::string> sensors = observed_sensors(args, run, rom.twin.outputs);
  const solvers::ObserverSetup setup = observer_setup(args.observer, rom.twin, spec, sensors);
  // 4. The run.
  const solvers::ObserverRun r =
      solvers::observe(rom.twin.model.system, spec, setup, run.time, readings_of(run, sensors));
  // 5. Outputs.
  std::ostringstream csv;
  csv << std::setprecision(9) << "time_s";
  for (const auto& t : setup.target_names) csv << "," << t << "_predicted_um," << t << "_sigma_um";
  csv << ",nis,readings,window_nis,window_bound,status\n";
  for (Eigen::Index i = 0; i < r.times.size(); ++i) {
    csv << r.times(i);
    for (Eigen::Index k = 0; k < r.drift.cols(); ++k)
      csv << "," << r.drift(i, k) * 1e6 << "," << r.drift_sigma(i, k) * 1e6;
    const bool alarm = r.recalibrate && r.times(i) >= r.recalibrate_at_s;
    csv << "," << r.nis(i) << "," << r.dof(i) << "," << r.window_nis(i) << "," << r.window_bound(i)
        << "," << (alarm ? "recalibrate" : "ok") << "\n";
  }
  {
    std::ofstream f(out.path() / "observer.csv");
    f << csv.str();
    if (!f) throw core::IoError((out.path() / "observer.csv").string() + ": cannot write");
  }
  nlohmann::json unknown = nlohmann::json::object();
  const Eigen::Index last = r.times.size() - 1;
  for (std::size_t k = 0; k < r.unknown_input_names.size(); ++k) {
    const auto j = static_cast<Eigen::Index>(k);
    const bool air = r.unknown_input_names[k] == "air";
    unknown[r.unknown_input_names[k]] = {
        {air ? "final_K" : "final_W", r.unknown_inputs(last, j)},
        {air ? "sigma_K" : "sigma_W", r.unknown_inputs_sigma(last, j)}};
  }
  nlohmann::json doc = {
      {"run", run.run},
      {"case", declared.name},
      {"model",
       {{"kind", "reduced"}, {"order", rom.twin.model.states()}, {"rom", args.rom.string()}}},
      {"sensors", sensors},
      {"noise", observer_noise_json(setup)},
      {"consistency",
       {{"window_s", setup.consistency.window_s},
        {"sustain_s", setup.consistency.sustain_s},
        {"probability", setup.consistency.probability}}},
      {"status", r.recalibrate ? "recalibrate" : "ok"},
      {"unknown_inputs", unknown},
      {"recalibrate_since_s", nullptr},
      {"recalibrate_raised_s", nullptr}};
  if (r.recalibrate) {
    doc["recalibrate_since_s"] = r.recalibrate_since_s;
    doc["recalibrate_raised_s"] = r.recalibrate_at_s;
  }
  io::write_json(out.path() / "observer.json", doc);
  out.commit();
  if (!args.quiet)
    std::cerr << "thermotwin: observe: " << r.times.size() << " samples, status "
              << (r.recalibrate
                      ? "recalibrate since t = " + std::to_string(r.recalibrate_since_s) + " s"
                      : std::string("ok"))
              << "\n";
  return 0;
}

}  // namespace tt::app
