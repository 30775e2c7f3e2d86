// thermotwin fit --data: thermal-error models fitted on measured runs with no machine model behind
// them (DB3401/T 326-2024 metrics S, S_M, S_sigma, and the error on held-out data).
//   thermotwin fit --data RUN... --out DIR [--test RUN... | --test-from-s T0 --test-to-s T1]
//                  [--quick]
// Any run shape: with or without a speed input, one long run or many short ones, days as runs.
// 1. The held-out data: the runs given with --test, else a time window (given, or the published
//    figure's), else the last run when there are 3 or more, else the last 30 % of the last run
//    (with a speed: from the start of its last speed cycle that begins by 70 % of it).
//    Every other row fits and validates. Runs are cut at their speed cycles (a start after a
//    stop) when they have a speed, kept whole when not; when that gives fewer than 4 pieces each
//    is cut into time blocks of equal duration (fitting::cross_validation_blocks). Every piece's
//    drift is re-zeroed at its first reading, as the standard's intercept assumes.
// 2. Candidates: no compensation; least squares with and without the standard's 3σ criterion,
//    ridge and ridge on the temperatures with their first-order lags (600 s, 3600 s) and the
//    speed, on all sensors, over a grid of ridge strengths (--quick: a coarser grid);
//    fitting::measured_data_candidates, which calibrate without --case chooses among too.
// 3. Per displacement channel, blocked cross-validation (each piece held out in turn) chooses the
//    lowest mean held-out S², guarded by one standard error against no compensation
//    (fitting::blocked_evaluation); the choice is refitted on all training pieces and tested on
//    the held-out data, beside the uncompensated drift. Test inputs outside the training range
//    are flagged.
// 4. With a time window inside a run, the error on the window is also reported continuously (the
//    chosen form refitted on the whole run outside the window, temperatures from the run's start).
// Writes fit.json, summary.md, compensation.csv, window_<channel>.csv/.png (window mode).
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include "app/commands.hpp"
#include "app/network_candidate.hpp"
#include "core/errors.hpp"
#include "fitting/features.hpp"
#include "fitting/linear.hpp"
#include "fitting/models.hpp"
#include "fitting/segments.hpp"
#include "fitting/selection.hpp"
#include "io/atomic_dir.hpp"
#include "io/csv_out.hpp"
#include "io/fitting_out.hpp"
#include "io/measured_data.hpp"
#include "io/measured_segments.hpp"
#include "io/reports.hpp"
#include "placement/place.hpp"
#include "studies/placement_input.hpp"

