#include "studies/observe_run.hpp"

#include <algorithm>
#include <limits>

#include "calibration/model.hpp"
#include "core/errors.hpp"

namespace tt::studies {
namespace {

/// The run's readings of `ids` [K], #samples x #ids.
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

DriftReadings drift_columns(const io::MeasuredRun& run, const std::vector<std::string>& targets,
                            const std::string& purpose) {
  const Eigen::Index n = run.time.size();
  const auto nt = static_cast<Eigen::Index>(targets.size());
  DriftReadings out;
  out.readings = Eigen::MatrixXd::Constant(n, nt, std::numeric_limits<double>::quiet_NaN());
  for (Eigen::Index t = 0; t < nt; ++t)
    for (std::size_t p = 0; p < run.displacements.size(); ++p)
      if (run.displacements[p].id == targets[static_cast<std::size_t>(t)]) {
        out.readings.col(t) = run.displacement.col(static_cast<Eigen::Index>(p));
        out.targets.push_back(run.displacements[p].id);
      }
  if (out.targets.empty())
    throw core::DataError(run.folder.string() + ": " + purpose +
                          ", but no displacement column of the run is named after a target of "
                          "the observer (dx, dy, dz, <axis point>_dy, ...)");
  out.samples = static_cast<int>(n);
  return out;
}

DriftReadings drift_readings(const io::MeasuredRun& run, const std::vector<std::string>& targets,
                             double every_s) {
  DriftReadings out = drift_columns(run, targets, "drift readings asked for");
  out.samples = 0;
  solvers::ProbeCycle cycle(every_s);
  for (Eigen::Index i = 0; i < run.time.size(); ++i) {
    if (cycle.due(run.time(i)))
      ++out.samples;
    else
      out.readings.row(i).setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  return out;
}

std::vector<std::string> named_by_twin(const solvers::TwinOutputs& outputs,
                                       const std::vector<std::string>& ids) {
  std::vector<std::string> named;
  for (const auto& id : ids)
    if (solvers::temperature_row(outputs, id) >= 0) named.push_back(id);
  return named;
}

std::vector<std::string> readable_sensors(const solvers::TwinOutputs& outputs,
                                          const mesh::TetMesh* mesh,
                                          const std::vector<io::MeasuredSensor>& located,
                                          const std::vector<std::string>& ids,
                                          const std::optional<std::string>& ambient) {
  std::vector<std::string> out;
  for (const auto& id : ids) {
    const auto s =
        std::find_if(located.begin(), located.end(), [&](const auto& l) { return l.id == id; });
    const bool positioned = mesh && s != located.end() && s->position;
    if (id != ambient && (positioned || solvers::temperature_row(outputs, id) >= 0))
      out.push_back(id);
  }
  return out;
}

SensorReadout sensor_readout(const solvers::Twin& twin, const mesh::TetMesh* mesh,
                             const std::vector<io::MeasuredSensor>& located,
                             const std::vector<std::string>& ids, const std::string& source) {
  SensorReadout r;
  r.places.resize(ids.size());
  r.rows.resize(static_cast<Eigen::Index>(ids.size()), twin.outputs.rows.cols());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const auto s =
        std::find_if(located.begin(), located.end(), [&](const auto& l) { return l.id == ids[k]; });
    const int named = solvers::temperature_row(twin.outputs, ids[k]);
    if (mesh && s != located.end() && s->position) {
      r.places[k].position = *s->position;
      std::vector<std::pair<int, double>> weights;
      try {
        weights = calibration::point_weights(*mesh, *s->position);
      } catch (const core::DataError& e) {
        throw core::DataError(source + ": sensor '" + ids[k] + "': " + e.what());
      }
      r.rows.row(static_cast<Eigen::Index>(k)) = solvers::twin_point_row(twin, weights);
      for (const auto& p : mesh->points)
        if (p.id == ids[k]) r.places[k].from_named_point_m = (*s->position - p.position).norm();
    } else if (named >= 0) {
      r.rows.row(static_cast<Eigen::Index>(k)) = twin.outputs.rows.row(named);
    } else {
      throw core::DataError(source + ": sensor '" + ids[k] +
                            "' has no position and is not a named point of the reduced model");
    }
  }
  return r;
}

ObserveReport observe_run(const ObserveInput& input) {
  const io::MeasuredRun& run = *input.run;
  ObserveReport report;
  report.spec = calibration::case_for_run(*input.declared, run);
  report.sensors = input.sensors;
  if (report.sensors.empty()) {
    std::vector<std::string> ids;
    for (const auto& s : run.sensors) ids.push_back(s.id);
    report.sensors =
        readable_sensors(input.twin->outputs, input.mesh, run.sensors, ids, run.ambient_sensor);
  }
  if (report.sensors.empty())
    throw core::DataError(run.folder.string() +
                          ": none of the run's sensors has a position or is a named point of the "
                          "reduced model; give positions in meta.json or name them with --sensors");
  SensorReadout readout =
      sensor_readout(*input.twin, input.mesh, run.sensors, report.sensors, run.folder.string());
  report.places = std::move(readout.places);
  report.setup = input.setup(report.spec, report.sensors, readout.rows);
  report.drift_readings_every_s = input.drift_readings_every_s;
  DriftReadings drifts;
  if (input.drift_readings_every_s > 0) {
    drifts = drift_readings(run, report.setup.target_names, input.drift_readings_every_s);
    report.drift_targets = drifts.targets;
    report.drift_samples = drifts.samples;
  }
  report.result = solvers::observe(input.twin->model.system, report.spec, report.setup, run.time,
                                   readings_of(run, report.sensors), drifts.readings);
  return report;
}

}  // namespace tt::studies
