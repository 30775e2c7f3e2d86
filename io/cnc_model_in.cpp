#include "io/cnc_model_in.hpp"

#include <cmath>
#include <fstream>
#include <optional>

#include "core/directions.hpp"
#include "core/errors.hpp"
#include "io/fit_json_keys.hpp"
#include "io/fit_model_in.hpp"
#include "io/sample_stream.hpp"
#include "solvers/axis_error.hpp"

namespace tt::io {

namespace {

using fit_keys::member;
using fit_keys::names_at;
using fit_keys::number_at;
using fit_keys::Place;
using fit_keys::vector_at;
using nlohmann::json;

int direction_of(const std::string& name) {
  for (int d = 0; d < 3; ++d)
    if (name == core::kDirectionNames[d]) return d;
  return -1;
}

/// The feed axis's points and models, appended to `models`.
struct AxisSection {
  std::vector<std::string> points;
  Eigen::VectorXd positions;
  int degree = 0;
  std::string name;
  int direction = 0;
};

AxisSection axis_section(const json& axis, const std::string& origin,
                         std::vector<fitting::FittedModel>& models,
                         std::vector<std::string>& targets) {
  const Place p{origin, ""};
  if (axis.is_object() && !axis.contains("feed_axis"))
    throw core::DataError(p.at("axis.feed_axis") +
                          " is missing: this fit.json was written before fit kept the feed axis "
                          "and its models' coefficients; hint: run `thermotwin fit` again");
  AxisSection a;
  a.points = names_at(axis, "points", p, "axis.");
  a.positions = vector_at(axis, "positions_m", p, "axis.");
  if (a.positions.size() != static_cast<Eigen::Index>(a.points.size()))
    throw core::DataError(p.at("axis.positions_m") + " has " + std::to_string(a.positions.size()) +
                          " entries for " + std::to_string(a.points.size()) + " axis points");
  const double degree = number_at(axis, "degree", p, "axis.");
  if (degree != std::floor(degree) || degree < 0 || degree > 9)
    throw core::DataError(p.at("axis.degree") + " = " + std::to_string(degree) +
                          ": expected a whole number from 0 to 9");
  a.degree = static_cast<int>(degree);
  const json& feed = member(axis, "feed_axis", p, "axis.");
  const json& name = member(feed, "name", p, "axis.feed_axis.");
  const json& dir = member(feed, "direction", p, "axis.feed_axis.");
  const std::string dir_name = dir.is_string() ? dir.get<std::string>() : dir.dump();
  a.direction = dir_name == "x" ? 0 : dir_name == "y" ? 1 : dir_name == "z" ? 2 : -1;
  if (!name.is_string() || a.direction < 0)
    throw core::DataError(p.at("axis.feed_axis") + " = " + feed.dump() +
                          ": expected a name and a direction x, y or z");
  a.name = name.get<std::string>();
  const json& axis_targets = member(axis, "targets", p, "axis.");
  for (const std::string& point : a.points)
    for (const char* d : core::kDirectionNames) {
      const std::string target = point + "_" + d;
      const std::string key = "axis.targets." + target;
      const json& t = member(axis_targets, target, p, "axis.targets.");
      if (!t.is_object() || !t.contains("coefficients"))
        throw core::DataError(
            p.at(key + ".coefficients") +
            " is missing; hint: this fit.json was written before fit kept the axis models' "
            "coefficients: run `thermotwin fit` again");
      models.push_back(
          fitted_model_from_json(t["coefficients"], origin, target, key + ".coefficients"));
      targets.push_back(target);
    }
  return a;
}

/// A CSV of sensor samples: its columns after time_s, times [s] and values (#samples x #columns).
struct SampleCsv {
  std::vector<std::string> columns;
  Eigen::VectorXd times;
  Eigen::MatrixXd values;
};

/// The header's columns after time_s, a "_degC" suffix dropped.
std::vector<std::string> sample_columns(std::istream& in, const std::filesystem::path& path) {
  std::string line;
  if (!std::getline(in, line))
    throw core::DataError(path.string() + ": empty; expected a header time_s,<sensor ids>");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  std::vector<std::string> columns = stream_columns(line, path.string());
  for (std::string& c : columns)
    if (c.size() > 5 && c.compare(c.size() - 5, 5, "_degC") == 0) c.resize(c.size() - 5);
  return columns;
}

SampleCsv read_sample_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw core::IoError(path.string() + ": cannot read (expected a CSV of sensor samples)");
  SampleCsv csv{sample_columns(in, path), {}, {}};
  std::vector<double> times;
  std::vector<Eigen::VectorXd> rows;
  Eigen::VectorXd values(static_cast<Eigen::Index>(csv.columns.size()));
  std::string line;
  for (int number = 2; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    double time = 0.0;
    if (!parsed_sample(line, time, values))
      throw core::DataError(path.string() + ": line " + std::to_string(number) + " has not " +
                            std::to_string(csv.columns.size() + 1) + " fields");
    times.push_back(time);
    rows.push_back(values);
  }
  if (rows.empty()) throw core::DataError(path.string() + ": no sample after the header");
  csv.times =
      Eigen::Map<const Eigen::VectorXd>(times.data(), static_cast<Eigen::Index>(times.size()));
  csv.values.resize(static_cast<Eigen::Index>(rows.size()), values.size());
  for (std::size_t i = 0; i < rows.size(); ++i)
    csv.values.row(static_cast<Eigen::Index>(i)) = rows[i];
  return csv;
}

}  // namespace

