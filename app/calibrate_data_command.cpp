// thermotwin calibrate without --case: close the loop on measured runs alone. The thermal-error
// model is fitted on the earlier data, its residual is traced to what the model lacks among terms
// the data can express (speed, time, temperatures), those terms are added, and the error on the
// later, held-out data is reported before and after, per displacement channel.
//   thermotwin calibrate --train RUN... --test RUN... --out DIR [--split-s T]
// A run given both as --train and --test is split in time: training before T, test from T (default:
// the start of the last speed cycle that begins before 70 % of the run).
// 1. Training and test runs cut into segments at their speed cycles (kept whole when a run has no
//    speed), drift re-zeroed per segment; fewer than 4 training pieces are cut into time blocks
//    (fitting::cross_validation_blocks).
// 2. Per channel, the baseline is the model fit --data chooses on the same training blocks
//    (fitting::measured_data_candidates, fitting::blocked_evaluation: ridge or least squares on all
//    temperature rises, possibly with their first-order lags and the speed, λ by blocked
//    cross-validation, or no compensation when nothing beats it by a standard error); then
//    fitting::residual_study on that baseline's leave-one-segment-out residual: candidate terms
//    claimed only when their share of that residual, less 1 % per coefficient, beats the best of 19
//    phase-randomised surrogates (and zero), and their per-segment held-out gain exceeds two
//    standard errors, each segment's gain taken with the setting (time constant, sensor) searched
//    on the other segments only.
// 3. The residual on the test segments, before and after, and how it still correlates with speed
//    (when there is one), time and temperatures; a channel whose test error is worse after than
//    before is said to be so.
// Writes calibration.json, report.md, residual_<channel>.csv/.png.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <set>
#include <sstream>

#include "app/commands.hpp"
#include "core/errors.hpp"
#include "fitting/features.hpp"
#include "fitting/residual_study.hpp"
#include "fitting/segments.hpp"
#include "io/atomic_dir.hpp"
#include "io/csv_out.hpp"
#include "io/measured_data.hpp"
#include "io/measured_segments.hpp"
#include "io/reports.hpp"

