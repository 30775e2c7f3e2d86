#include "io/fit_campaign_out.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>

#include "core/units.hpp"
#include "io/atomic_dir.hpp"
#include "io/axis_fit_out.hpp"
#include "io/csv_out.hpp"
#include "io/fitting_out.hpp"
#include "io/network_out.hpp"
#include "io/plot.hpp"
#include "io/reports.hpp"

namespace tt::io {
namespace {

using nlohmann::json;

json campaign_json(const std::vector<solvers::CampaignRun>& runs) {
  json out = json::array();
  for (const auto& r : runs)
    out.push_back({{"name", r.name},
                   {"shape", r.shape},
                   {"hours", r.spec.duty_cycle.end / 3600.0},
                   {"initial_temperature_degC", r.spec.thermal.initial_temperature_c}});
  return out;
}

json fit_document(const studies::CampaignFitReport& report,
                  const std::vector<solvers::CampaignRun>& runs, const json& model) {
  std::vector<fitting::SensorCountTable> tables;
  for (const auto& t : report.targets) tables.push_back(t.sensor_count);
  json doc = fit_json(report.evaluations(), tables);
  doc["summary"] = campaign_fit_summary(report);
  doc["model"] = model;
  doc["campaign"] = campaign_json(runs);
  if (const auto& axis = report.axis) {
    doc["axis"] = axis_fit_json(*axis);
    doc["axis"]["seconds"] = report.axis_seconds;  // the axis points' models, network, polynomials
    if (!axis->network.empty()) doc["axis"]["network"]["file"] = "network_all_outputs.pt";
  }
  return doc;
}

/// What the standard's section 8.2.1 asks of the record, for a virtual machine.
ModellingConditions modelling_conditions(const core::CaseSpec& spec,
                                         const std::vector<solvers::CampaignRun>& runs) {
  ModellingConditions conditions;
  conditions.machine_model = spec.machine.empty() ? spec.name : spec.machine;
  conditions.machine_number = "virtual";
  conditions.modelling_date = modelling_date_today();
  conditions.initial_ambient_temperature =
      spec.thermal.initial_temperature_c + core::kCelsiusOffset;
  double max_speed = 0;  // [rpm]
  for (const auto& r : runs)
    for (const auto& s : r.spec.duty_cycle.segments) max_speed = std::max(max_speed, s.speed_rpm);
  conditions.max_spindle_speed = max_speed * 2 * std::numbers::pi / 60;
  return conditions;
}

/// The held-out groups' sensor readings [degC, as measured data]: the temperature states on
/// which `thermotwin export --states` judges the controllers' laws (docs/cnc-export.md).
void write_held_out(const std::filesystem::path& dir, const studies::CampaignFitReport& report) {
  std::filesystem::create_directories(dir / "held_out");
  for (int i : report.split.test) {
    const fitting::Group& g = report.groups[static_cast<std::size_t>(i)];
    std::vector<std::string> header{"time_s"};
    header.insert(header.end(), g.sensor_names.begin(), g.sensor_names.end());
    Eigen::MatrixXd rows(g.time.size(), g.temperature.cols() + 1);
    rows << g.time, g.temperature.array() - core::kCelsiusOffset;
    write_csv(dir / "held_out" / (g.name + "_temperatures.csv"), header, rows);
  }
}

/// The test S_M [um] by number of sensors, a column per placement method, and its figure.
void write_sensor_count(const std::filesystem::path& dir, const fitting::SensorCountTable& t) {
  std::set<std::string> methods;
  for (const auto& row : t.rows) methods.insert(row.method);
  std::vector<std::string> header{"m"};
  for (const auto& m : methods) header.push_back(m + "_test_sm_um");
  int max_m = 0;
  for (const auto& row : t.rows) max_m = std::max(max_m, row.m);
  Eigen::MatrixXd rows =
      Eigen::MatrixXd::Constant(max_m, static_cast<Eigen::Index>(header.size()), std::nan(""));
  for (int m = 1; m <= max_m; ++m) rows(m - 1, 0) = m;
  for (const auto& row : t.rows) {
    const auto col = 1 + std::distance(methods.begin(), methods.find(row.method));
    rows(row.m - 1, col) = row.test_sm * 1e6;
  }
  const std::string stem = "sensor_count_" + t.target_name;
  write_csv(dir / (stem + ".csv"), header, rows);
  std::string cols;
  for (size_t i = 1; i < header.size(); ++i) cols += (i > 1 ? "," : "") + header[i];
  plot({"lines", (dir / (stem + ".csv")).string(), (dir / (stem + ".png")).string(), "--x", "m",
        "--columns=" + cols, "--xlabel", "sensors m", "--ylabel", "test S_M [um]",
        "--title=test accuracy by number of sensors, target " + t.target_name});
}

}  // namespace

json campaign_fit_summary(const studies::CampaignFitReport& report) {
  json summary = json::object();
  const auto& sensor_names = report.groups.front().sensor_names;
  for (const auto& t : report.targets) {
    const auto& e = t.evaluation;
    const auto& chosen = e.sensor_sets[static_cast<std::size_t>(
        e.selection.candidates[static_cast<std::size_t>(e.selection.best)].sensor_set)];
    std::vector<std::string> names;
    for (int c : chosen.sensors) names.push_back(sensor_names[static_cast<std::size_t>(c)]);
    json& s =
        summary[e.target_name] = {{"method", chosen.method},
                                  {"sensors", names},
                                  {"model", fitting::model_label(e.model.spec)},
                                  {"test_sm_um", e.test.sm * 1e6},
                                  {"test_s_sigma_um", e.test.s_sigma * 1e6},
                                  {"uncompensated_std_um", t.uncompensated_std * 1e6},
                                  {"test_sm_over_uncompensated", e.test.sm / t.uncompensated_std}};
    if (!t.network) continue;
    s["network"] = network_json(*t.network);
    s["network"]["test_sm_over_uncompensated"] = t.network->test.sm / t.uncompensated_std;
    s["network"]["file"] = "network_" + e.target_name + ".pt";
  }
  return summary;
}

void write_campaign_fit(const std::filesystem::path& dir, const core::CaseSpec& spec,
                        const std::vector<solvers::CampaignRun>& runs,
                        const studies::CampaignFitReport& report, const json& model) {
  write_json(dir / "fit.json", fit_document(report, runs, model));
  if (const auto& axis = report.axis) {
    write_file_atomically(dir / "axis_fit.md", axis_fit_markdown(*axis));
    if (!axis->network.empty())
      write_network(dir / "network_all_outputs.pt", axis->network.front());
  }
  for (const auto& t : report.targets)
    if (t.network)
      write_network(dir / ("network_" + t.evaluation.target_name + ".pt"), t.network->model);
  const auto evaluations = report.evaluations();
  write_modelling_record(dir / "modelling_record.json", dir / "modelling_record.md",
                         modelling_conditions(spec, runs), evaluations);
  std::vector<fitting::FittedModel> models;
  for (const auto& e : evaluations) models.push_back(e.model);
  write_compensation_csv(dir / "compensation.csv", models, report.groups);
  write_held_out(dir, report);
  for (const auto& t : report.targets) write_sensor_count(dir, t.sensor_count);
}

}  // namespace tt::io
