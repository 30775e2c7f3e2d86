// A run directory's candidate histories (`place --from RUN`): the files read by io, the
// histories assembled by studies.
#include "app/study.hpp"
#include "core/errors.hpp"
#include "core/units.hpp"
#include "io/candidates_csv.hpp"
#include "io/case_reader.hpp"
#include "io/csv_out.hpp"
#include "solvers/thermal_error.hpp"

namespace tt::app {

Histories histories_from_run(const std::filesystem::path& dir) {
  const core::CaseSpec spec = io::read_case(dir / "case.resolved.toml");
  const bool surface = spec.placement.surface();
  const std::filesystem::path temps_file =
      dir / (surface ? io::kCandidateTemperaturesCsv : "temperatures.csv");
  if (surface &&
      (!std::filesystem::exists(temps_file) || !std::filesystem::exists(dir / io::kCandidatesCsv)))
    throw core::DataError(dir.string() +
                          ": the case asks for surface candidates but the run has no " +
                          io::kCandidatesCsv + " and " + io::kCandidateTemperaturesCsv +
                          "; hint: run the case again with this version of thermotwin");
  const io::CsvTable temps = io::read_numeric_csv(temps_file);
  const io::CsvTable err = io::read_numeric_csv(dir / "thermal_error.csv");
  if (temps.rows.rows() != err.rows.rows() ||
      (temps.column("time_s") - err.column("time_s")).cwiseAbs().maxCoeff() > 1e-6)
    throw core::DataError((dir / "thermal_error.csv").string() + ": times differ from " +
                          temps_file.filename().string());
  Eigen::MatrixXd error = Eigen::MatrixXd::Zero(err.rows.rows(), solvers::kThermalErrorColumns);
  for (const auto& t : spec.mechanical.targets)
    error.col(target_column(t)) = 1e-6 * err.column(t + "_um");
  const Eigen::VectorXd t = temps.column("time_s");
  const std::vector<double> times(t.data(), t.data() + t.size());
  if (surface) {
    const io::CandidateTable table = io::read_candidates_csv(dir / io::kCandidatesCsv);
    const CandidateSet set{table.ids, table.nodes, table.positions};
    Eigen::MatrixXd node_temperature(temps.rows.rows(),
                                     static_cast<Eigen::Index>(set.names.size()));
    for (size_t c = 0; c < set.names.size(); ++c)
      node_temperature.col(static_cast<Eigen::Index>(c)) =
          temps.rows.col(temps.column_index(set.names[c] + "_degC")).array() + core::kCelsiusOffset;
    return histories_from_nodes(spec, set, times, node_temperature, error);
  }
  Eigen::MatrixXd point_temperature(temps.rows.rows(),
                                    static_cast<Eigen::Index>(spec.points.size()));
  for (size_t i = 0; i < spec.points.size(); ++i) {
    const int col = temps.column_index(spec.points[i].id + "_degC");
    point_temperature.col(static_cast<Eigen::Index>(i)) =
        temps.rows.col(col).array() + core::kCelsiusOffset;
  }
  return histories_from_points(spec, times, point_temperature, error);
}

}  // namespace tt::app
