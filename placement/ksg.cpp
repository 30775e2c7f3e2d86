#include "placement/ksg.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <string>

#include "core/errors.hpp"
#include "core/parallel.hpp"
#include "core/rng.hpp"
#include "core/timing.hpp"
#include "placement/random.hpp"

namespace tt::placement {

using core::seconds_since;

namespace {

/// ψ(n) for integers n >= 1: ψ(1) = −γ, ψ(n + 1) = ψ(n) + 1/n.
std::vector<double> digamma_table(int n_max) {
  std::vector<double> psi(static_cast<std::size_t>(n_max) + 1, 0.0);
  psi[1] = -0.57721566490153286061;
  for (int n = 1; n < n_max; ++n)
    psi[static_cast<std::size_t>(n) + 1] = psi[static_cast<std::size_t>(n)] + 1.0 / n;
  return psi;
}

/// Points stored row by row: sample s occupies [s·d, (s+1)·d).
double ksg_rows(const std::vector<double>& x, int dx, const std::vector<double>& y, int dy,
                int samples, int k) {
  if (k < 1 || k >= samples)
    throw core::DataError("placement.ksg_k = " + std::to_string(k) + " with " +
                          std::to_string(samples) +
                          " samples: expected 1 <= k < #samples (3 to 5)");
  const auto psi = digamma_table(samples + 1);
  const auto n = static_cast<std::size_t>(samples);
  std::vector<double> ex(n), ey(n), joint(n);
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      double a = 0.0, b = 0.0;
      for (int d = 0; d < dx; ++d) a = std::max(a, std::abs(x[i * dx + d] - x[j * dx + d]));
      for (int d = 0; d < dy; ++d) b = std::max(b, std::abs(y[i * dy + d] - y[j * dy + d]));
      ex[j] = a;
      ey[j] = b;
      joint[j] = std::max(a, b);
    }
    joint[i] = std::numeric_limits<double>::infinity();  // a point is not its own neighbour
    std::nth_element(joint.begin(), joint.begin() + (k - 1), joint.end());
    const double eps = joint[static_cast<std::size_t>(k - 1)];
    int nx = 0, ny = 0;
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      nx += ex[j] < eps;
      ny += ey[j] < eps;
    }
    sum += psi[static_cast<std::size_t>(nx) + 1] + psi[static_cast<std::size_t>(ny) + 1];
  }
  const double nats = psi[static_cast<std::size_t>(k)] + psi[n] - sum / samples;
  return nats / std::numbers::ln2;
}

std::vector<double> rows_of(const Eigen::MatrixXd& m, std::span<const int> columns) {
  const auto d = columns.size();
  std::vector<double> out(static_cast<std::size_t>(m.rows()) * d);
  for (Eigen::Index s = 0; s < m.rows(); ++s)
    for (std::size_t c = 0; c < d; ++c) out[static_cast<std::size_t>(s) * d + c] = m(s, columns[c]);
  return out;
}

/// Best admissible entry of `score` (ties to the lower pool position), or -1.
std::ptrdiff_t best_of(const std::vector<double>& score, const std::vector<char>& admissible) {
  std::ptrdiff_t best = -1;
  for (std::size_t i = 0; i < score.size(); ++i)
    if (admissible[i] && (best < 0 || score[i] > score[static_cast<std::size_t>(best)]))
      best = static_cast<std::ptrdiff_t>(i);
  return best;
}

}  // namespace

double ksg_mi_bits(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y, int k) {
  if (x.rows() != y.rows())
    throw core::DataError("placement: KSG on " + std::to_string(x.rows()) + " and " +
                          std::to_string(y.rows()) + " samples: expected equal counts");
  std::vector<int> cx(static_cast<std::size_t>(x.cols())), cy(static_cast<std::size_t>(y.cols()));
  for (std::size_t i = 0; i < cx.size(); ++i) cx[i] = static_cast<int>(i);
  for (std::size_t i = 0; i < cy.size(); ++i) cy[i] = static_cast<int>(i);
  return ksg_rows(rows_of(x, cx), static_cast<int>(x.cols()), rows_of(y, cy),
                  static_cast<int>(y.cols()), static_cast<int>(x.rows()), k);
}

