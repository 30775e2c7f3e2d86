#include "io/fit_data_in.hpp"

#include <cmath>

#include "core/errors.hpp"
#include "io/measured_segments.hpp"

namespace tt::io {
namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

/// Every run has displacements and temperatures, the first run's columns and its speed input.
void require_same_columns(const std::vector<MeasuredRun>& runs) {
  const bool has_speed = measured_speed(runs[0]).size() != 0;
  for (const auto& r : runs) {
    if (r.displacements.empty() || r.sensors.empty())
      throw core::DataError(r.folder.string() +
                            ": no displacement or no temperature columns: nothing to fit");
    if (r.displacements.size() != runs[0].displacements.size() ||
        r.sensors.size() != runs[0].sensors.size())
      throw core::DataError(r.folder.string() + ": columns differ from " + runs[0].folder.string() +
                            ": every run must have the same sensors and displacements");
    if ((measured_speed(r).size() != 0) != has_speed)
      throw core::DataError(
          r.folder.string() + (has_speed ? " has no speed input but " : " has a speed input but ") +
          runs[0].folder.string() + (has_speed ? " has one" : " has none") +
          ": every run must have the same inputs; hint: drop the speed column from all runs, or "
          "give it in all");
  }
}

/// The held-out window of the last training run (or none, with test runs), and why.
void choose_window(const std::vector<MeasuredRun>& runs, bool test_runs,
                   std::optional<double> from_s, std::optional<double> to_s, DataFitRuns& out) {
  if (test_runs) {
    out.window_origin = "the runs given with --test, tested whole";
  } else if (from_s || to_s) {
    out.from_s = from_s.value_or(out.from_s);
    out.to_s = to_s.value_or(out.to_s);
    out.window_origin = "given on the command line";
  } else if (out.published) {
    out.from_s = out.published->from_s;
    out.to_s = out.published->to_s;
    out.window_origin = "the published figure's test window";
  } else if (runs.size() >= 3) {
    out.window_origin = "the last run, tested whole";
  } else {
    // From a stop, as every training piece starts: increments from a running spindle would take
    // the speed outside the training range.
    out.from_s = fitting::held_out_start(runs.back().time, measured_speed(runs.back()), 0.7, 0.7);
    out.window_origin = out.has_speed
                            ? "the last run from the start of its last speed cycle that begins "
                              "by 70 % of it"
                            : "the last 30 % of the last run";
  }
}

/// Run k's rows before, inside and after its window (a test run: all inside), as segments.
void cut_run(const MeasuredRun& run, std::size_t k, std::size_t count, bool windowed,
             DataFitRuns& out) {
  const std::string name = count == 1 ? std::string("run") : "run" + std::to_string(k + 1);
  const double lo = windowed ? out.from_s : inf;
  const double hi = windowed ? out.to_s : inf;
  const std::vector<std::pair<double, double>> parts =
      k >= out.training_runs
          ? std::vector<std::pair<double, double>>{{inf, inf}, {-inf, inf}}
          : std::vector<std::pair<double, double>>{{-inf, lo}, {lo, hi}, {hi, inf}};
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const auto& t = run.time;
    const bool any =
        (t.array() >= parts[p].first).cwiseProduct(t.array() < parts[p].second).count() >= 2;
    if (!any) continue;
    for (auto& s :
         measured_segments(run, name + (p == 1 ? ".test" : ""), parts[p].first, parts[p].second))
      (p == 1 ? out.testing : out.training_pieces).push_back(std::move(s));
  }
  // A window that covers a whole run leaves nothing of it to refit on: no continuous figure.
  if (windowed && (std::isfinite(out.from_s) || std::isfinite(out.to_s))) {
    std::vector<std::string> sensor_ids, probe_ids;
    for (const auto& sensor : run.sensors) sensor_ids.push_back(sensor.id);
    for (const auto& probe : run.displacements) probe_ids.push_back(probe.id);
    out.windowed_run =
        fitting::segment_of(name, run.time, measured_speed(run), run.temperature, run.displacement,
                            sensor_ids, probe_ids, {0, run.time.size()});
  }
}

}  // namespace

DataFitRuns read_data_fit_runs(const std::vector<std::filesystem::path>& runs,
                               const std::vector<std::filesystem::path>& test_runs,
                               std::optional<double> test_from_s, std::optional<double> test_to_s) {
  require_distinct_runs(runs, "--data");
  require_distinct_runs(test_runs, "--test");
  require_disjoint_runs(test_runs, runs, "--test", "--data",
                        "fit --data does not split a run; hint: hold out a time window with "
                        "--test-from-s/--test-to-s");
  std::vector<MeasuredRun> read;
  for (const auto& folder : runs) read.push_back(read_measured_run(folder));
  for (const auto& folder : test_runs) read.push_back(read_measured_run(folder));
  if (!test_runs.empty() && (test_from_s || test_to_s))
    throw core::DataError(
        "fit --data: --test RUN... and --test-from-s/--test-to-s both given; hint: hold out whole "
        "runs or a time window, not both");
  require_same_columns(read);
  DataFitRuns out;
  out.training_runs = runs.size();
  out.has_speed = measured_speed(read[0]).size() != 0;
  if (test_runs.empty()) out.published = read.back().published;
  choose_window(read, !test_runs.empty(), test_from_s, test_to_s, out);
  for (std::size_t k = 0; k < read.size(); ++k) {
    out.runs.push_back({read[k].folder, read[k].machine, read[k].run, k < runs.size()});
    cut_run(read[k], k, read.size(), test_runs.empty() && k + 1 == runs.size(), out);
  }
  if (out.testing.empty())
    throw core::DataError("fit --data: no samples in the test window [" +
                          std::to_string(out.from_s) + ", " + std::to_string(out.to_s) + ") s (" +
                          out.window_origin + ")");
  if (out.training_pieces.empty())
    throw core::DataError("fit --data: no training data outside the test window (" +
                          out.window_origin +
                          "); hint: give more runs, --test RUN... or a shorter test window");
  return out;
}

}  // namespace tt::io
