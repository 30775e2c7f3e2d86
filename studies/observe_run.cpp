#include "studies/observe_run.hpp"

#include <algorithm>

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

std::vector<std::string> named_by_twin(const solvers::TwinOutputs& outputs,
                                       const std::vector<std::string>& ids) {
  std::vector<std::string> named;
  const auto first = outputs.names.begin(), last = first + outputs.temperatures;
  for (const auto& id : ids)
    if (std::find(first, last, id) != last) named.push_back(id);
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
    if (id != ambient && (positioned || !named_by_twin(outputs, {id}).empty())) out.push_back(id);
  }
  return out;
}

SensorReadout sensor_readout(const solvers::Twin& twin, const mesh::TetMesh* mesh,
                             const std::vector<io::MeasuredSensor>& located,
                             const std::vector<std::string>& ids, const std::string& source) {
  const solvers::TwinOutputs& out = twin.outputs;
  SensorReadout r;
  r.places.resize(ids.size());
  Eigen::MatrixXd rows(static_cast<Eigen::Index>(ids.size()), out.rows.cols());
  bool any = false;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const auto s =
        std::find_if(located.begin(), located.end(), [&](const auto& l) { return l.id == ids[k]; });
    const auto first = out.names.begin(), last = first + out.temperatures;
    const auto named = std::find(first, last, ids[k]);
    if (mesh && s != located.end() && s->position) {
      r.places[k].position = *s->position;
      std::vector<std::pair<int, double>> weights;
      try {
        weights = calibration::point_weights(*mesh, *s->position);
      } catch (const core::DataError& e) {
        throw core::DataError(source + ": sensor '" + ids[k] + "': " + e.what());
      }
      rows.row(static_cast<Eigen::Index>(k)) = solvers::twin_point_row(twin, weights);
      any = true;
      for (const auto& p : mesh->points)
        if (p.id == ids[k]) r.places[k].from_named_point_m = (*s->position - p.position).norm();
    } else if (named != last) {
      rows.row(static_cast<Eigen::Index>(k)) = out.rows.row(named - first);
    } else {
      throw core::DataError(source + ": sensor '" + ids[k] +
                            "' has no position and is not a named point of the reduced model");
    }
  }
  if (any) r.rows = std::move(rows);
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
  report.result = solvers::observe(input.twin->model.system, report.spec, report.setup,
                                   input.run->time, readings_of(*input.run, report.sensors));
  return report;
}

}  // namespace tt::studies
