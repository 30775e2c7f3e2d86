#include "placement/detection.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/errors.hpp"
#include "core/timing.hpp"

namespace tt::placement {

namespace {

[[noreturn]] void fail(const std::string& what) {
  throw core::DataError("placement for detection: " + what);
}

/// The largest over time of the smallest |value| over `w` consecutive readings, per row of
/// `history` (#rows x #readings).
Eigen::VectorXd held_largest(const Eigen::MatrixXd& history, int w) {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(history.rows());
  const Eigen::Index k = history.cols();
  for (Eigen::Index start = 0; start + w <= k; ++start)
    out = out.cwiseMax(history.middleCols(start, w).cwiseAbs().rowwise().minCoeff());
  return out;
}

}  // namespace

DetectionProblem detection_problem(const EstimationProblem& problem,
                                   const std::vector<std::string>& effects,
                                   std::span<const Eigen::Index> effect_states,
                                   const Eigen::VectorXd& sizes, int sustain_readings) {
  const auto ne = static_cast<Eigen::Index>(effect_states.size());
  if (effects.size() != effect_states.size() || sizes.size() != ne)
    fail(std::to_string(effects.size()) + " effect names, " + std::to_string(ne) + " states and " +
         std::to_string(sizes.size()) + " sizes: expected one of each per effect");
  if (sustain_readings < 1)
    fail("held over " + std::to_string(sustain_readings) + " readings: expected at least 1");
  if (problem.tracks.empty()) fail("no run");
  const Eigen::Index n = problem.tracks.front().initial.rows();
  for (Eigen::Index e = 0; e < ne; ++e) {
    if (effect_states[static_cast<std::size_t>(e)] < 0 ||
        effect_states[static_cast<std::size_t>(e)] >= n)
      fail("effect '" + effects[static_cast<std::size_t>(e)] + "' at state " +
           std::to_string(effect_states[static_cast<std::size_t>(e)]) + " of " + std::to_string(n));
    if (!(sizes(e) > 0) || !std::isfinite(sizes(e)))
      fail("effect '" + effects[static_cast<std::size_t>(e)] + "' of size " +
           std::to_string(sizes(e)) + ": expected a finite size > 0");
  }
  if (problem.candidate_rows.cols() != n ||
      problem.candidate_sigma.size() != problem.candidate_rows.rows())
    fail("candidate rows of " + std::to_string(problem.candidate_rows.cols()) + " states and " +
         std::to_string(problem.candidate_sigma.size()) + " sigmas for " +
         std::to_string(problem.candidate_rows.rows()) + " candidates; the filter has " +
         std::to_string(n) + " states");
  const Eigen::Index nc = problem.candidate_rows.rows();
  DetectionProblem out;
  out.effects = effects;
  out.held_sigmas = Eigen::MatrixXd::Zero(ne, nc);
  const Eigen::VectorXd inverse_sigma = problem.candidate_sigma.cwiseInverse();
  for (const CovarianceTrack& track : problem.tracks) {
    // The deviation from the declared run each effect makes: its input held at its size.
    Eigen::MatrixXd d = Eigen::MatrixXd::Zero(n, ne);
    for (Eigen::Index e = 0; e < ne; ++e)
      d(effect_states[static_cast<std::size_t>(e)], e) = sizes(e);
    const auto k = static_cast<Eigen::Index>(track.transitions.size());
    // Per candidate, the reading's change in sigmas at each reading: (#effects x #candidates) x k.
    Eigen::MatrixXd history(ne * nc, k);
    for (Eigen::Index i = 0; i < k; ++i) {
      d = track.transitions[static_cast<std::size_t>(i)] * d;
      const Eigen::MatrixXd seen =
          (problem.candidate_rows * d).transpose() * inverse_sigma.asDiagonal();
      history.col(i) = Eigen::Map<const Eigen::VectorXd>(seen.data(), ne * nc);
    }
    const Eigen::VectorXd held = held_largest(history, sustain_readings);
    out.held_sigmas =
        out.held_sigmas.cwiseMax(Eigen::Map<const Eigen::MatrixXd>(held.data(), ne, nc));
  }
  return out;
}

DetectionProblem detection_problem(const std::vector<std::string>& effects,
                                   const std::vector<std::vector<Eigen::MatrixXd>>& changes,
                                   const Eigen::VectorXd& sigma, int sustain_readings) {
  if (effects.size() != changes.size())
    fail(std::to_string(effects.size()) + " effect names and " + std::to_string(changes.size()) +
         " effects' changes: expected one of each per effect");
  if (sustain_readings < 1)
    fail("held over " + std::to_string(sustain_readings) + " readings: expected at least 1");
  if (!(sigma.array() > 0).all() || !sigma.allFinite())
    fail("a candidate's sigma that is not finite and > 0");
  const auto ne = static_cast<Eigen::Index>(effects.size());
  DetectionProblem out;
  out.effects = effects;
  out.held_sigmas = Eigen::MatrixXd::Zero(ne, sigma.size());
  for (Eigen::Index e = 0; e < ne; ++e) {
    const auto& runs = changes[static_cast<std::size_t>(e)];
    if (runs.empty()) fail("effect '" + effects[static_cast<std::size_t>(e)] + "' on no run");
    for (const Eigen::MatrixXd& change : runs) {
      if (change.cols() != sigma.size())
        fail("effect '" + effects[static_cast<std::size_t>(e)] + "' changes " +
             std::to_string(change.cols()) + " candidates' readings; " +
             std::to_string(sigma.size()) + " have a sigma");
      const Eigen::MatrixXd in_sigmas = (change * sigma.cwiseInverse().asDiagonal()).transpose();
      out.held_sigmas.row(e) =
          out.held_sigmas.row(e).cwiseMax(held_largest(in_sigmas, sustain_readings).transpose());
    }
  }
  return out;
}

Eigen::VectorXd weights_per_kind(const std::vector<std::string>& kinds) {
  Eigen::VectorXd w(static_cast<Eigen::Index>(kinds.size()));
  for (std::size_t e = 0; e < kinds.size(); ++e)
    w(static_cast<Eigen::Index>(e)) =
        1.0 / static_cast<double>(std::count(kinds.begin(), kinds.end(), kinds[e]));
  return w;
}

std::vector<int> unseen_effects(const DetectionProblem& problem, std::span<const int> columns,
                                double bound) {
  std::vector<int> out;
  for (Eigen::Index e = 0; e < problem.held_sigmas.rows(); ++e) {
    const bool seen = std::any_of(columns.begin(), columns.end(),
                                  [&](int c) { return problem.held_sigmas(e, c) >= bound; });
    if (!seen) out.push_back(static_cast<int>(e));
  }
  return out;
}

double seen_weight(const DetectionProblem& problem, std::span<const int> columns, double bound) {
  const auto ne = problem.held_sigmas.rows();
  double seen = 0;
  for (Eigen::Index e = 0; e < ne; ++e)
    if (std::any_of(columns.begin(), columns.end(),
                    [&](int c) { return problem.held_sigmas(e, c) >= bound; }))
      seen += problem.weights.size() == ne ? problem.weights(e) : 1.0;
  return seen;
}

GreedyPath detection_greedy(const DetectionProblem& problem, std::span<const int> chosen,
                            std::span<const int> pool, int m_max, double bound) {
  if (!(bound > 0) || !std::isfinite(bound))
    fail("a bound of " + std::to_string(bound) + " sigma: expected a finite bound > 0");
  const Eigen::Index nc = problem.held_sigmas.cols(), ne = problem.held_sigmas.rows();
  for (std::span<const int> set : {chosen, pool})
    for (int c : set)
      if (c < 0 || c >= nc)
        fail("candidate column " + std::to_string(c) + " of " + std::to_string(nc));
  const Eigen::VectorXd weight =
      problem.weights.size() == 0 ? Eigen::VectorXd::Ones(ne) : problem.weights;
  if (weight.size() != ne || !weight.allFinite() || (weight.array() < 0).any())
    fail(std::to_string(problem.weights.size()) + " weights for " + std::to_string(ne) +
         " effects: expected one finite weight >= 0 per effect");
  const auto start = std::chrono::steady_clock::now();
  std::vector<int> columns(chosen.begin(), chosen.end());
  std::vector<int> unseen = unseen_effects(problem, columns, bound);
  GreedyPath path;
  for (int step = 0; step < m_max; ++step) {
    // Per unseen effect, how far the chosen sensors already get towards the bound.
    std::vector<double> already(unseen.size(), 0.0);
    for (std::size_t u = 0; u < unseen.size(); ++u)
      for (int s : columns) already[u] = std::max(already[u], problem.held_sigmas(unseen[u], s));
    // Per candidate: the effects it would add, then the progress beyond that towards the rest.
    int best = -1;
    std::pair<double, double> best_gain{0.0, 0.0};
    for (int c : pool) {
      if (std::find(columns.begin(), columns.end(), c) != columns.end()) continue;
      std::pair<double, double> gain{0.0, 0.0};
      for (std::size_t u = 0; u < unseen.size(); ++u) {
        const double held = problem.held_sigmas(unseen[u], c), w = weight(unseen[u]);
        gain.first += held >= bound ? w : 0.0;
        gain.second += w * std::max(0.0, std::min(held, bound) - already[u]);
      }
      const bool adds = gain.first > 0 || gain.second > 0;
      if (adds && (gain > best_gain || (gain == best_gain && c < best))) {
        best_gain = gain;
        best = c;
      }
    }
    if (best < 0) break;  // no candidate adds anything
    columns.push_back(best);
    unseen = unseen_effects(problem, columns, bound);
    path.order.push_back(best);
    path.scores.push_back(seen_weight(problem, columns, bound));
    path.seconds.push_back(core::seconds_since(start));
  }
  return path;
}

}  // namespace tt::placement