namespace tt::app {
namespace {

/// The chosen model form refitted on the whole run outside [from, to): one group from the run's
/// start, fitted on the rows outside the window, predicting the rows inside. #window rows [m].
struct WindowPrediction {
  Eigen::VectorXd time, measured, predicted;
};

WindowPrediction continuous_prediction(const fitting::FittedModel& chosen,
                                       const fitting::Segment& whole, double from, double to) {
  const auto& g = whole.group;
  const Eigen::MatrixXd x = fitting::feature_matrix(chosen.features, g);
  std::vector<Eigen::Index> fit_rows, test_rows;
  for (Eigen::Index i = 0; i < g.time.size(); ++i)
    (g.time(i) >= from && g.time(i) < to ? test_rows : fit_rows).push_back(i);
  const auto rows_of = [&](const std::vector<Eigen::Index>& idx) {
    Eigen::MatrixXd out(static_cast<Eigen::Index>(idx.size()), x.cols());
    for (std::size_t k = 0; k < idx.size(); ++k)
      out.row(static_cast<Eigen::Index>(k)) = x.row(idx[k]);
    return out;
  };
  Eigen::VectorXd y(static_cast<Eigen::Index>(fit_rows.size()));
  for (std::size_t k = 0; k < fit_rows.size(); ++k)
    y(static_cast<Eigen::Index>(k)) = g.error(fit_rows[k], chosen.target);
  const Eigen::MatrixXd x_test = rows_of(test_rows);
  WindowPrediction w;
  if (chosen.spec.kind == fitting::ModelKind::no_compensation) {
    w.predicted = Eigen::VectorXd::Zero(x_test.rows());
  } else if (chosen.spec.kind == fitting::ModelKind::cnn_bigru_attention) {
    std::vector<bool> fit_row(static_cast<std::size_t>(g.time.size()));
    for (Eigen::Index i = 0; i < g.time.size(); ++i)
      fit_row[static_cast<std::size_t>(i)] = !(g.time(i) >= from && g.time(i) < to);
    const Eigen::VectorXd all = fitting::refitted_prediction(chosen, g, fit_row);
    w.predicted.resize(static_cast<Eigen::Index>(test_rows.size()));
    for (std::size_t k = 0; k < test_rows.size(); ++k)
      w.predicted(static_cast<Eigen::Index>(k)) = all(test_rows[k]);
  } else if (chosen.spec.kind == fitting::ModelKind::projection_pursuit) {
    const auto model = fitting::ppr_fit(rows_of(fit_rows), y, chosen.spec.ppr);
    w.predicted = fitting::ppr_prediction(model, x_test);
  } else {
    const auto fit = fitting::linear_fit(rows_of(fit_rows), y, chosen.spec.ridge_lambda);
    w.predicted = fitting::linear_prediction(fit, x_test);
  }
  w.time.resize(w.predicted.size());
  w.measured.resize(w.predicted.size());
  for (std::size_t k = 0; k < test_rows.size(); ++k) {
    w.time(static_cast<Eigen::Index>(k)) = g.time(test_rows[k]);
    w.measured(static_cast<Eigen::Index>(k)) = g.error(test_rows[k], chosen.target);
  }
  return w;
}

/// The candidate sensors ranked on the training groups laid end to end (for --network).
placement::PlacementResult placed_on(const std::vector<fitting::Group>& groups,
                                     std::uint64_t seed) {
  std::vector<int> all(groups.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  const auto sensors = static_cast<Eigen::Index>(groups.front().sensor_names.size());
  const placement::PlacementInput in =
      studies::groups_end_to_end(groups, all, Eigen::MatrixX3d::Zero(sensors, 3),
                                 static_cast<Eigen::Index>(groups.front().target_names.size()));
  placement::PlacementOptions options;
  options.samples =
      400;  // resampled: the MI searches need no more than this, the runs have 10^4 rows
  options.m_max = 4;
  options.seed = seed;
  options.mirror_twins = false;
  return placement::place_all(in, options);
}

double rms(const Eigen::VectorXd& r) {
  return r.size() ? std::sqrt(r.squaredNorm() / static_cast<double>(r.size())) : std::nan("");
}

double mean_abs(const Eigen::VectorXd& r) {
  return r.size() ? r.cwiseAbs().mean() : std::nan("");
}

std::string um(double metres, int digits = 2) {
  if (!std::isfinite(metres)) return "-";
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << metres * 1e6;
  return s.str();
}

}  // namespace

int fit_data_command(const FitDataArgs& args) {
  // 1. The runs; the held-out data; the training pieces as cross-validation blocks. The output
  //    is claimed first: one that is refused fails before any work.
  io::require_distinct_runs(args.runs, "--data");
  io::require_distinct_runs(args.test_runs, "--test");
  io::require_disjoint_runs(args.test_runs, args.runs, "--test", "--data",
                            "fit --data does not split a run; hint: hold out a time window with "
                            "--test-from-s/--test-to-s");
  std::vector<std::filesystem::path> inputs = args.runs;
  inputs.insert(inputs.end(), args.test_runs.begin(), args.test_runs.end());
  io::OutputDir out(args.out, inputs);
  std::vector<io::MeasuredRun> runs;
  const auto read = [&](const std::filesystem::path& folder) {
    runs.push_back(io::read_measured_run(folder));
  };
  for (const auto& folder : args.runs) read(folder);
  for (const auto& folder : args.test_runs) read(folder);
  const std::size_t training_runs = args.runs.size();
  if (!args.test_runs.empty() && (args.test_from_s || args.test_to_s))
    throw core::DataError(
        "fit --data: --test RUN... and --test-from-s/--test-to-s both given; hint: hold out whole "
        "runs or a time window, not both");
  const bool has_speed = io::measured_speed(runs[0]).size() != 0;
  for (const auto& r : runs) {
    if (r.displacements.empty() || r.sensors.empty())
      throw core::DataError(r.folder.string() +
                            ": no displacement or no temperature columns: nothing to fit");
    if (r.displacements.size() != runs[0].displacements.size() ||
        r.sensors.size() != runs[0].sensors.size())
      throw core::DataError(r.folder.string() + ": columns differ from " + runs[0].folder.string() +
                            ": every run must have the same sensors and displacements");
    if ((io::measured_speed(r).size() != 0) != has_speed)
      throw core::DataError(
          r.folder.string() + (has_speed ? " has no speed input but " : " has a speed input but ") +
          runs[0].folder.string() + (has_speed ? " has one" : " has none") +
          ": every run must have the same inputs; hint: drop the speed column from all runs, or "
          "give it in all");
  }
  // A published figure for the data (meta.json `published`) sets the default test window.
  const std::optional<io::PublishedFigure> published =
      args.test_runs.empty() ? runs.back().published : std::nullopt;
  double from = -std::numeric_limits<double>::infinity(),
         to = std::numeric_limits<double>::infinity();
  int window_run = static_cast<int>(training_runs) - 1;
  std::string window_origin;
  if (!args.test_runs.empty()) {
    window_run = -1;
    window_origin = "the runs given with --test, tested whole";
  } else if (args.test_from_s || args.test_to_s) {
    from = args.test_from_s.value_or(from);
    to = args.test_to_s.value_or(to);
    window_origin = "given on the command line";
  } else if (published) {
    from = published->from_s;
    to = published->to_s;
    window_origin = "the published figure's test window";
  } else if (runs.size() >= 3) {
    window_origin = "the last run, tested whole";
  } else {
    // From a stop, as every training piece starts: increments from a running spindle would take
    // the speed outside the training range.
    from = fitting::held_out_start(runs.back().time, io::measured_speed(runs.back()), 0.7, 0.7);
    window_origin = has_speed ? "the last run from the start of its last speed cycle that begins "
                                "by 70 % of it"
                              : "the last 30 % of the last run";
  }
  // A window that covers a whole run leaves nothing of it to refit on: no continuous figure.
  const bool window_inside_run = window_run >= 0 && (std::isfinite(from) || std::isfinite(to));
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::vector<fitting::Segment> pieces, tested;
  std::vector<fitting::Segment> whole_runs;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const std::string name = runs.size() == 1 ? std::string("run") : "run" + std::to_string(k + 1);
    const bool is_test_run = k >= training_runs;
    const bool windowed = static_cast<int>(k) == window_run;
    const double lo = windowed ? from : inf;
    const double hi = windowed ? to : inf;
    const std::vector<std::pair<double, double>> parts =
        is_test_run ? std::vector<std::pair<double, double>>{{inf, inf}, {-inf, inf}, {inf, inf}}
                    : std::vector<std::pair<double, double>>{{-inf, lo}, {lo, hi}, {hi, inf}};
    for (std::size_t p = 0; p < parts.size(); ++p) {
      const auto& t = runs[k].time;
      const bool any =
          (t.array() >= parts[p].first).cwiseProduct(t.array() < parts[p].second).count() >= 2;
      if (!any) continue;
      for (auto& s : io::measured_segments(runs[k], name + (p == 1 ? ".test" : ""), parts[p].first,
                                           parts[p].second))
        (p == 1 ? tested : pieces).push_back(std::move(s));
    }
    if (windowed && window_inside_run) {
      std::vector<std::string> sensor_ids, probe_ids;
      for (const auto& sensor : runs[k].sensors) sensor_ids.push_back(sensor.id);
      for (const auto& probe : runs[k].displacements) probe_ids.push_back(probe.id);
      whole_runs.push_back(fitting::segment_of(name, runs[k].time, io::measured_speed(runs[k]),
                                               runs[k].temperature, runs[k].displacement,
                                               sensor_ids, probe_ids, {0, runs[k].time.size()}));
    }
  }
  if (tested.empty())
    throw core::DataError("fit --data: no samples in the test window [" + std::to_string(from) +
                          ", " + std::to_string(to) + ") s (" + window_origin + ")");
  if (pieces.empty())
    throw core::DataError("fit --data: no training data outside the test window (" + window_origin +
                          "); hint: give more runs, --test RUN... or a shorter test window");
  const fitting::Blocks blocks = fitting::cross_validation_blocks(pieces);
  std::vector<fitting::Segment> segments = blocks.segments;
  std::vector<int> pool, test;
  for (std::size_t i = 0; i < segments.size(); ++i) pool.push_back(static_cast<int>(i));
  for (auto& s : tested) {
    test.push_back(static_cast<int>(segments.size()));
    segments.push_back(std::move(s));
  }
  const std::vector<fitting::Group> groups = fitting::segment_groups(segments);
  const auto& targets = groups.front().target_names;
  const std::string block_origin =
      (has_speed ? "speed cycles of " : "whole runs (no speed input, so no speed cycles) of ") +
      std::to_string(training_runs) + " run(s); " + blocks.origin;
  if (!args.quiet)
    std::cerr << "thermotwin: fit --data: " << pool.size() << " training blocks (" << block_origin
              << "), " << test.size() << " test groups, " << targets.size() << " channels\n";

