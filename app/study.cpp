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
    if (id == spec.mechanical.tcp_point || std::find(probes.begin(), probes.end(), id) != probes.end()) continue;
    out.push_back(static_cast<int>(i));
  }
  if (out.empty()) throw core::CaseError(spec.source.string() + ": no named points to use as candidate sensors");
  return out;
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
  h.dy = error.col(solvers::kDy);
  h.dz = error.col(solvers::kDz);
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
  error.col(solvers::kDy) = 1e-6 * err.column("dy_um");
  error.col(solvers::kDz) = 1e-6 * err.column("dz_um");
  const Eigen::VectorXd t = temps.column("time_s");
  return histories_from_points(spec, std::vector<double>(t.data(), t.data() + t.size()), point_temperature, error);
}

}  // namespace tt::app
