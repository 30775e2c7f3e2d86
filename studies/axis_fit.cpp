#include "studies/axis_fit.hpp"

#include <cmath>

#include "core/directions.hpp"
#include "core/errors.hpp"
#include "fitting/metrics.hpp"
#include "solvers/axis_error.hpp"

namespace tt::studies {

namespace {

/// Sums of squares, counts and largest |residual| per direction, over groups.
struct Tally {
  std::array<double, 3> squares{}, count{}, max{};
  void add(const Eigen::MatrixXd& residual) {
    for (Eigen::Index c = 0; c < residual.cols(); ++c) {
      const auto d = static_cast<std::size_t>(c % 3);
      squares[d] += residual.col(c).squaredNorm();
      count[d] += static_cast<double>(residual.rows());
      max[d] = std::max(max[d], residual.col(c).cwiseAbs().maxCoeff());
    }
  }
  AxisCompensation result(const std::string& source) const {
    AxisCompensation a{source, {}, {}};
    for (std::size_t d = 0; d < 3; ++d) {
      a.rms_m[d] = count[d] > 0 ? std::sqrt(squares[d] / count[d]) : std::nan("");
      a.max_m[d] = max[d];
    }
    return a;
  }
};

}  // namespace

std::vector<std::string> axis_target_names(const core::CaseSpec& spec) {
  std::vector<std::string> names;
  for (const auto& id : spec.mechanical.axis_points)
    for (const char* d : core::kDirectionNames) names.push_back(id + "_" + d);
  return names;
}

double uncompensated_std(const std::vector<fitting::Group>& groups, const std::vector<int>& which,
                         int target) {
  double sum = 0;
  for (int i : which) {
    const Eigen::VectorXd e = groups[static_cast<std::size_t>(i)].error.col(target);
    sum += fitting::residual_std((e.array() - e.mean()).matrix());
  }
  return sum / static_cast<double>(which.size());
}

Eigen::MatrixXd linear_axis_predictions(const AxisFit& fit, const fitting::Group& group) {
  Eigen::MatrixXd p(group.time.size(), static_cast<Eigen::Index>(fit.linear.size()));
  for (std::size_t k = 0; k < fit.linear.size(); ++k)
    p.col(static_cast<Eigen::Index>(k)) = fitting::predicted_error(fit.linear[k].model, group);
  return p;
}

AxisCompensation axis_compensation(const std::string& source, const AxisFit& fit,
                                   const std::vector<Eigen::MatrixXd>& truths,
                                   const std::vector<Eigen::MatrixXd>& estimates) {
  if (truths.size() != estimates.size())
    throw core::SolverError("axis compensation '" + source +
                            "': " + std::to_string(estimates.size()) + " estimates for " +
                            std::to_string(truths.size()) + " truths");
  Tally tally;
  for (std::size_t k = 0; k < truths.size(); ++k) {
    if (estimates[k].rows() != truths[k].rows() || estimates[k].cols() != truths[k].cols())
      throw core::SolverError("axis compensation '" + source + "': an estimate of " +
                              std::to_string(estimates[k].rows()) + " x " +
                              std::to_string(estimates[k].cols()) + " against a truth of " +
                              std::to_string(truths[k].rows()) + " x " +
                              std::to_string(truths[k].cols()));
    const solvers::AxisError truth{fit.points, fit.positions, truths[k]};
    const auto poly = solvers::axis_polynomial(
        solvers::AxisError{fit.points, fit.positions, estimates[k]}, fit.degree);
    tally.add(solvers::axis_polynomial_residual(poly, truth));
  }
  return tally.result(source);
}

AxisFit axis_fit(const core::CaseSpec& spec, const std::vector<fitting::Group>& groups,
                 const fitting::Split& split, int first_target,
                 const std::vector<fitting::SensorSet>& extra_sets,
                 const std::vector<fitting::ModelSpec>& specs,
                 const std::optional<fitting::ModelSpec>& network,
                 const std::vector<int>& network_sensors) {
  if (split.test.empty())
    throw core::DataError("the feed axis's models with no test group; expected at least one");
  AxisFit fit;
  fit.degree = spec.mechanical.axis_polynomial_degree;
  const auto n = static_cast<int>(spec.mechanical.axis_points.size());
  const int columns = static_cast<int>(groups.front().error.cols());
  if (first_target < 0 || first_target + 3 * n != columns)
    throw core::DataError("the groups have " + std::to_string(columns) +
                          " error columns; expected the axis points' 3 x " + std::to_string(n) +
                          " from column " + std::to_string(first_target) + " to the last");
  // 1. Linear models per axis target, chosen on validation like the TCP's.
  const std::vector<fitting::Group> fitting_groups = fitting::group_subset(groups, split.fitting);
  for (int t = first_target; t < columns; ++t) {
    std::vector<fitting::SensorSet> sets = fitting::correlation_sensor_sets(fitting_groups, t, 4);
    for (auto& s : sets) s.method = "db3401_correlation";
    sets.insert(sets.end(), extra_sets.begin(), extra_sets.end());
    fit.targets.push_back(t);
    fit.linear.push_back(fitting::evaluation(groups, split, t, sets, specs));
    fit.uncompensated_std.push_back(uncompensated_std(groups, split.test, t));
  }
  // 2. The patent's network: every error column at once, trained on fitting and validation
  //    groups (the last of them stops it early), tested on the test groups.
  const std::vector<fitting::Group> test = fitting::group_subset(groups, split.test);
  if (network) {
    std::vector<int> refit = split.fitting;
    refit.insert(refit.end(), split.validation.begin(), split.validation.end());
    std::vector<int> all(static_cast<std::size_t>(columns));
    for (int t = 0; t < columns; ++t) all[static_cast<std::size_t>(t)] = t;
    // One scale for all outputs: the loss weighs them by size, so the 100 um dx of the far axis
    // points counts for more than the 1 um dz that is mostly noise.
    fitting::ModelSpec every_output = *network;
    every_output.network.options.common_output_scale = true;
    fit.network = fitting::fitted_network_models(every_output, fitting::group_subset(groups, refit),
                                                 network_sensors, all);
    for (const auto& m : fit.network) fit.network_test.push_back(fitting::model_accuracy(m, test));
  }
  // 3. The axis polynomial at every test time from each source, judged at the points.
  const solvers::AxisError first = solvers::axis_error_at_points(
      spec, Eigen::MatrixXd::Zero(1, 3 * static_cast<Eigen::Index>(n)));
  fit.points = first.points;
  fit.positions = first.positions;
  fit.feed_axis = spec.feed_axis.name;
  fit.direction = spec.feed_axis.direction;
  std::vector<Eigen::MatrixXd> truths, zeros, linear, net;
  for (const fitting::Group& g : test) {
    truths.push_back(g.error.rightCols(3 * n));
    zeros.push_back(Eigen::MatrixXd::Zero(g.time.size(), 3 * n));
    linear.push_back(linear_axis_predictions(fit, g));
    if (!fit.network.empty()) {
      Eigen::MatrixXd p(g.time.size(), 3 * n);
      for (int k = 0; k < 3 * n; ++k)
        p.col(k) = fitting::predicted_error(fit.network[first_target + k], g);
      net.push_back(p);
    }
  }
  fit.compensation = {axis_compensation("uncompensated", fit, truths, zeros),
                      axis_compensation("measured", fit, truths, truths),
                      axis_compensation("linear", fit, truths, linear)};
  if (!fit.network.empty())
    fit.compensation.push_back(axis_compensation("network", fit, truths, net));
  return fit;
}

}  // namespace tt::studies