CncModelFile cnc_model(const json& fit, const std::string& origin) {
  CncModelFile out;
  std::vector<fitting::FittedModel> models;
  std::vector<int> tcp_direction;
  for (const DeployedModel& d : deployed_models(fit, origin)) {
    const int dir = direction_of(d.model.target_name);
    if (dir < 0) {
      out.ignored_targets.push_back(d.model.target_name);
      continue;
    }
    models.push_back(d.model);
    out.targets.push_back(d.model.target_name);
    tcp_direction.push_back(dir);
  }
  const std::size_t tcp_count = models.size();
  std::optional<AxisSection> axis;
  if (fit.contains("axis")) axis = axis_section(fit["axis"], origin, models, out.targets);
  if (models.empty())
    throw core::DataError(origin +
                          ": no target is a direction (dx, dy, dz) and there is no axis; "
                          "nothing a controller's axis takes");
  const fitting::LinearBasis basis = fitting::linear_basis(models);
  fitting::CncModel& m = out.model;
  m.basis = basis.names;
  m.features = basis.features;
  const auto nb = static_cast<Eigen::Index>(basis.names.size());
  for (auto& t : m.tcp) t = Eigen::VectorXd::Zero(nb);
  for (auto& c : m.axis) c.resize(0, nb);
  for (std::size_t i = 0; i < tcp_count; ++i)
    m.tcp[static_cast<std::size_t>(tcp_direction[i])] +=
        basis.coefficients.row(static_cast<Eigen::Index>(i)).transpose();
  if (axis) {
    m.feed_axis = axis->name;
    m.feed_direction = axis->direction;
    m.travel_min = axis->positions.minCoeff();
    m.travel_max = axis->positions.maxCoeff();
    // The axis points' error for each basis function alone, as rows of "times": the polynomial
    // of each row is that basis function's polynomial, since the fit is linear in the values.
    const auto n = static_cast<Eigen::Index>(axis->points.size());
    solvers::AxisError e{axis->points, axis->positions, Eigen::MatrixXd(nb, 3 * n)};
    e.values = basis.coefficients.bottomRows(3 * n).transpose();
    try {
      const solvers::AxisPolynomial poly = solvers::axis_polynomial(e, axis->degree);
      for (std::size_t d = 0; d < 3; ++d) m.axis[d] = poly.coefficients[d].transpose();
    } catch (const core::SolverError& err) {
      throw core::DataError(origin + ": axis: " + err.what());
    }
  }
  return out;
}

CncModelFile read_cnc_model(const std::filesystem::path& path) {
  return cnc_model(read_fit_json(path), path.string());
}

StateSamples read_state_samples(const fitting::CncModel& model,
                                const std::vector<std::filesystem::path>& paths) {
  StateSamples samples{Eigen::MatrixXd(0, fitting::unit_states(model).cols()), {}};
  for (const std::filesystem::path& path : paths) {
    const SampleCsv csv = read_sample_csv(path);
    Eigen::MatrixXd s;
    try {
      s = fitting::basis_states(model, csv.columns, csv.times, csv.values);
    } catch (const core::DataError& e) {
      throw core::DataError(path.string() + ": " + e.what());
    }
    samples.states.conservativeResize(samples.states.rows() + s.rows(), Eigen::NoChange);
    samples.states.bottomRows(s.rows()) = s;
    samples.per_file.push_back(s.rows());
  }
  return samples;
}

}  // namespace tt::io
