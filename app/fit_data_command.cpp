// thermotwin fit --data: thermal-error models fitted on measured runs with no machine model behind
// them (DB3401/T 326-2024 metrics S, S_M, S_sigma, and the mean absolute error on a test window).
//   thermotwin fit --data RUN... --out DIR [--test-from-s T0 --test-to-s T1] [--quick]
// 1. Each run (docs/measured-data.md) is cut into groups at its speed cycles and at the edges of
//    the test window; every group's drift is re-zeroed at its first reading, as the standard's
//    intercept assumes of a run that starts cold (pieces of one run are not independent cold
//    starts, so the choice is averaged over several validation groups, not made on one).
// 2. Sensors are chosen among the run's temperatures by every placement method and by correlation,
//    on the groups outside the test window only.
// 3. Per displacement channel, the (sensor set, model) pair with the smallest mean validation S
//    (each non-test group validating in turn) is refitted on all non-test groups and tested.
// 4. On the window, the mean absolute error is reported two ways: re-zeroed (the groups above) and
//    continuous (the chosen model refitted on the whole run outside the window, temperatures from
//    the run's start, no displacement reading inside the window used), beside the published figure
//    when the data set has one.
// Writes fit.json, summary.md, compensation.csv, window_<channel>.csv/.png.
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

namespace tt::app {
namespace {

/// A figure published for a data set: the test window and the MAE per channel [µm].
struct Published {
  std::string model, source, note;
  double from_s = 0.0, to_s = 0.0;
  std::map<std::string, double> mae_um;
  std::map<std::string, std::map<std::string, double>> others_um;
};

/// The published figure of the FL_THERMAL data (shared/data/fl_thermal_spindle_5probe/SOURCE.md).
std::optional<Published> published_for(const io::MeasuredRun& run) {
  const auto it = run.meta.find("source");
  if (it == run.meta.end() || !it->is_string() ||
      it->get<std::string>().find("FL_THERMAL") == std::string::npos)
    return std::nullopt;
  Published p;
  p.model = "seq2seq v2 (GRU encoder-decoder with attention)";
  p.source = "github.com/CAIVIAC/FL_THERMAL, figures images/test_ch*(um)_S2S2[e100].png";
  p.note =
      "test window inferred from the plotted ground truth (rows ~6581-8800); the split is not "
      "stated, so the "
      "comparison is context, not a gate";
  p.from_s = 98700.0;
  p.to_s = 132000.0;
  p.mae_um = {{"ch1", 3.561}, {"ch2", 3.755}, {"ch3", 3.704}, {"ch4", 3.461}, {"ch5", 4.284}};
  p.others_um = {
      {"random_forest",
       {{"ch1", 6.456}, {"ch2", 4.501}, {"ch3", 7.330}, {"ch4", 7.178}, {"ch5", 12.440}}},
      {"xgboost", {{"ch1", 5.611}, {"ch2", 4.966}, {"ch3", 6.039}, {"ch4", 7.804}, {"ch5", 9.535}}},
      {"seq2seq_v1",
       {{"ch1", 5.576}, {"ch2", 5.943}, {"ch3", 4.183}, {"ch4", 4.160}, {"ch5", 6.499}}}};
  return p;
}

std::optional<Eigen::AlignedBox3d> machine_box(const std::filesystem::path& folder) {
  std::ifstream in(folder / "meta.json");
  try {
    const auto meta = nlohmann::json::parse(in);
    if (meta.value("machine", std::string()) == "SB-1")
      return Eigen::AlignedBox3d(Eigen::Vector3d(-0.16, 0.0, -0.04),
                                 Eigen::Vector3d(0.16, 0.30, 0.58));
  } catch (const std::exception&) {
    // read_measured_run reports a malformed meta.json with its location.
  }
  return std::nullopt;
}

/// Sensor sets of every placement method for one target, m <= max_m.
std::vector<fitting::SensorSet> placement_sets(const placement::PlacementResult& p, int target,
                                               int max_m) {
  std::vector<fitting::SensorSet> sets;
  for (const auto& s : p.targets[static_cast<std::size_t>(target)].selections)
    if (s.m <= max_m) sets.push_back({std::string(placement::method_name(s.method)), s.columns});
  return sets;
}

/// Placement on groups laid end to end; positions are unknown, so no mirror twins.
placement::PlacementResult placed_on(const std::vector<fitting::Group>& groups,
                                     std::uint64_t seed) {
  Eigen::Index rows = 0;
  for (const auto& g : groups) rows += g.time.size();
  const auto& g0 = groups.front();
  placement::PlacementInput in;
  for (std::size_t c = 0; c < g0.sensor_names.size(); ++c)
    in.ids.push_back(core::SensorId{static_cast<int>(c) + 1});
  in.positions_m = Eigen::MatrixX3d::Zero(static_cast<Eigen::Index>(g0.sensor_names.size()), 3);
  in.times_s.resize(rows);
  in.temperatures_K.resize(rows, g0.temperature.cols());
  std::vector<Eigen::VectorXd> targets(g0.target_names.size(), Eigen::VectorXd(rows));
  Eigen::Index r = 0;
  double offset = 0.0;
  for (const auto& g : groups) {
    const Eigen::Index n = g.time.size();
    in.times_s.segment(r, n) = g.time.array() - g.time(0) + offset;
    in.temperatures_K.middleRows(r, n) = g.temperature;
    for (std::size_t t = 0; t < targets.size(); ++t)
      targets[t].segment(r, n) = g.error.col(static_cast<Eigen::Index>(t));
    offset = in.times_s(r + n - 1) + 1.0;
    r += n;
  }
  for (std::size_t t = 0; t < targets.size(); ++t)
    in.targets.push_back({g0.target_names[t], targets[t]});
  placement::PlacementOptions options;
  options.samples =
      400;  // resampled: the MI searches need no more than this, the runs have 10^4 rows
  options.m_max = 4;
  options.seed = seed;
  options.mirror_twins = false;
  return placement::place_all(in, options);
}

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
  if (chosen.spec.kind == fitting::ModelKind::cnn_bigru_attention) {
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
  // 1. The runs, cut at speed cycles and at the test window's edges.
  std::vector<io::MeasuredRun> runs;
  for (const auto& folder : args.runs) {
    io::MeasuredReadLimits limits;
    limits.machine_box = machine_box(folder);
    runs.push_back(io::read_measured_run(folder, limits));
  }
  for (const auto& r : runs) {
    if (r.displacements.empty() || r.sensors.empty())
      throw core::DataError(r.folder.string() +
                            ": no displacement or no temperature columns: nothing to fit");
    if (r.displacements.size() != runs[0].displacements.size() ||
        r.sensors.size() != runs[0].sensors.size())
      throw core::DataError(r.folder.string() + ": columns differ from " + runs[0].folder.string() +
                            ": every run must have the same sensors and displacements");
  }
  const std::optional<Published> published = published_for(runs.back());
  double from = -std::numeric_limits<double>::infinity(),
         to = std::numeric_limits<double>::infinity();
  int window_run = static_cast<int>(runs.size()) - 1;
  std::string window_origin;
  if (args.test_from_s || args.test_to_s) {
    from = args.test_from_s.value_or(from);
    to = args.test_to_s.value_or(to);
    window_origin = "given on the command line";
  } else if (published) {
    from = published->from_s;
    to = published->to_s;
    window_origin = "the published figure's test window";
  } else if (runs.size() >= 3) {
    window_run = static_cast<int>(runs.size()) - 1;
    window_origin = "the last run";
  } else {
    const auto& t = runs.back().time;
    from = t(0) + 0.7 * (t(t.size() - 1) - t(0));
    window_origin = "the last 30 % of the last run";
  }
  std::vector<fitting::Segment> segments;
  std::vector<int> pool, test;
  std::vector<fitting::Segment> whole_runs;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const std::string name = runs.size() == 1 ? std::string("run") : "run" + std::to_string(k + 1);
    const bool windowed = static_cast<int>(k) == window_run;
    const double lo = windowed ? from : std::numeric_limits<double>::infinity();
    const double hi = windowed ? to : std::numeric_limits<double>::infinity();
    const double inf = std::numeric_limits<double>::infinity();
    const std::vector<std::pair<double, double>> pieces{{-inf, lo}, {lo, hi}, {hi, inf}};
    for (std::size_t p = 0; p < pieces.size(); ++p) {
      const auto& t = runs[k].time;
      const bool any =
          (t.array() >= pieces[p].first).cwiseProduct(t.array() < pieces[p].second).count() >= 2;
      if (!any) continue;
      for (auto& s : io::measured_segments(runs[k], name + (p == 1 ? ".test" : ""), pieces[p].first,
                                           pieces[p].second)) {
        (p == 1 ? test : pool).push_back(static_cast<int>(segments.size()));
        segments.push_back(std::move(s));
      }
    }
    std::vector<std::string> sensor_ids, probe_ids;
    for (const auto& sensor : runs[k].sensors) sensor_ids.push_back(sensor.id);
    for (const auto& probe : runs[k].displacements) probe_ids.push_back(probe.id);
    whole_runs.push_back(fitting::segment_of(name, runs[k].time, io::measured_speed(runs[k]),
                                             runs[k].temperature, runs[k].displacement, sensor_ids,
                                             probe_ids, {0, runs[k].time.size()}));
  }
  if (test.empty())
    throw core::DataError("fit --data: no samples in the test window [" + std::to_string(from) +
                          ", " + std::to_string(to) + ") s (" + window_origin + ")");
  if (pool.size() < 2)
    throw core::DataError(
        "fit --data: " + std::to_string(pool.size()) +
        " group outside the test window: expected at least 2 (give longer runs or more runs)");
  const std::vector<fitting::Group> groups = fitting::segment_groups(segments);
  const auto& targets = groups.front().target_names;
  if (!args.quiet)
    std::cerr << "thermotwin: fit --data: " << groups.size() << " groups (" << test.size()
              << " test), " << targets.size() << " channels\n";