  // 2. What the test data hold that the training data do not.
  const int sensor_count = static_cast<int>(groups.front().sensor_names.size());
  const auto training = fitting::group_subset(groups, pool);
  const auto out_of_range = fitting::out_of_training_range(training, group_subset(groups, test));
  // With --network: the grey relational grade's sensors, for the network only (seed 004).
  std::optional<placement::PlacementResult> placed;
  if (args.network) placed = placed_on(training, 1);
  std::map<std::string, NetworkFigures> networks;

  // 3. Per channel: blocked choice on the training blocks, test on the held-out groups.
  std::vector<fitting::Evaluation> evals;
  nlohmann::json summary = nlohmann::json::object();
  std::map<std::string, Eigen::MatrixXd>
      window_rows;  /// per channel: time_s, measured_um, predicted_um
  const auto candidates = fitting::measured_data_candidates(sensor_count, has_speed, args.quick);
  for (int target = 0; target < static_cast<int>(targets.size()); ++target) {
    evals.push_back(fitting::blocked_evaluation(groups, pool, test, target, candidates));
    if (placed) {
      // The network on the grey relational sensors, on the inputs of the linear model just chosen
      // (that model its linear skip) and on the best ridge's (that ridge its skip), chosen beside
      // the linear models under the same rule.
      std::vector<fitting::Candidate> target_candidates = candidates;
      for (const auto& set : network_sensor_sets(*placed, target))
        target_candidates.push_back({set, driver_network_spec(1)});
      target_candidates.push_back(linear_inputs_network(evals.back().model, 1));
      if (auto c = ridge_skip_network(evals.back(), 1, has_speed)) target_candidates.push_back(*c);
      evals.back() = fitting::blocked_evaluation(groups, pool, test, target, target_candidates);
    }
    const auto& e = evals.back();
    const auto& chosen = e.selection.candidates[static_cast<std::size_t>(e.selection.best)];
    const auto& lowest = e.selection.candidates[static_cast<std::size_t>(e.selection.lowest)];
    Eigen::VectorXd residual(0), uncompensated(0);
    for (int i : test) {
      const auto& g = groups[static_cast<std::size_t>(i)];
      const Eigen::VectorXd r = g.error.col(target) - fitting::predicted_error(e.model, g);
      residual.conservativeResize(residual.size() + r.size());
      residual.tail(r.size()) = r;
      uncompensated.conservativeResize(uncompensated.size() + r.size());
      uncompensated.tail(r.size()) = g.error.col(target);
    }
    const std::string& name = targets[static_cast<std::size_t>(target)];
    if (!args.quiet)
      std::cerr << "thermotwin: fit --data: " << name << ": " << fitting::model_label(e.model.spec)
                << " on " << e.sensor_sets[static_cast<std::size_t>(chosen.sensor_set)].method
                << ", test RMS " << um(rms(residual)) << " um (uncompensated "
                << um(rms(uncompensated)) << ")\n";
    nlohmann::json s{
        {"model", fitting::model_label(e.model.spec)},
        {"method", e.sensor_sets[static_cast<std::size_t>(chosen.sensor_set)].method},
        {"sensors", e.model.features.sensor_names},
        {"inputs", e.model.features.input_names},
        {"validation_sm_um", chosen.validation.sm * 1e6},
        {"validation_standard_error_um",
         chosen.validation.s_sigma / std::sqrt(static_cast<double>(pool.size())) * 1e6},
        {"lowest_validation_candidate",
         fitting::model_label(e.specs[static_cast<std::size_t>(lowest.spec)]) + " on " +
             e.sensor_sets[static_cast<std::size_t>(lowest.sensor_set)].method},
        {"lowest_validation_sm_um", lowest.validation.sm * 1e6},
        {"validation_rms_um", std::sqrt(fitting::mean_square(chosen.validation)) * 1e6},
        {"lowest_validation_rms_um", std::sqrt(fitting::mean_square(lowest.validation)) * 1e6},
        {"no_compensation_validation_rms_um",
         e.selection.none >= 0
             ? nlohmann::json(std::sqrt(fitting::mean_square(
                                  e.selection.candidates[static_cast<std::size_t>(e.selection.none)]
                                      .validation)) *
                              1e6)
             : nlohmann::json(nullptr)},
        {"gain_over_no_compensation_um2", io::finite_or_null(e.selection.gain_over_none * 1e12)},
        {"gain_over_no_compensation_standard_error_um2",
         io::finite_or_null(e.selection.gain_over_none_standard_error * 1e12)},
        {"test_s_um", nlohmann::json::array()},
        {"test_sm_um", e.test.sm * 1e6},
        {"test_s_sigma_um", std::isfinite(e.test.s_sigma) ? nlohmann::json(e.test.s_sigma * 1e6)
                                                          : nlohmann::json(nullptr)},
        {"test_rms_um", rms(residual) * 1e6},
        {"test_max_abs_um", residual.cwiseAbs().maxCoeff() * 1e6},
        {"test_rms_uncompensated_um", rms(uncompensated) * 1e6},
        {"test_max_abs_uncompensated_um", uncompensated.cwiseAbs().maxCoeff() * 1e6},
        {"worse_than_uncompensated_on_test", rms(residual) > rms(uncompensated)},
        {"window_mae_rezeroed_um", mean_abs(residual) * 1e6},
        {"window_mae_uncompensated_um", mean_abs(uncompensated) * 1e6},
        {"window_mae_continuous_um", nullptr}};
    for (double v : e.test.s) s["test_s_um"].push_back(v * 1e6);
    if (published && published->mae_um.count(name))
      s["published_mae_um"] = published->mae_um.at(name);
    if (window_inside_run) {
      // 4. The continuous refit on the run outside the window.
      const WindowPrediction w = continuous_prediction(e.model, whole_runs.front(), from, to);
      s["window_mae_continuous_um"] = mean_abs(w.measured - w.predicted) * 1e6;
      Eigen::MatrixXd rows(w.time.size(), 3);
      rows << w.time, w.measured * 1e6, w.predicted * 1e6;
      window_rows[name] = rows;
    }
    if (args.network) {
      // The network's own held-out figures beside the chosen model's, on the same groups.
      auto n = network_figures(e, fitting::group_subset(groups, pool),
                               fitting::group_subset(groups, test));
      if (n) {
        Eigen::VectorXd residual(0);
        for (int i : test) {
          const auto& g = groups[static_cast<std::size_t>(i)];
          const Eigen::VectorXd r = g.error.col(target) - fitting::predicted_error(n->model, g);
          residual.conservativeResize(residual.size() + r.size());
          residual.tail(r.size()) = r;
        }
        s["network"] = network_json(*n);
        s["network"]["window_mae_rezeroed_um"] = mean_abs(residual) * 1e6;
        if (window_inside_run) {
          const WindowPrediction nw = continuous_prediction(
              n->model, whole_runs[static_cast<std::size_t>(window_run)], from, to);
          s["network"]["window_mae_continuous_um"] = mean_abs(nw.measured - nw.predicted) * 1e6;
        }
        s["network"]["file"] = "network_" + name + ".pt";
        networks.emplace(name, std::move(*n));
      }
    }
    summary[name] = s;
  }
  {
    // 5. Outputs, all or nothing.
    const auto& dir = out.path();
    nlohmann::json doc = io::fit_json(evals);
    for (auto& t : doc["targets"])
      t["selection_rule"] =
          "blocked cross-validation (each training block held out in turn): the candidate of "
          "the lowest mean validation S^2 (validation_rms_um is its square root; ties to the "
          "fewer coefficients), unless its mean per-block gain in S^2 over no compensation does "
          "not exceed one standard error of that gain: then no compensation (one-standard-error "
          "guard), so a model worse than no compensation on validation is never chosen";
    doc["summary"] = summary;
    doc["data"] = nlohmann::json::array();
    for (std::size_t k = 0; k < runs.size(); ++k)
      doc["data"].push_back({{"folder", runs[k].folder.string()},
                             {"machine", runs[k].machine},
                             {"run", runs[k].run},
                             {"role", k < training_runs ? "training" : "test"},
                             {"speed_input", has_speed}});
    doc["blocks"] = block_origin;
    doc["groups"] = nlohmann::json::array();
    for (std::size_t i = 0; i < segments.size(); ++i) {
      const bool is_test = i >= pool.size();
      const auto& g = segments[i].group;
      doc["groups"].push_back({{"name", g.name},
                               {"role", is_test ? "test" : "fitting_and_validation"},
                               {"from_s", g.time(0)},
                               {"to_s", g.time(g.time.size() - 1)},
                               {"samples", g.time.size()},
                               {"dropped_rows", segments[i].dropped_rows}});
    }
    doc["test_window"] = {
        {"from_s", std::isfinite(from) ? nlohmann::json(from) : nlohmann::json(nullptr)},
        {"to_s", std::isfinite(to) ? nlohmann::json(to) : nlohmann::json(nullptr)},
        {"origin", window_origin}};
    doc["out_of_training_range"] = nlohmann::json::array();
    for (const auto& o : out_of_range)
      doc["out_of_training_range"].push_back({{"column", o.column},
                                              {"training_min", o.training_min},
                                              {"training_max", o.training_max},
                                              {"test_min", o.test_min},
                                              {"test_max", o.test_max},
                                              {"share_of_test_samples_outside", o.share_outside},
                                              {"units", "K for dT, rpm for d[speed_rpm]"}});
    doc["method_notes"] = {
        "training blocks: " + block_origin +
            "; each block's drift is re-zeroed at its first reading, as the standard's intercept "
            "assumes",
        "candidates: no compensation; least squares (with the standard's 3 sigma criterion, and "
        "without it), ridge and ridge on the temperatures with their first-order lags at 600 s and "
        "3600 s (and "
        "the speed with its lags, where there is one) on all sensors, ridge strength lambda in "
        "1e-6..10",
        "test_rms_um and test_max_abs_um: residual on the held-out groups, re-zeroed at each "
        "group's start; window_mae_continuous_um (a window inside a run only): the chosen form "
        "refitted on the whole run outside the window, temperatures from the run's start, no "
        "displacement inside the window used"};
    if (published) {
      doc["published"] = {{"model", published->model},
                          {"source", published->source},
                          {"note", published->note},
                          {"mae_um", published->mae_um},
                          {"others_mae_um", published->others_mae_um}};
    }
    io::write_json(dir / "fit.json", doc);
    for (const auto& [channel, n] : networks)
      std::get<torchnet::Network>(n.model.body)
          .save_torchscript(dir / ("network_" + channel + ".pt"));
    std::vector<fitting::FittedModel> models;
    for (const auto& ev : evals) models.push_back(ev.model);
    io::write_compensation_csv(dir / "compensation.csv", models,
                               fitting::group_subset(groups, test));
    std::ostringstream md;
    md << "# fit --data\n\nRuns: ";
    for (std::size_t k = 0; k < runs.size(); ++k)
      md << "`" << runs[k].folder.string() << "` (" << runs[k].run
         << (k < training_runs ? "" : ", test") << ") ";
    md << "\n\nHeld out: " << window_origin;
    if (std::isfinite(from) || std::isfinite(to))
      md << ", " << (std::isfinite(from) ? std::to_string(from) : "start") << " to "
         << (std::isfinite(to) ? std::to_string(to) : "end") << " s";
    md << ". Training blocks: " << block_origin << ". Test groups: " << test.size() << ".\n\n"
       << "| channel | model | sensors | test RMS [um] | test max [um] | uncompensated RMS [um] | "
          "uncompensated max [um] | test S_M [um] | MAE continuous [um] | published MAE [um] "
          "|\n|---|---|---|---|---|---|---|---|---|---|\n";
    std::vector<std::string> worse;
    for (const auto& ev : evals) {
      const auto& s2 = summary[ev.target_name];
      std::string sensors;
      for (const auto& n : ev.model.features.sensor_names)
        sensors += (sensors.empty() ? "" : " ") + n;
      for (const auto& n : ev.model.features.input_names) sensors += " " + n;
      const auto field = [&](const char* key) {
        return s2[key].is_number() ? um(s2[key].get<double>() * 1e-6) : std::string("-");
      };
      md << "| " << ev.target_name << " | " << fitting::model_label(ev.model.spec) << " | "
         << (ev.model.spec.kind == fitting::ModelKind::no_compensation ? "-" : sensors) << " | "
         << field("test_rms_um") << " | " << field("test_max_abs_um") << " | "
         << field("test_rms_uncompensated_um") << " | " << field("test_max_abs_uncompensated_um")
         << " | " << um(ev.test.sm) << " | " << field("window_mae_continuous_um") << " | "
         << (s2.contains("published_mae_um") ? um(s2["published_mae_um"].get<double>() * 1e-6, 3)
                                             : "-")
         << " |\n";
      if (s2["worse_than_uncompensated_on_test"].get<bool>()) worse.push_back(ev.target_name);
    }
    if (!worse.empty()) {
      md << "\n**Worse than no compensation on the test data:**";
      for (const auto& w : worse) md << " " << w;
      md << ". The choice was made on the training blocks only; this says the test data differ "
            "from them.\n";
    }
    if (!out_of_range.empty()) {
      md << "\n**Test inputs outside the training range** (the models extrapolate there):";
      for (const auto& o : out_of_range)
        md << " " << o.column << " (" << std::lround(o.share_outside * 100.0)
           << " % of test samples)";
      md << ".\n";
    }
    if (published)
      md << "\nPublished: " << published->model << ", " << published->source << ". "
         << published->note << ".\n";
    md << "\nChoice: " << doc["targets"][0]["selection_rule"].get<std::string>()
       << ". S, S_M, S_sigma: DB3401/T 326-2024 formulas 5-7 over the test groups. See fit.json "
          "`method_notes`.\n";
    io::write_file_atomically(dir / "summary.md", md.str());
    for (const auto& [channel, table] : window_rows) {
      const auto csv = dir / ("window_" + channel + ".csv");
      io::write_csv(csv, {"time_s", "measured_um", "predicted_continuous_um"}, table);
      plot({"lines", csv.string(), (dir / ("window_" + channel + ".png")).string(), "--x", "time_s",
            "--columns", "measured_um,predicted_continuous_um", "--ylabel=" + channel + " [um]",
            "--title=test window, channel " + channel});
    }
    out.commit();
  }
  return 0;
}

}  // namespace tt::app
