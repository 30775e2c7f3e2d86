#include "studies/fit_from_data.hpp"

#include "fitting/models.hpp"
#include "placement/place.hpp"
#include "studies/placement_input.hpp"

namespace tt::studies {
namespace {

/// The candidate sensors ranked on the training groups laid end to end (for the network).
placement::PlacementResult placed_on(const std::vector<fitting::Group>& groups,
                                     std::uint64_t seed) {
  std::vector<int> all(groups.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  const auto sensors = static_cast<Eigen::Index>(groups.front().sensor_names.size());
  const placement::PlacementInput in =
      groups_end_to_end(groups, all, Eigen::MatrixX3d::Zero(sensors, 3),
                        static_cast<Eigen::Index>(groups.front().target_names.size()));
  placement::PlacementOptions options;
  options.samples =
      400;  // resampled: the MI searches need no more than this, the runs have 10^4 rows
  options.m_max = 4;
  options.seed = seed;
  options.mirror_twins = false;
  return placement::place_all(in, options);
}

/// Error column `target` of the groups, less the model's prediction when given, stacked [m].
Eigen::VectorXd stacked_residual(const std::vector<fitting::Group>& groups, int target,
                                 const fitting::FittedModel* model) {
  Eigen::Index n = 0;
  for (const auto& g : groups) n += g.time.size();
  Eigen::VectorXd r(n);
  Eigen::Index at = 0;
  for (const auto& g : groups) {
    r.segment(at, g.time.size()) = g.error.col(target);
    if (model) r.segment(at, g.time.size()) -= fitting::predicted_error(*model, g);
    at += g.time.size();
  }
  return r;
}

WindowPrediction continuous_prediction(const fitting::FittedModel& chosen,
                                       const fitting::Segment& whole, double from, double to) {
  const auto& g = whole.group;
  const auto inside = [&](Eigen::Index i) { return g.time(i) >= from && g.time(i) < to; };
  std::vector<bool> fit_row(static_cast<std::size_t>(g.time.size()));
  std::vector<Eigen::Index> rows;
  for (Eigen::Index i = 0; i < g.time.size(); ++i) {
    fit_row[static_cast<std::size_t>(i)] = !inside(i);
    if (inside(i)) rows.push_back(i);
  }
  const Eigen::VectorXd all = fitting::refitted_prediction(chosen, g, fit_row);
  const auto n = static_cast<Eigen::Index>(rows.size());
  WindowPrediction w{Eigen::VectorXd(n), Eigen::VectorXd(n), Eigen::VectorXd(n)};
  for (Eigen::Index k = 0; k < n; ++k) {
    const Eigen::Index i = rows[static_cast<std::size_t>(k)];
    w.time(k) = g.time(i);
    w.measured(k) = g.error(i, chosen.target);
    w.predicted(k) = all(i);
  }
  return w;
}

double window_mae(const WindowPrediction& w) {
  return core::error_figures(w.measured - w.predicted).mae;
}

/// The network on the grey relational sensors, on the inputs of the linear model chosen in `e`
/// (that model its linear skip) and on the best ridge's (that ridge its skip), beside the linear
/// models.
std::vector<fitting::Candidate> with_networks(std::vector<fitting::Candidate> candidates,
                                              const placement::PlacementResult& placed,
                                              const fitting::Evaluation& e, int target,
                                              bool has_speed) {
  for (const auto& set : network_sensor_sets(placed, target))
    candidates.push_back({set, driver_network_spec(1)});
  candidates.push_back(linear_inputs_network(e.model, 1));
  if (auto c = ridge_skip_network(e, 1, has_speed)) candidates.push_back(*c);
  return candidates;
}

struct Split {
  std::vector<fitting::Group> groups;
  std::vector<int> pool, test;
};

DataFitChannel channel_fit(const DataFitInput& in, const Split& s, int target,
                           const std::vector<fitting::Candidate>& candidates,
                           const std::optional<placement::PlacementResult>& placed) {
  DataFitChannel ch;
  ch.evaluation = fitting::blocked_evaluation(s.groups, s.pool, s.test, target, candidates);
  if (placed)
    ch.evaluation = fitting::blocked_evaluation(
        s.groups, s.pool, s.test, target,
        with_networks(candidates, *placed, ch.evaluation, target, in.has_speed));
  const auto& e = ch.evaluation;
  const std::vector<fitting::Group> tests = fitting::group_subset(s.groups, s.test);
  ch.test = core::error_figures(stacked_residual(tests, target, &e.model));
  ch.uncompensated = core::error_figures(stacked_residual(tests, target, nullptr));
  if (in.windowed_run)
    ch.window = continuous_prediction(e.model, *in.windowed_run, in.test_from_s, in.test_to_s);
  if (!in.network) return ch;
  auto n = network_figures(e, fitting::group_subset(s.groups, s.pool), tests);
  if (!n) return ch;
  const core::ErrorFigures figures =
      core::error_figures(stacked_residual(tests, target, &n->model));
  DataFitNetwork net{std::move(*n), figures, std::nullopt};
  if (in.windowed_run)
    net.window_mae_continuous = window_mae(
        continuous_prediction(net.figures.model, *in.windowed_run, in.test_from_s, in.test_to_s));
  ch.network = std::move(net);
  return ch;
}

}  // namespace

std::vector<fitting::Group> DataFitReport::test_groups() const {
  std::vector<fitting::Group> out;
  for (std::size_t i = blocks; i < segments.size(); ++i) out.push_back(segments[i].group);
  return out;
}

DataFitReport fit_from_data(const DataFitInput& input, const DataFitProgress& progress) {
  const fitting::Blocks blocks = fitting::cross_validation_blocks(input.training_pieces);
  DataFitReport report;
  report.segments = blocks.segments;
  report.blocks = blocks.segments.size();
  report.segments.insert(report.segments.end(), input.testing.begin(), input.testing.end());
  report.block_origin = (input.has_speed ? "speed cycles of "
                                         : "whole runs (no speed input, so no speed cycles) of ") +
                        std::to_string(input.training_runs) + " run(s); " + blocks.origin;
  Split s{fitting::segment_groups(report.segments), {}, {}};
  for (std::size_t i = 0; i < report.segments.size(); ++i)
    (i < report.blocks ? s.pool : s.test).push_back(static_cast<int>(i));
  report.channel_count = s.groups.front().target_names.size();
  if (progress) progress(report);
  const auto training = fitting::group_subset(s.groups, s.pool);
  report.out_of_range =
      fitting::out_of_training_range(training, fitting::group_subset(s.groups, s.test));
  // With the network: the grey relational grade's sensors, for the network only (seed 004).
  std::optional<placement::PlacementResult> placed;
  if (input.network) placed = placed_on(training, 1);
  const auto candidates = fitting::measured_data_candidates(
      static_cast<int>(s.groups.front().sensor_names.size()), input.has_speed, input.quick);
  for (int target = 0; target < static_cast<int>(report.channel_count); ++target) {
    report.channels.push_back(channel_fit(input, s, target, candidates, placed));
    if (progress) progress(report);
  }
  return report;
}

}  // namespace tt::studies