  // 2. Sensor sets on the non-test groups only.
  const placement::PlacementResult placed = placed_on(fitting::group_subset(groups, pool), 1);
  // Projection pursuit is left out: on runs of 10^4 rows its search over folds and channels costs
  // tens of minutes, and the linear families already span the standard's model.
  std::vector<fitting::ModelSpec> specs{fitting::ModelSpec{}};
  if (!args.quick) {
    specs.clear();
    for (const auto& spec : fitting::default_model_candidates())
      if (spec.kind != fitting::ModelKind::projection_pursuit) specs.push_back(spec);
  }
  if (args.network) specs.push_back(driver_network_spec(1));
  std::map<std::string, NetworkFigures> networks;

  // 3. Per channel: choice on several validation groups, test on the window's groups.
  std::vector<fitting::Evaluation> evals;
  nlohmann::json summary = nlohmann::json::object();
  std::map<std::string, Eigen::MatrixXd>
      window_rows;  /// per channel: time_s, measured_um, predicted_um
  for (int target = 0; target < static_cast<int>(targets.size()); ++target) {
    std::vector<fitting::SensorSet> sets = placement_sets(placed, target, 4);
    const auto corr =
        fitting::correlation_sensor_sets(fitting::group_subset(groups, pool), target, 4);
    sets.insert(sets.end(), corr.begin(), corr.end());
    if (args.network) {
      const auto grey = network_sensor_sets(placed, target);
      sets.insert(sets.end(), grey.begin(), grey.end());
    }
    evals.push_back(fitting::cross_validated_evaluation(groups, pool, test, target, sets, specs));
    const auto& e = evals.back();
    if (!args.quiet)
      std::cerr << "thermotwin: fit --data: " << targets[static_cast<std::size_t>(target)] << ": "
                << fitting::model_label(e.model.spec) << ", test S_M " << um(e.test.sm) << " um\n";

    // 4. MAE on the window: re-zeroed groups, and the continuous refit.
    Eigen::VectorXd rezeroed_residual(0), uncompensated(0);
    for (int i : test) {
      const auto& g = groups[static_cast<std::size_t>(i)];
      const Eigen::VectorXd r = g.error.col(target) - fitting::predicted_error(e.model, g);
      rezeroed_residual.conservativeResize(rezeroed_residual.size() + r.size());
      rezeroed_residual.tail(r.size()) = r;
      uncompensated.conservativeResize(uncompensated.size() + r.size());
      uncompensated.tail(r.size()) = g.error.col(target);
    }
    const WindowPrediction w =
        continuous_prediction(e.model, whole_runs[static_cast<std::size_t>(window_run)], from, to);
    const std::string& name = targets[static_cast<std::size_t>(target)];
    nlohmann::json s{
        {"model", fitting::model_label(e.model.spec)},
        {"method",
         e
             .sensor_sets[static_cast<std::size_t>(
                 e.selection.candidates[static_cast<std::size_t>(e.selection.best)].sensor_set)]
             .method},
        {"sensors", e.model.features.sensor_names},
        {"validation_sm_um",
         e.selection.candidates[static_cast<std::size_t>(e.selection.best)].validation.sm * 1e6},
        {"test_s_um", nlohmann::json::array()},
        {"test_sm_um", e.test.sm * 1e6},
        {"test_s_sigma_um", std::isfinite(e.test.s_sigma) ? nlohmann::json(e.test.s_sigma * 1e6)
                                                          : nlohmann::json(nullptr)},
        {"window_mae_rezeroed_um", mean_abs(rezeroed_residual) * 1e6},
        {"window_mae_continuous_um", mean_abs(w.measured - w.predicted) * 1e6},
        {"window_mae_uncompensated_um", mean_abs(uncompensated) * 1e6}};
    for (double v : e.test.s) s["test_s_um"].push_back(v * 1e6);
    if (published && published->mae_um.count(name))
      s["published_mae_um"] = published->mae_um.at(name);
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
        const WindowPrediction nw = continuous_prediction(
            n->model, whole_runs[static_cast<std::size_t>(window_run)], from, to);
        s["network"] = network_json(*n);
        s["network"]["window_mae_rezeroed_um"] = mean_abs(residual) * 1e6;
        s["network"]["window_mae_continuous_um"] = mean_abs(nw.measured - nw.predicted) * 1e6;
        s["network"]["file"] = "network_" + name + ".pt";
        networks.emplace(name, std::move(*n));
      }
    }
    summary[name] = s;
    Eigen::MatrixXd rows(w.time.size(), 3);
    rows << w.time, w.measured * 1e6, w.predicted * 1e6;
    window_rows[name] = rows;
  }
  {
    // 5. Outputs, all or nothing.
    io::OutputDir out(args.out);
    const auto& dir = out.path();
    nlohmann::json doc = io::fit_json(evals);
    doc["summary"] = summary;
    doc["data"] = nlohmann::json::array();
    for (const auto& r : runs)
      doc["data"].push_back(
          {{"folder", r.folder.string()}, {"machine", r.machine}, {"run", r.run}});
    doc["groups"] = nlohmann::json::array();
    for (std::size_t i = 0; i < segments.size(); ++i) {
      const bool is_test = std::find(test.begin(), test.end(), static_cast<int>(i)) != test.end();
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
    doc["method_notes"] = {
        "groups are cut at speed cycles (a start after a stop) and at the test window's edges; "
        "each group's "
        "drift is re-zeroed at its first reading, as the standard's intercept assumes",
        "model and sensor set chosen by the smallest mean validation S over folds in which each "
        "non-test group "
        "validates once, then refitted on all non-test groups",
        "window_mae_rezeroed_um: residual of the test groups (re-zeroed at the window start and at "
        "each cycle "
        "start inside it); window_mae_continuous_um: the chosen form refitted on the whole run "
        "outside the window, "
        "temperatures from the run's start, no displacement inside the window used"};
    if (published) {
      doc["published"] = {{"model", published->model},
                          {"source", published->source},
                          {"note", published->note},
                          {"mae_um", published->mae_um},
                          {"others_mae_um", published->others_um}};
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
    for (const auto& r : runs) md << "`" << r.folder.string() << "` (" << r.run << ") ";
    md << "\n\nTest window: " << (std::isfinite(from) ? std::to_string(from) : "-inf") << " to "
       << (std::isfinite(to) ? std::to_string(to) : "end") << " s (" << window_origin
       << "). Groups: " << pool.size() << " for fitting and validation, " << test.size()
       << " for test.\n\n"
       << "| channel | model | sensors | test S_M [um] | test S_sigma [um] | MAE re-zeroed [um] | "
          "MAE continuous [um] "
          "| MAE uncompensated [um] | published MAE [um] "
          "|\n|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& ev : evals) {
      const auto& s2 = summary[ev.target_name];
      std::string sensors;
      for (const auto& n : ev.model.features.sensor_names)
        sensors += (sensors.empty() ? "" : " ") + n;
      md << "| " << ev.target_name << " | " << fitting::model_label(ev.model.spec) << " | "
         << sensors << " | " << um(ev.test.sm) << " | " << um(ev.test.s_sigma) << " | "
         << um(s2["window_mae_rezeroed_um"].get<double>() * 1e-6) << " | "
         << um(s2["window_mae_continuous_um"].get<double>() * 1e-6) << " | "
         << um(s2["window_mae_uncompensated_um"].get<double>() * 1e-6) << " | "
         << (s2.contains("published_mae_um") ? um(s2["published_mae_um"].get<double>() * 1e-6, 3)
                                             : "-")
         << " |\n";
    }
    if (published)
      md << "\nPublished: " << published->model << ", " << published->source << ". "
         << published->note << ".\n";
    md << "\nS, S_M, S_sigma: DB3401/T 326-2024 formulas 5-7 over the test groups. See fit.json "
          "`method_notes`.\n";
    io::write_file_atomically(dir / "summary.md", md.str());
    for (const auto& [channel, table] : window_rows) {
      const auto csv = dir / ("window_" + channel + ".csv");
      io::write_csv(csv, {"time_s", "measured_um", "predicted_continuous_um"}, table);
      plot({"lines", csv.string(), (dir / ("window_" + channel + ".png")).string(), "--x", "time_s",
            "--columns", "measured_um,predicted_continuous_um", "--ylabel", channel + " [um]",
            "--title", "test window, channel " + channel});
    }
    out.commit();
  }
  return 0;
}

}  // namespace tt::app