namespace tt::app {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double correlation(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const Eigen::VectorXd x = a.array() - a.mean(), y = b.array() - b.mean();
  const double d = x.norm() * y.norm();
  return d > 0 ? x.dot(y) / d : 0.0;
}

/// Residual [m] of a model on each segment, stacked.
Eigen::VectorXd stacked_residual(const fitting::TermModel& m,
                                 const std::vector<fitting::Segment>& segments) {
  Eigen::Index n = 0;
  for (const auto& s : segments) n += s.group.time.size();
  Eigen::VectorXd r(n);
  Eigen::Index at = 0;
  for (const auto& s : segments) {
    const Eigen::Index k = s.group.time.size();
    r.segment(at, k) = s.group.error.col(m.target) - fitting::term_prediction(m, s);
    at += k;
  }
  return r;
}

double rms(const Eigen::VectorXd& r) {
  return r.size() ? std::sqrt(r.squaredNorm() / static_cast<double>(r.size())) : 0.0;
}

nlohmann::json effect_json(const fitting::Effect& e, const fitting::ChannelStudy& study,
                           const std::vector<std::string>& sensor_names,
                           const fitting::TermModel& with) {
  nlohmann::json parameters = nlohmann::json::object();
  if (e.term.kind == fitting::EffectKind::lag || e.term.kind == fitting::EffectKind::lagged_speed)
    parameters["time_constant_s"] = e.term.time_constant;
  if (e.term.sensor >= 0)
    parameters["sensor"] = sensor_names[static_cast<std::size_t>(e.term.sensor)];
  // The coefficients this term has in the final model, by regressor name [µm per unit].
  const auto names = fitting::term_regressor_names(with.baseline, with.terms, sensor_names);
  const auto before = fitting::term_regressor_names(with.baseline, {}, sensor_names).size();
  std::size_t at = before;
  for (const auto& t : with.terms) {
    const auto count =
        fitting::term_regressor_names(with.baseline, {t}, sensor_names).size() - before;
    if (t.kind == e.term.kind)
      for (std::size_t k = 0; k < count; ++k)
        parameters["coefficients_um"][names[at + k]] =
            with.fit.coefficients(static_cast<Eigen::Index>(at + k)) * 1e6;
    at += count;
  }
  nlohmann::json location{{"channel", study.target_name}};
  if (e.term.sensor >= 0)
    location["sensor"] = sensor_names[static_cast<std::size_t>(e.term.sensor)];
  return {{"kind", fitting::effect_kind_name(e.term.kind)},
          {"parameters", parameters},
          {"location", location},
          {"explained_fraction", e.explained_fraction},
          {"step_fraction", e.step_fraction},
          {"null_fraction", std::isfinite(e.null_fraction) ? nlohmann::json(e.null_fraction)
                                                           : nlohmann::json(nullptr)},
          {"added_coefficients", e.parameters},
          {"heldout_training_rms_um_before", std::isfinite(e.heldout_rms_before)
                                                 ? nlohmann::json(e.heldout_rms_before * 1e6)
                                                 : nlohmann::json(nullptr)},
          {"heldout_training_rms_um_with_it", std::isfinite(e.heldout_rms_after)
                                                  ? nlohmann::json(e.heldout_rms_after * 1e6)
                                                  : nlohmann::json(nullptr)},
          {"heldout_gain_t", std::isfinite(e.gain_t) ? nlohmann::json(e.gain_t)
                                                     : nlohmann::json(e.gain_t > 0 ? 1e300 : 0.0)},
          {"segments_improved", e.segments_improved},
          {"claimed", e.claimed}};
}

nlohmann::json model_json(const fitting::TermModel& m,
                          const std::vector<std::string>& sensor_names) {
  nlohmann::json terms = nlohmann::json::object();
  const auto names = fitting::term_regressor_names(m.baseline, m.terms, sensor_names);
  for (std::size_t k = 0; k < names.size(); ++k)
    terms[names[k]] = m.fit.coefficients(static_cast<Eigen::Index>(k)) * 1e6;
  return {{"form", fitting::model_label(m.baseline.spec)},
          {"intercept_um", m.fit.intercept * 1e6},
          {"coefficients_um_per_unit", terms},
          {"units", "dT in K, d[speed_rpm] in rpm, speed_krpm in krpm, time in h"}};
}

}  // namespace

