#include "app/study.hpp"

#include <algorithm>

#include "core/errors.hpp"
#include "io/case_reader.hpp"
#include "io/csv_out.hpp"
#include "solvers/thermal.hpp"
#include "solvers/thermal_error.hpp"

namespace tt::app {

std::vector<int> candidate_points(const core::CaseSpec& spec) {
  std::vector<int> out;
  for (size_t i = 0; i < spec.points.size(); ++i) {
    const auto& id = spec.points[i].id;
    const auto& probes = spec.mechanical.probe_points;
    const auto& axis = spec.mechanical.axis_points;
    if (id == spec.mechanical.tcp_point ||
        std::find(probes.begin(), probes.end(), id) != probes.end() ||
        std::find(axis.begin(), axis.end(), id) != axis.end())
      continue;
    out.push_back(static_cast<int>(i));
  }
  if (out.empty()) throw core::CaseError(spec.source.string() + ": no named points to use as candidate sensors");
  return out;
}

int target_column(const std::string& target) {
  if (target == "dx") return solvers::kDx;
  if (target == "dy") return solvers::kDy;
  if (target == "dz") return solvers::kDz;
  throw core::CaseError("target '" + target + "': expected \"dx\", \"dy\" or \"dz\"");
}

Histories histories_from_points(const core::CaseSpec& spec, const std::vector<double>& times,
                                const Eigen::MatrixXd& point_temperature, const Eigen::MatrixXd& error) {
  const std::vector<int> cand = candidate_points(spec);
  Histories h;
  h.times = Eigen::Map<const Eigen::VectorXd>(times.data(), static_cast<Eigen::Index>(times.size()));
  h.positions.resize(static_cast<Eigen::Index>(cand.size()), 3);
  h.temperature.resize(point_temperature.rows(), static_cast<Eigen::Index>(cand.size()));
  for (size_t c = 0; c < cand.size(); ++c) {
    h.names.push_back(spec.points[cand[c]].id);
    h.positions.row(static_cast<Eigen::Index>(c)) = spec.points[cand[c]].position.transpose();
    h.temperature.col(static_cast<Eigen::Index>(c)) = point_temperature.col(cand[c]);
  }
  h.target_names = spec.mechanical.targets;
  h.targets.resize(error.rows(), static_cast<Eigen::Index>(h.target_names.size()));
  for (size_t k = 0; k < h.target_names.size(); ++k)
    h.targets.col(static_cast<Eigen::Index>(k)) = error.col(target_column(h.target_names[k]));
  return h;
}

Histories histories_from_run(const std::filesystem::path& dir) {
  const core::CaseSpec spec = io::read_case(dir / "case.resolved.toml");
  const io::CsvTable temps = io::read_numeric_csv(dir / "temperatures.csv");
  const io::CsvTable err = io::read_numeric_csv(dir / "thermal_error.csv");
  if (temps.rows.rows() != err.rows.rows() || (temps.column("time_s") - err.column("time_s")).cwiseAbs().maxCoeff() > 1e-6)
    throw core::DataError((dir / "thermal_error.csv").string() + ": times differ from temperatures.csv");
  Eigen::MatrixXd point_temperature(temps.rows.rows(), static_cast<Eigen::Index>(spec.points.size()));
  for (size_t i = 0; i < spec.points.size(); ++i) {
    const int col = temps.column_index(spec.points[i].id + "_degC");
    point_temperature.col(static_cast<Eigen::Index>(i)) = temps.rows.col(col).array() + solvers::kCelsiusOffset;
  }
  Eigen::MatrixXd error = Eigen::MatrixXd::Zero(err.rows.rows(), solvers::kThermalErrorColumns);
  for (const auto& t : spec.mechanical.targets)
    error.col(target_column(t)) = 1e-6 * err.column(t + "_um");
  const Eigen::VectorXd t = temps.column("time_s");
  return histories_from_points(spec, std::vector<double>(t.data(), t.data() + t.size()), point_temperature, error);
}

}  // namespace tt::app
