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

/// `chosen`, or every sensor of the run that the twin names.
std::vector<std::string> observed_sensors(const std::vector<std::string>& chosen,
                                          const io::MeasuredRun& run,
                                          const solvers::TwinOutputs& outputs) {
  if (!chosen.empty()) return chosen;
  std::vector<std::string> ids;
  for (const auto& s : run.sensors) ids.push_back(s.id);
  ids = named_by_twin(outputs, ids);
  if (ids.empty())
    throw core::DataError(run.folder.string() +
                          ": none of the run's sensors is a named point of the reduced model; "
                          "name them with --sensors");
  return ids;
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

ObserveReport observe_run(const ObserveInput& input) {
  ObserveReport report;
  report.spec = calibration::case_for_run(*input.declared, *input.run);
  report.sensors = observed_sensors(input.sensors, *input.run, input.twin->outputs);
  report.setup = input.setup(report.spec, report.sensors);
  report.result = solvers::observe(input.twin->model.system, report.spec, report.setup,
                                   input.run->time, readings_of(*input.run, report.sensors));
  return report;
}

}  // namespace tt::studies