int calibrate_data_command(const CalibrateArgs& args) {
  // 1. Runs and segments; a run in both lists is split in time.
  if (args.train.empty() || args.test.empty())
    throw core::DataError(
        "calibrate: give --train RUN... and --test RUN... (the same run in both splits it in "
        "time)");
  io::require_distinct_runs(args.train, "--train");
  io::require_distinct_runs(args.test, "--test");
  std::vector<std::filesystem::path> inputs = args.train;
  inputs.insert(inputs.end(), args.test.begin(), args.test.end());
  io::OutputDir out(args.out, inputs);  // refused at once, not after the study
  std::vector<fitting::Segment> pieces, testing;
  bool has_speed = false;
  std::vector<io::MeasuredRun> runs;
  nlohmann::json splits = nlohmann::json::array();
  std::set<std::string> test_names;
  for (const auto& p : args.test) test_names.insert(std::filesystem::weakly_canonical(p).string());
  std::set<std::string> train_names;
  for (const auto& p : args.train)
    train_names.insert(std::filesystem::weakly_canonical(p).string());
  int index = 0;
  const auto add = [&](const std::filesystem::path& folder, bool is_train) {
    const std::string key = std::filesystem::weakly_canonical(folder).string();
    const bool shared = train_names.count(key) && test_names.count(key);
    io::MeasuredRun run = io::read_measured_run(folder);
    const bool speed = io::measured_speed(run).size() != 0;
    if (index > 0 && speed != has_speed)
      throw core::DataError(folder.string() +
                            (speed ? " has a speed input but " : " has none but ") +
                            runs.front().folder.string() + (speed ? " has none" : " has one") +
                            ": every run must have the same inputs; hint: drop the speed column "
                            "from all runs, or give it in all");
    has_speed = speed;
    const double split = shared ? args.split_s.value_or(fitting::held_out_start(
                                      run.time, io::measured_speed(run), 0.7, 0.6))
                                : kInf;
    const std::string name = "run" + std::to_string(++index) + (is_train ? ".train" : ".test");
    auto segments = is_train ? io::measured_segments(run, name, -kInf, shared ? split : kInf)
                             : io::measured_segments(run, name, shared ? split : -kInf, kInf);
    splits.push_back({{"folder", folder.string()},
                      {"role", is_train ? "train" : "test"},
                      {"split_s", shared ? nlohmann::json(split) : nlohmann::json(nullptr)},
                      {"segments", nlohmann::json::array()}});
    for (const auto& s : segments)
      splits.back()["segments"].push_back({{"name", s.group.name},
                                           {"from_s", s.group.time(0)},
                                           {"to_s", s.group.time(s.group.time.size() - 1)},
                                           {"dropped_rows", s.dropped_rows}});
    auto& into = is_train ? pieces : testing;
    into.insert(into.end(), segments.begin(), segments.end());
    runs.push_back(std::move(run));
  };
  for (const auto& f : args.train) add(f, true);
  for (const auto& f : args.test) add(f, false);
  const fitting::Blocks blocks = fitting::cross_validation_blocks(pieces);
  const std::vector<fitting::Segment>& training = blocks.segments;
  const std::string block_origin =
      (has_speed ? "speed cycles; " : "whole runs (no speed input, so no speed cycles); ") +
      blocks.origin;
  if (!args.quiet)
    std::cerr << "thermotwin: calibrate: " << training.size() << " training blocks ("
              << block_origin << "), " << testing.size() << " test segments\n";
  const auto& sensor_names = training.front().group.sensor_names;
  const auto& targets = training.front().group.target_names;
  const std::vector<fitting::Group> groups = fitting::segment_groups(training);
  std::vector<int> pool;
  for (std::size_t i = 0; i < groups.size(); ++i) pool.push_back(static_cast<int>(i));
  const auto candidates =
      fitting::measured_data_candidates(static_cast<int>(sensor_names.size()), has_speed, false);
  fitting::ResidualStudyOptions options;
  if (runs.front().ambient_sensor)
    for (std::size_t k = 0; k < sensor_names.size(); ++k)
      if (sensor_names[k] == *runs.front().ambient_sensor)
        options.ambient_sensor = static_cast<int>(k);

  // 2. The study per channel, 3. the test residual before and after.
  nlohmann::json channels_before, channels_after, tested = nlohmann::json::object(),
                                                  models = nlohmann::json::object(),
                                                  diagnosis = nlohmann::json::object();
  nlohmann::json effects = nlohmann::json::array();
  double sum_before = 0, sum_after = 0;
  Eigen::Index count = 0;
  std::vector<std::pair<std::string, Eigen::MatrixXd>> tables;
  for (int target = 0; target < static_cast<int>(targets.size()); ++target) {
    // The baseline: fit --data's choice on the same blocks.
    const fitting::Evaluation choice =
        fitting::blocked_evaluation(groups, pool, {}, target, candidates);
    const fitting::ChannelStudy study =
        fitting::residual_study(training, target, fitting::baseline_of(choice.model), options);
    const Eigen::VectorXd before = stacked_residual(study.before, testing);
    const Eigen::VectorXd after = stacked_residual(study.after, testing);
    const std::string& ch = targets[static_cast<std::size_t>(target)];
    channels_before[ch] = {{"rms_um", rms(before) * 1e6},
                           {"mae_um", before.cwiseAbs().mean() * 1e6}};
    channels_after[ch] = {{"rms_um", rms(after) * 1e6},
                          {"mae_um", after.cwiseAbs().mean() * 1e6},
                          {"max_abs_um", after.cwiseAbs().maxCoeff() * 1e6},
                          {"worse_than_before", rms(after) > rms(before)}};
    channels_before[ch]["max_abs_um"] = before.cwiseAbs().maxCoeff() * 1e6;
    sum_before += before.squaredNorm();
    sum_after += after.squaredNorm();
    count += before.size();
    // Cumulative test RMS as effects are added, in the order the study added them.
    for (std::size_t k = 0; k < study.effects.size(); ++k) {
      std::vector<fitting::EffectTerm> prefix;
      for (std::size_t j = 0; j <= k; ++j) prefix.push_back(study.effects[j].term);
      const auto model =
          fitting::fitted_term_model(training, target, study.before.baseline, prefix);
      nlohmann::json e = effect_json(study.effects[k], study, sensor_names, study.after);
      e["test_rms_um_with_effects_so_far"] = rms(stacked_residual(model, testing)) * 1e6;
      e["test_rms_um_before"] = rms(before) * 1e6;
      effects.push_back(e);
    }
    tested[ch] = nlohmann::json::array();
    for (const auto& step : study.steps) {
      tested[ch].push_back(nlohmann::json::array());
      for (const auto& e : step)
        tested[ch].back().push_back(effect_json(e, study, sensor_names, study.after));
    }
    const auto& chosen =
        choice.selection.candidates[static_cast<std::size_t>(choice.selection.best)];
    models[ch] = {{"baseline_choice",
                   {{"model", fitting::model_label(choice.model.spec)},
                    {"validation_rms_um", std::sqrt(fitting::mean_square(chosen.validation)) * 1e6},
                    {"gain_over_no_compensation_um2",
                     std::isfinite(choice.selection.gain_over_none)
                         ? nlohmann::json(choice.selection.gain_over_none * 1e12)
                         : nlohmann::json(nullptr)},
                    {"gain_over_no_compensation_standard_error_um2",
                     std::isfinite(choice.selection.gain_over_none_standard_error)
                         ? nlohmann::json(choice.selection.gain_over_none_standard_error * 1e12)
                         : nlohmann::json(nullptr)}}},
                  {"before", model_json(study.before, sensor_names)},
                  {"after", model_json(study.after, sensor_names)},
                  {"heldout_training_rss_um2_before", study.heldout_rss_before * 1e12},
                  {"heldout_training_rss_um2_after", study.heldout_rss_after * 1e12}};
    // What the test residual (after) still follows: speed, time since segment start, temperatures.
    Eigen::Index n = after.size(), at = 0;
    Eigen::VectorXd speed(n), since(n), time(n);
    Eigen::MatrixXd dt(n, static_cast<Eigen::Index>(sensor_names.size()));
    double offset = 0;
    for (const auto& s : testing) {
      const Eigen::Index k = s.group.time.size();
      speed.segment(at, k) = s.speed;
      since.segment(at, k) = s.group.time.array() - s.group.time(0);
      time.segment(at, k) = s.group.time.array() - s.group.time(0) + offset;
      offset = time(at + k - 1) + 1.0;
      for (Eigen::Index c = 0; c < dt.cols(); ++c)
        dt.col(c).segment(at, k) = s.group.temperature.col(c).array() - s.group.temperature(0, c);
      at += k;
    }
    // A run with no speed input has no speed to correlate with: no column of zeros.
    nlohmann::json d{{"time_since_segment_start", correlation(after, since)}};
    if (has_speed) d["speed"] = correlation(after, speed);
    for (Eigen::Index c = 0; c < dt.cols(); ++c)
      d["dT[" + sensor_names[static_cast<std::size_t>(c)] + "]"] = correlation(after, dt.col(c));
    diagnosis[ch] = {{"before", nlohmann::json::object()}, {"after", d}};
    if (has_speed) diagnosis[ch]["before"]["speed"] = correlation(before, speed);
    diagnosis[ch]["before"]["time_since_segment_start"] = correlation(before, since);
    Eigen::MatrixXd table(n, 6);
    Eigen::VectorXd measured(n);
    at = 0;
    for (const auto& s : testing) {
      measured.segment(at, s.group.time.size()) = s.group.error.col(target);
      at += s.group.time.size();
    }
    table << time, speed / 1000.0, measured * 1e6, (measured - before) * 1e6, before * 1e6,
        after * 1e6;
    tables.emplace_back(ch, table);
  }
  std::vector<std::string> worse;
  for (const auto& ch : targets)
    if (channels_after[ch]["worse_than_before"].get<bool>()) worse.push_back(ch);
  std::stable_sort(
      effects.begin(), effects.end(), [](const nlohmann::json& a, const nlohmann::json& b) {
        return a["explained_fraction"].get<double>() > b["explained_fraction"].get<double>();
      });
  const std::string no_temperature =
      "not applicable: no machine model behind the data, so no temperature is predicted (reported "
      "as null)";
  nlohmann::json doc{
      {"mode", "data-driven (no --case)"},
      {"runs", splits},
      {"before",
       {{"temperature_rms_K", nullptr},
        {"temperature_note", no_temperature},
        {"displacement_rms_um", std::sqrt(sum_before / static_cast<double>(count)) * 1e6},
        {"channels", channels_before}}},
      {"after",
       {{"temperature_rms_K", nullptr},
        {"temperature_note", no_temperature},
        {"displacement_rms_um", std::sqrt(sum_after / static_cast<double>(count)) * 1e6},
        {"channels", channels_after}}},
      {"effects", effects},
      {"tested_per_step", tested},
      {"models", models},
      {"test_residual_correlations", diagnosis},
      {"method",
       {{"baseline",
         "the model fit --data chooses on the same training blocks (same candidates, same rule): "
         "no compensation, least squares, ridge, or ridge on every temperature rise with its "
         "first-order lags at 600 s and 3600 s (and the speed with its lags, where there is one), "
         "lambda in 1e-6..10, the lowest mean held-out S^2 guarded by one standard error against "
         "no compensation; effects are fitted jointly with it under its lambda"},
        {"explained_fraction",
         "share of the baseline's leave-one-segment-out training residual sum of squares the "
         "effect removes (given the effects added before it)"},
        {"threshold",
         "claimed when step_fraction - 0.01 x added_coefficients > null_fraction, the largest "
         "share reached by 19 phase-randomised surrogates of the same term (same amplitude "
         "spectrum, random phases, one surrogate per segment), each searched over the same "
         "settings, and never below 0 (a term with no relation to the residual beats all 19 with "
         "probability 1/20), and when its per-segment held-out gain is more than 2 standard "
         "errors above 0 (heldout_gain_t > 2: the gain holds from segment to segment)"},
        {"segments", block_origin + "; each segment's drift re-zeroed at its start"}}},
      {"speed_input", has_speed},
      {"after_worse_than_before_on_test", worse}};
  // The header that both calibrate modes write (docs/schemas/calibration.schema.json).
  doc["format"] = "thermotwin-calibration/1";
  doc["training_runs"] = nlohmann::json::array();
  doc["test_runs"] = nlohmann::json::array();
  for (const auto& s : splits)
    doc[s["role"] == "train" ? "training_runs" : "test_runs"].push_back(s["folder"]);

  // 4. Outputs, all or nothing.
  const auto& dir = out.path();
  io::write_json(dir / "calibration.json", doc);
  std::ostringstream md;
  md.setf(std::ios::fixed);
  md.precision(2);
  md << "# calibrate (data-driven)\n\nTraining segments: " << training.size() << " ("
     << block_origin << "), test segments: " << testing.size()
     << (has_speed ? "" : ". The runs have no speed input: no speed term is tried")
     << ". No machine model: temperatures are inputs, not predictions, so `temperature_rms_K` is "
        "null.\n\n"
     << "Before: per channel, the model `fit --data` chooses on the same training blocks (blocked "
        "cross-validation); after: with the claimed effects added.\n\n"
     << "| channel | before: chosen model | test RMS before [um] | test RMS after [um] | test MAE "
        "before [um] | test MAE after [um] |\n"
     << "|---|---|---|---|---|---|\n";
  for (const auto& ch : targets)
    md << "| " << ch << " | `" << models[ch]["baseline_choice"]["model"].get<std::string>()
       << "` | " << channels_before[ch]["rms_um"].get<double>() << " | "
       << channels_after[ch]["rms_um"].get<double>() << " | "
       << channels_before[ch]["mae_um"].get<double>() << " | "
       << channels_after[ch]["mae_um"].get<double>() << " |\n";
  md << "| all | | " << doc["before"]["displacement_rms_um"].get<double>() << " | "
     << doc["after"]["displacement_rms_um"].get<double>() << " | | |\n\n";
  if (!worse.empty()) {
    md << "**Worse after than before on the test data:**";
    for (const auto& ch : worse)
      md << " " << ch << " (" << channels_before[ch]["rms_um"].get<double>() << " -> "
         << channels_after[ch]["rms_um"].get<double>() << " um RMS)";
    md << ". The effects were claimed on held-out training segments only; on these test data "
          "they do not hold.\n\n";
  }
  md << "## Effects claimed\n\n";
  if (effects.empty())
    md << "None: no candidate term beat its surrogates with a gain that holds from segment to "
          "segment.\n";
  else {
    md << "| kind | channel | parameters | explained fraction | null threshold | held-out "
          "training RMS before -> with it [um] | gain t | test RMS with it [um] |\n"
       << "|---|---|---|---|---|---|---|---|\n";
    md.precision(3);
    for (const auto& e : effects)
      md << "| " << e["kind"].get<std::string>() << " | "
         << e["location"]["channel"].get<std::string>() << " | `" << e["parameters"].dump()
         << "` | " << e["explained_fraction"].get<double>() << " | "
         << e["null_fraction"].get<double>() << " | "
         << e["heldout_training_rms_um_before"].get<double>() << " -> "
         << e["heldout_training_rms_um_with_it"].get<double>() << " | "
         << e["heldout_gain_t"].get<double>() << " | "
         << e["test_rms_um_with_effects_so_far"].get<double>() << " |\n";
  }
  md << "\nHow an effect is claimed: " << doc["method"]["threshold"].get<std::string>()
     << ".\n\n## Test residual\n\n";
  for (const auto& [ch, table] : tables) {
    const auto csv = dir / ("residual_" + ch + ".csv");
    if (has_speed) {
      io::write_csv(csv,
                    {"time_s", "speed_krpm", "measured_um", "predicted_before_um",
                     "residual_before_um", "residual_after_um"},
                    table);
      plot({"lines", csv.string(), (dir / ("residual_" + ch + ".png")).string(), "--x", "time_s",
            "--columns", "speed_krpm,measured_um,residual_before_um,residual_after_um", "--ylabel",
            "um (speed: krpm)", "--title=test segments, channel " + ch});
    } else {
      Eigen::MatrixXd no_speed(table.rows(), 5);
      no_speed << table.col(0), table.rightCols(4);
      io::write_csv(csv,
                    {"time_s", "measured_um", "predicted_before_um", "residual_before_um",
                     "residual_after_um"},
                    no_speed);
      plot({"lines", csv.string(), (dir / ("residual_" + ch + ".png")).string(), "--x", "time_s",
            "--columns", "measured_um,residual_before_um,residual_after_um", "--ylabel", "um",
            "--title=test segments, channel " + ch});
    }
    md << "![" << ch << "](residual_" << ch << ".png)\n";
  }
  io::write_file_atomically(dir / "report.md", md.str());
  out.commit();
  std::cerr << "thermotwin: calibrate: test RMS "
            << doc["before"]["displacement_rms_um"].get<double>() << " -> "
            << doc["after"]["displacement_rms_um"].get<double>() << " um, " << effects.size()
            << " effects\n";
  return 0;
}

}  // namespace tt::app