KsgProblem ksg_problem(const LinearProblem& problem, int k, std::uint64_t seed) {
  KsgProblem p;
  p.k = k;
  const double scale = std::sqrt(static_cast<double>(problem.z.rows()));  // unit variance
  p.x = problem.z * scale;
  p.y = problem.y * scale;
  std::mt19937_64 gen = core::generator(seed, 0);
  for (Eigen::Index j = 0; j < p.x.cols(); ++j)
    for (Eigen::Index s = 0; s < p.x.rows(); ++s) p.x(s, j) += 1e-10 * (uniform_unit(gen) - 0.5);
  for (Eigen::Index s = 0; s < p.y.size(); ++s) p.y(s) += 1e-10 * (uniform_unit(gen) - 0.5);
  return p;
}

double ksg_set_bits(const KsgProblem& problem, std::span<const int> set) {
  const std::vector<double> y(problem.y.data(), problem.y.data() + problem.y.size());
  return ksg_rows(rows_of(problem.x, set), static_cast<int>(set.size()), y, 1,
                  static_cast<int>(problem.y.size()), problem.k);
}

GreedyPath ksg_greedy(const KsgProblem& problem, const LinearProblem& linear,
                      std::span<const int> pool, int m_max, const Collinearity& guard) {
  const auto start = std::chrono::steady_clock::now();
  GreedyPath path;
  std::vector<double> score(pool.size());
  std::vector<char> ok(pool.size());
  for (int step = 0; step < m_max; ++step) {
    core::parallel_for(static_cast<std::ptrdiff_t>(pool.size()), [&](std::ptrdiff_t i) {
      const int c = pool[static_cast<std::size_t>(i)];
      ok[i] = std::find(path.order.begin(), path.order.end(), c) == path.order.end() &&
              adds_direction(linear, path.order, c, guard);
      if (!ok[i]) return;
      std::vector<int> set = path.order;
      set.push_back(c);
      score[i] = ksg_set_bits(problem, set);
    });
    const auto best = best_of(score, ok);
    if (best < 0) break;
    path.order.push_back(pool[static_cast<std::size_t>(best)]);
    path.scores.push_back(score[static_cast<std::size_t>(best)]);
    path.seconds.push_back(seconds_since(start));
  }
  return path;
}

GreedyPath jmi_greedy(const KsgProblem& problem, const LinearProblem& linear,
                      std::span<const int> pool, int m_max, const Collinearity& guard) {
  const auto start = std::chrono::steady_clock::now();
  GreedyPath path;
  std::vector<double> jmi(pool.size(), 0.0);  // Σ over chosen s of I(Y; T_c, T_s), or I(Y; T_c)
  std::vector<char> ok(pool.size());
  for (int step = 0; step < m_max; ++step) {
    const int last = path.order.empty() ? -1 : path.order.back();
    core::parallel_for(static_cast<std::ptrdiff_t>(pool.size()), [&](std::ptrdiff_t i) {
      const int c = pool[static_cast<std::size_t>(i)];
      ok[i] = std::find(path.order.begin(), path.order.end(), c) == path.order.end() &&
              adds_direction(linear, path.order, c, guard);
      if (!ok[i]) return;
      if (last < 0) {
        const int set[1] = {c};
        jmi[i] = ksg_set_bits(problem, set);
      } else {
        if (step == 1) jmi[i] = 0.0;  // the single-sensor term is replaced by the pair sums
        const int set[2] = {c, last};
        jmi[i] += ksg_set_bits(problem, set);
      }
    });
    const auto best = best_of(jmi, ok);
    if (best < 0) break;
    path.order.push_back(pool[static_cast<std::size_t>(best)]);
    path.scores.push_back(ksg_set_bits(problem, path.order));
    path.seconds.push_back(seconds_since(start));
  }
  return path;
}

}  // namespace tt::placement
