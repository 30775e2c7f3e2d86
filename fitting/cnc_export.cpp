#include "fitting/cnc_export.hpp"

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "core/text.hpp"
#include "core/units.hpp"
#include "fitting/compensation.hpp"

namespace tt::fitting {

namespace {

/// Appends the names of `from` that `to` lacks, keeping first appearances' order.
void add_missing(std::vector<std::string>& to, const std::vector<std::string>& from) {
  for (const std::string& n : from)
    if (std::find(to.begin(), to.end(), n) == to.end()) to.push_back(n);
}

/// Positions of a uniform grid over the travel; one position when the travel is empty.
Eigen::VectorXd travel_grid(const CncModel& model, int points) {
  if (!(model.travel_max > model.travel_min) || points < 2)
    return Eigen::VectorXd::Constant(1, model.travel_min);
  return Eigen::VectorXd::LinSpaced(points, model.travel_min, model.travel_max);
}

/// Σ_k coefficients(k, ·)·b p^k by Horner's rule; 0 for an empty matrix.
double polynomial_value(const Eigen::MatrixXd& coefficients, double p, const Eigen::VectorXd& b) {
  double v = 0.0;
  for (Eigen::Index k = coefficients.rows() - 1; k >= 0; --k)
    v = v * p + coefficients.row(k).dot(b);
  return v;
}

/// The model's compensation per basis function at position p: #basis values [m per unit].
Eigen::RowVectorXd compensation_row(const CncModel& model, int d, double p) {
  Eigen::RowVectorXd r = -model.tcp[static_cast<std::size_t>(d)].transpose();
  const Eigen::MatrixXd& c = model.axis[static_cast<std::size_t>(d)];
  double power = 1.0;
  for (Eigen::Index k = 0; k < c.rows(); ++k, power *= p) r -= power * c.row(k);
  return r;
}

double rounded(double v, double quantum, bool truncate) {
  if (!(quantum > 0.0)) return v;
  return (truncate ? std::trunc(v / quantum) : std::round(v / quantum)) * quantum;
}

/// Linear interpolation in an equidistant table, constant beyond its ends.
double table_value(const TableLaw& t, int d, double p, const Eigen::VectorXd& b) {
  const Eigen::MatrixXd& v = t.values[static_cast<std::size_t>(d)];
  const Eigen::Index n = t.positions.size();
  if (n == 1 || p <= t.positions(0)) return v.row(0).dot(b);
  if (p >= t.positions(n - 1)) return v.row(n - 1).dot(b);
  const double h = (t.positions(n - 1) - t.positions(0)) / static_cast<double>(n - 1);
  const auto i = std::min<Eigen::Index>(static_cast<Eigen::Index>((p - t.positions(0)) / h), n - 2);
  const double w = (p - t.positions(i)) / h;
  return (1.0 - w) * v.row(i).dot(b) + w * v.row(i + 1).dot(b);
}

}  // namespace

LinearBasis linear_basis(const std::vector<FittedModel>& models) {
  LinearBasis basis;
  for (const FittedModel& m : models) {
    if (!std::holds_alternative<LinearFit>(m.body))
      throw core::DataError("the model of target '" + m.target_name + "' is of kind '" +
                            kind_name(m.spec.kind) +
                            "': a controller takes a law linear in the temperatures; hint: refit "
                            "with least_squares, ridge or distributed_lag");
    add_missing(basis.features.sensor_names, m.features.sensor_names);
    add_missing(basis.features.input_names, m.features.input_names);
    for (double tau : m.features.time_constants)
      if (std::find(basis.features.time_constants.begin(), basis.features.time_constants.end(),
                    tau) == basis.features.time_constants.end())
        basis.features.time_constants.push_back(tau);
  }
  std::sort(basis.features.time_constants.begin(), basis.features.time_constants.end());
  for (std::size_t k = 0; k < basis.features.sensor_names.size(); ++k)
    basis.features.sensors.push_back(static_cast<int>(k));
  for (std::size_t k = 0; k < basis.features.input_names.size(); ++k)
    basis.features.inputs.push_back(static_cast<int>(k));
  basis.names = {"1"};
  const std::vector<std::string> features = feature_names(basis.features);
  basis.names.insert(basis.names.end(), features.begin(), features.end());
  basis.coefficients.setZero(static_cast<Eigen::Index>(models.size()),
                             static_cast<Eigen::Index>(basis.names.size()));
  for (std::size_t i = 0; i < models.size(); ++i) {
    const FittedModel& m = models[i];
    const auto& fit = std::get<LinearFit>(m.body);
    const std::vector<std::string> own = feature_names(m.features);
    if (static_cast<Eigen::Index>(own.size()) != fit.coefficients.size())
      throw core::DataError("the model of target '" + m.target_name + "' has " +
                            std::to_string(fit.coefficients.size()) + " coefficients for " +
                            std::to_string(own.size()) + " regressors");
    const auto row = static_cast<Eigen::Index>(i);
    basis.coefficients(row, 0) = fit.intercept;
    for (std::size_t k = 0; k < own.size(); ++k) {
      const auto at = std::find(basis.names.begin(), basis.names.end(), own[k]);
      basis.coefficients(row, at - basis.names.begin()) +=
          fit.coefficients(static_cast<Eigen::Index>(k));
    }
  }
  return basis;
}

double model_compensation(const CncModel& model, int d, double p, const Eigen::VectorXd& b) {
  const auto i = static_cast<std::size_t>(d);
  return -(model.tcp[i].dot(b) + polynomial_value(model.axis[i], p, b));
}

LineLaw line_law(const CncModel& model) {
  LineLaw law;
  const double a = model.travel_min, b = model.travel_max;
  law.reference = 0.5 * (a + b);
  const auto nb = static_cast<Eigen::Index>(model.basis.size());
  // The continuous least-squares line over [a, b] from exact integrals of the powers of p: with
  // u = p - p_0 centred, the value at p_0 is the mean and the slope is ∫f u / ∫u².
  const auto integral = [&](int k) {  // ∫_a^b p^k dp
    return (std::pow(b, k + 1) - std::pow(a, k + 1)) / (k + 1);
  };
  const PolynomialLaw poly = polynomial_law(model, 0.0, false);  // the compensation's powers
  for (std::size_t d = 0; d < 3; ++d) {
    const Eigen::MatrixXd& c = poly.coefficients[d];
    law.value[d] = c.row(0).transpose();
    law.slope[d] = Eigen::VectorXd::Zero(nb);
    if (!(b > a)) continue;
    law.value[d].setZero();
    Eigen::VectorXd moment = Eigen::VectorXd::Zero(nb);  // ∫ f (p - p_0) dp
    for (Eigen::Index k = 0; k < c.rows(); ++k) {
      const int ki = static_cast<int>(k);
      law.value[d] += c.row(k).transpose() * integral(ki) / (b - a);
      moment += c.row(k).transpose() * (integral(ki + 1) - law.reference * integral(ki));
    }
    if (static_cast<int>(d) == model.feed_direction)
      law.slope[d] = moment / (std::pow(b - a, 3) / 12.0);
  }
  return law;
}

TableLaw table_law(const CncModel& model, int points, double quantum, bool truncate) {
  if (points < 2)
    throw core::DataError("compensation table of " + std::to_string(points) +
                          " points: expected at least 2");
  if (!(quantum >= 0.0))
    throw core::DataError("compensation table quantum = " + std::to_string(quantum) +
                          " m: expected >= 0");
  TableLaw t;
  t.positions = travel_grid(model, points);
  t.quantum = quantum;
  t.truncate = truncate;
  for (int d = 0; d < 3; ++d) {
    auto& v = t.values[static_cast<std::size_t>(d)];
    v.resize(t.positions.size(), static_cast<Eigen::Index>(model.basis.size()));
    for (Eigen::Index i = 0; i < t.positions.size(); ++i)
      v.row(i) = compensation_row(model, d, t.positions(i));
  }
  return t;
}

PolynomialLaw polynomial_law(const CncModel& model, double quantum, bool truncate) {
  PolynomialLaw law;
  law.quantum = quantum;
  law.truncate = truncate;
  for (std::size_t d = 0; d < 3; ++d) {
    Eigen::MatrixXd c = -model.axis[d];
    if (c.rows() == 0) c = Eigen::MatrixXd::Zero(1, static_cast<Eigen::Index>(model.basis.size()));
    c.row(0) -= model.tcp[d].transpose();
    law.coefficients[d] = c;
  }
  return law;
}

double law_compensation(const ControllerLaw& law, int d, double p, const Eigen::VectorXd& b) {
  const auto di = static_cast<std::size_t>(d);
  if (const auto* line = std::get_if<LineLaw>(&law))
    return line->value[di].dot(b) + (p - line->reference) * line->slope[di].dot(b);
  if (const auto* table = std::get_if<TableLaw>(&law))
    return rounded(table_value(*table, d, p, b), table->quantum, table->truncate);
  const auto& poly = std::get<PolynomialLaw>(law);
  return rounded(polynomial_value(poly.coefficients[di], p, b), poly.quantum, poly.truncate);
}

LawError law_error(const CncModel& model, const ControllerLaw& law, const Eigen::MatrixXd& states,
                   int grid) {
  const auto nb = static_cast<Eigen::Index>(model.basis.size());
  if (states.cols() != nb)
    throw core::DataError("law error: states of " + std::to_string(states.cols()) +
                          " basis values; the model's basis has " + std::to_string(nb));
  const Eigen::VectorXd p = travel_grid(model, grid);
  LawError e;
  e.positions = static_cast<int>(p.size());
  e.states = static_cast<int>(states.rows());
  for (int d = 0; d < 3; ++d) {
    const auto di = static_cast<std::size_t>(d);
    double squares = 0.0;
    for (Eigen::Index s = 0; s < states.rows(); ++s) {
      const Eigen::VectorXd b = states.row(s).transpose();
      for (Eigen::Index i = 0; i < p.size(); ++i) {
        const double m = model_compensation(model, d, p(i), b);
        const double r = law_compensation(law, d, p(i), b) - m;
        squares += r * r;
        e.max[di] = std::max(e.max[di], std::abs(r));
        e.model_max[di] = std::max(e.model_max[di], std::abs(m));
      }
    }
    const double count = static_cast<double>(p.size() * states.rows());
    e.rms[di] = count > 0 ? std::sqrt(squares / count) : 0.0;
  }
  return e;
}

Eigen::MatrixXd unit_states(const CncModel& model) {
  const auto nb = static_cast<Eigen::Index>(model.basis.size());
  return Eigen::MatrixXd::Identity(nb, nb);
}

Eigen::MatrixXd basis_states(const CncModel& model, const std::vector<std::string>& columns,
                             const Eigen::VectorXd& times, const Eigen::MatrixXd& values) {
  // One unit model per regressor: the Compensator's predictions are then the regressors, bound
  // to the columns by name and stepped the way compensate steps them.
  const auto nf = static_cast<Eigen::Index>(model.basis.size()) - 1;
  std::vector<FittedModel> unit(static_cast<std::size_t>(nf));
  for (Eigen::Index k = 0; k < nf; ++k) {
    FittedModel& m = unit[static_cast<std::size_t>(k)];
    m.spec.kind = ModelKind::least_squares;
    m.features = model.features;
    m.target_name = model.basis[static_cast<std::size_t>(k + 1)];
    m.body = LinearFit{0.0, Eigen::VectorXd::Unit(nf, k)};
  }
  Eigen::MatrixXd states = Eigen::MatrixXd::Ones(times.size(), nf + 1);
  if (nf == 0) return states;
  std::vector<std::string> needed = model.features.sensor_names;
  needed.insert(needed.end(), model.features.input_names.begin(), model.features.input_names.end());
  for (const std::string& name : needed)
    if (std::find(columns.begin(), columns.end(), name) == columns.end()) {
      const std::string listed = core::joined(columns);
      throw core::DataError("column '" + name + "' is missing: the exported models read '" + name +
                            "'; the samples have " + (listed.empty() ? "none" : listed));
    }
  Compensator stepper(unit, columns);
  for (Eigen::Index t = 0; t < times.size(); ++t) {
    const LiveStep& step = stepper.next(times(t), values.row(t).transpose());
    if (step.status == SampleStatus::late || step.status == SampleStatus::waiting)
      throw core::DataError("temperature states: sample " + std::to_string(t + 1) + " at " +
                            std::to_string(times(t)) + " s is " + status_name(step.status) +
                            "; expected ascending times and every reading of the first sample");
    states.block(t, 1, 1, nf) = step.predicted.transpose();
  }
  return states;
}

ControllerLaw controller_law(CncFormat format, const CncModel& model, int table_points) {
  switch (format) {
    case CncFormat::sinumerik:
      return line_law(model);
    case CncFormat::twincat:
      return table_law(model, table_points, 0.0, false);
    case CncFormat::heidenhain:
      return table_law(model, table_points, 1e-7, false);
    case CncFormat::linuxcnc:
      return polynomial_law(model, kLinuxcncScaleMm / core::kMillimetresPerMetre, true);
  }
  throw core::DataError("unknown controller format");
}

}  // namespace tt::fitting
