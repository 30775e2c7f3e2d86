#include "fitting/ppr.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "core/errors.hpp"
#include "core/rng.hpp"

namespace tt::fitting {

namespace {

double to_t(double z, double low, double high) {
  const double width = high - low;
  return width > 0.0 ? (2.0 * z - low - high) / width : 0.0;
}

/// f(t) and df/dt of the polynomial, extended along its tangent outside [−1, 1].
std::pair<double, double> polynomial_value(const Eigen::VectorXd& c, double t) {
  const double inside = std::clamp(t, -1.0, 1.0);
  double value = 0.0;
  double slope = 0.0;
  for (Eigen::Index k = c.size() - 1; k >= 0; --k) {
    slope = slope * inside + value;
    value = value * inside + c(k);
  }
  return {value + slope * (t - inside), slope};
}

struct Projection {
  Eigen::VectorXd direction;
  double z_low = 0.0;
  double z_high = 0.0;
  Eigen::VectorXd polynomial;
  double sse = 0.0;
};

/// Least-squares polynomial of the projections z fitted to r.
Projection polynomial_fit(const Eigen::VectorXd& direction, const Eigen::VectorXd& z,
                          const Eigen::VectorXd& r, int degree) {
  Projection p;
  p.direction = direction;
  p.z_low = z.minCoeff();
  p.z_high = z.maxCoeff();
  Eigen::MatrixXd v(z.size(), degree + 1);
  for (Eigen::Index i = 0; i < z.size(); ++i) {
    const double t = to_t(z(i), p.z_low, p.z_high);
    double power = 1.0;
    for (int k = 0; k <= degree; ++k, power *= t) v(i, k) = power;
  }
  p.polynomial = v.colPivHouseholderQr().solve(r);
  p.sse = (v * p.polynomial - r).squaredNorm();
  return p;
}

/// Gauss–Newton on the direction with the polynomial refitted at every step.
Projection refined(Projection p, const Eigen::MatrixXd& xs, const Eigen::VectorXd& r, int degree) {
  const Eigen::Index n = xs.rows();
  for (int iteration = 0; iteration < 12; ++iteration) {
    const Eigen::VectorXd z = xs * p.direction;
    const double width = p.z_high - p.z_low;
    if (!(width > 0.0)) break;
    Eigen::VectorXd f(n);
    Eigen::VectorXd dfdz(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto [value, slope] = polynomial_value(p.polynomial, to_t(z(i), p.z_low, p.z_high));
      f(i) = value;
      dfdz(i) = slope * 2.0 / width;
    }
    const Eigen::MatrixXd jacobian = dfdz.asDiagonal() * xs;
    Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
    normal.diagonal().array() += 1e-9 * (normal.trace() + 1e-300);
    const Eigen::VectorXd step = normal.ldlt().solve(jacobian.transpose() * (r - f));
    bool improved = false;
    for (double fraction = 1.0; fraction > 1.0 / 64.0; fraction *= 0.5) {
      Eigen::VectorXd a = p.direction + fraction * step;
      const double norm = a.norm();
      if (!(norm > 0.0) || !a.allFinite()) continue;
      a /= norm;
      const Projection trial = polynomial_fit(a, xs * a, r, degree);
      if (trial.sse < p.sse) {
        improved = trial.sse < p.sse * (1.0 - 1e-7);
        p = trial;
        break;
      }
    }
    if (!improved) break;
  }
  return p;
}

RidgeFunction as_ridge(const Projection& p, double sst, int cluster_size) {
  RidgeFunction ridge;
  ridge.direction = p.direction;
  ridge.z_low = p.z_low;
  ridge.z_high = p.z_high;
  ridge.polynomial = p.polynomial;
  ridge.r_squared = sst > 0.0 ? 1.0 - p.sse / sst : 0.0;
  ridge.cluster_size = cluster_size;
  return ridge;
}

Projection as_projection(const RidgeFunction& ridge, const Eigen::MatrixXd& xs,
                         const Eigen::VectorXd& r, int degree) {
  return polynomial_fit(ridge.direction, xs * ridge.direction, r, degree);
}

double centred_sum_of_squares(const Eigen::VectorXd& r) {
  return (r.array() - r.mean()).matrix().squaredNorm();
}

/// The seed's step: random directions scored by R², the cluster within ε of the best averaged
/// into one direction.
RidgeFunction best_ridge(const Eigen::MatrixXd& xs, const Eigen::VectorXd& r,
                         const PprOptions& options, std::uint64_t stream) {
  const Eigen::Index p = xs.cols();
  std::mt19937_64 rng = core::generator(options.seed, stream);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::MatrixXd directions(p, options.directions);
  for (int j = 0; j < options.directions; ++j) {
    double norm = 0.0;
    while (!(norm > 1e-6)) {
      for (Eigen::Index k = 0; k < p; ++k) directions(k, j) = uniform(rng);
      norm = directions.col(j).norm();
    }
    directions.col(j) /= norm;
  }
  const Eigen::MatrixXd z = xs * directions;
  const double sst = centred_sum_of_squares(r);
  std::vector<double> r2(static_cast<std::size_t>(options.directions));
  std::vector<Projection> fits;
  fits.reserve(r2.size());
  for (int j = 0; j < options.directions; ++j) {
    fits.push_back(polynomial_fit(directions.col(j), z.col(j), r, options.degree));
    r2[static_cast<std::size_t>(j)] = sst > 0.0 ? 1.0 - fits.back().sse / sst : 0.0;
  }
  const auto best = static_cast<int>(std::max_element(r2.begin(), r2.end()) - r2.begin());
  Eigen::VectorXd mean_direction = Eigen::VectorXd::Zero(p);
  int cluster_size = 0;
  for (int j = 0; j < options.directions; ++j) {
    if (r2[static_cast<std::size_t>(j)] <
        r2[static_cast<std::size_t>(best)] - options.cluster_epsilon)
      continue;
    // A polynomial does not care about the sign of its argument; align before averaging.
    const double sign = directions.col(j).dot(directions.col(best)) < 0.0 ? -1.0 : 1.0;
    mean_direction += sign * directions.col(j);
    ++cluster_size;
  }
  Projection chosen = fits[static_cast<std::size_t>(best)];
  if (mean_direction.norm() > 1e-12) {
    mean_direction.normalize();
    Projection centre = polynomial_fit(mean_direction, xs * mean_direction, r, options.degree);
    if (centre.sse <= chosen.sse) chosen = centre;
  }
  if (options.refine) chosen = refined(chosen, xs, r, options.degree);
  return as_ridge(chosen, sst, cluster_size);
}

Eigen::MatrixXd standardised(const PprModel& model, const Eigen::MatrixXd& x) {
  return (x.rowwise() - model.center.transpose()) * model.scale.cwiseInverse().asDiagonal();
}

void require_options(const PprOptions& o) {
  if (o.directions < 1 || o.degree < 1 || o.max_terms < 1)
    throw core::DataError("PPR options: directions = " + std::to_string(o.directions) +
                          ", degree = " + std::to_string(o.degree) +
                          ", max_terms = " + std::to_string(o.max_terms) + "; each must be >= 1");
  if (!(o.cluster_epsilon >= 0.0) || !(o.relative_error_goal >= 0.0) || !(o.min_gain >= 0.0))
    throw core::DataError(
        "PPR options: cluster_epsilon, relative_error_goal and min_gain must "
        "be >= 0");
}

}  // namespace

Eigen::VectorXd ridge_values(const RidgeFunction& ridge, const Eigen::MatrixXd& xs) {
  const Eigen::VectorXd z = xs * ridge.direction;
  Eigen::VectorXd f(z.size());
  for (Eigen::Index i = 0; i < z.size(); ++i)
    f(i) = polynomial_value(ridge.polynomial, to_t(z(i), ridge.z_low, ridge.z_high)).first;
  return f;
}

PprModel ppr_fit(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const PprOptions& options) {
  require_options(options);
  const Eigen::Index n = x.rows();
  if (y.size() != n)
    throw core::DataError("PPR fit: " + std::to_string(n) + " input rows but " +
                          std::to_string(y.size()) + " errors");
  if (n < options.degree + 2)
    throw core::DataError("PPR fit: " + std::to_string(n) +
                          " samples for ridge polynomials of "
                          "degree " +
                          std::to_string(options.degree) +
                          "; hint: more readings or a lower degree");
  PprModel model;
  model.center = x.colwise().mean().transpose();
  model.scale.resize(x.cols());
  for (Eigen::Index k = 0; k < x.cols(); ++k) {
    const double s =
        std::sqrt((x.col(k).array() - model.center(k)).square().sum() / static_cast<double>(n));
    model.scale(k) = s > 0.0 ? s : 1.0;
  }
  const Eigen::MatrixXd xs = standardised(model, x);
  model.mean = y.mean();
  const double sst_y = centred_sum_of_squares(y);
  Eigen::VectorXd residual = y.array() - model.mean;
  if (!(sst_y > 0.0)) return model;

  for (int m = 0; m < options.max_terms; ++m) {
    RidgeFunction ridge = best_ridge(xs, residual, options, static_cast<std::uint64_t>(m));
    if (m > 0 && ridge.r_squared < options.min_gain) break;
    residual -= ridge_values(ridge, xs);
    model.terms.push_back(ridge);
    if (options.refine && model.terms.size() > 1) {
      for (int pass = 0; pass < 2; ++pass)
        for (RidgeFunction& term : model.terms) {
          const Eigen::VectorXd partial = residual + ridge_values(term, xs);
          const double sst = centred_sum_of_squares(partial);
          const Projection p = refined(as_projection(term, xs, partial, options.degree), xs,
                                       partial, options.degree);
          term = as_ridge(p, sst, term.cluster_size);
          residual = partial - ridge_values(term, xs);
        }
    }
    if (std::sqrt(residual.squaredNorm() / sst_y) < options.relative_error_goal) break;
  }
  return model;
}

Eigen::VectorXd ppr_prediction(const PprModel& model, const Eigen::MatrixXd& x) {
  if (x.cols() != model.center.size())
    throw core::DataError("PPR prediction: " + std::to_string(x.cols()) +
                          " inputs for a model of " + std::to_string(model.center.size()));
  const Eigen::MatrixXd xs = standardised(model, x);
  Eigen::VectorXd prediction = Eigen::VectorXd::Constant(x.rows(), model.mean);
  for (const RidgeFunction& ridge : model.terms) prediction += ridge_values(ridge, xs);
  return prediction;
}

}  // namespace tt::fitting
