#include "probes/command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <system_error>

#include "core/errors.hpp"

namespace tt::probes {
namespace {

std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

/// Spindle angle at a reading's first sample, relative to the reference angle [deg, 0..360).
double start_angle_deg(double offset_samples, double per_rev) {
  const double a = std::fmod(-360.0 * offset_samples / per_rev, 360.0);
  return a < 0.0 ? a + 360.0 : a;
}

DriftSeries truth_series(const std::filesystem::path& file, const ProbeRecord& record) {
  const DriftHistory history = read_drift_history_csv(file);
  if (history.size() != record.readings.size())
    throw core::DataError(core::located(file.string(), 0,
                                        std::to_string(history.size()) + " drift rows for " +
                                            std::to_string(record.readings.size()) +
                                            " readings: the truth needs one row per reading"));
  for (std::size_t i = 0; i < history.size(); ++i)
    if (std::abs(history[i].time_s - record.readings[i].start_time_s) >
        1e-6 * std::max(1.0, history[i].time_s))
      throw core::DataError(core::located(
          file.string(), 0,
          "row " + std::to_string(i + 1) + " time_s = " + num(history[i].time_s) + " but reading " +
              std::to_string(i + 1) + " starts at " + num(record.readings[i].start_time_s) + " s"));
  return drift_relative_to_first(history, record.probe_distance_m, record.has_axial_probe());
}

double max_difference(const DriftSeries& a, const DriftSeries& b) {
  return drift_error(a, b).max_drift_m;
}

std::string alignment_csv_text(const ProbeRecord& record, const RecoveredDrift& info,
                               const RecoveredDrift& xcorr) {
  std::string out =
      "reading,time_s,offset_info_samples,offset_xcorr_samples,start_angle_info_deg,"
      "start_angle_xcorr_deg,info_distance_nats,info_runner_up_nats\n";
  const double per_rev = info.plan.samples_per_revolution;
  for (std::size_t i = 0; i < record.readings.size(); ++i) {
    const ReadingAlignment& a = info.alignment[i];
    const ReadingAlignment& b = xcorr.alignment[i];
    out += std::to_string(i + 1) + "," + num(record.readings[i].start_time_s) + "," +
           num(a.offset_samples) + "," + num(b.offset_samples) + "," +
           num(start_angle_deg(a.offset_samples, per_rev)) + "," +
           num(start_angle_deg(b.offset_samples, per_rev)) + "," + num(a.best_score) + "," +
           num(a.runner_up_score) + "\n";
  }
  return out;
}

std::string summary_json_text(const std::filesystem::path& in, const ProbeRunSummary& s) {
  std::string out = "{\n";
  out += "  \"input\": \"" + in.generic_string() + "\",\n";
  out += "  \"readings\": " + std::to_string(s.readings) + ",\n";
  out += "  \"axial_probe\": " + std::string(s.has_axial ? "true" : "false") + ",\n";
  out += "  \"samples_per_revolution\": " + num(s.plan.samples_per_revolution) + ",\n";
  out += "  \"window_samples\": " + std::to_string(s.plan.window_samples) + ",\n";
  out += "  \"level_samples\": " + std::to_string(s.plan.level_samples) + ",\n";
  out += "  \"bins\": " + std::to_string(s.plan.bins) + ",\n";
  out += "  \"min_relative_margin\": " + num(s.min_relative_margin) + ",\n";
  out += "  \"methods\": {\n";
  for (std::size_t k = 0; k < s.methods.size(); ++k) {
    const MethodSummary& m = s.methods[k];
    out += "    \"" + method_name(m.method) + "\": {\"file\": \"" + m.file +
           "\", \"max_difference_from_info_um\": " + num(m.max_difference_from_info_m * 1e6);
    if (m.error_vs_truth)
      out += ", \"max_drift_error_um\": " + num(m.error_vs_truth->max_drift_m * 1e6) +
             ", \"max_tilt_error_urad\": " + num(m.error_vs_truth->max_tilt_rad * 1e6);
    out += k + 1 < s.methods.size() ? "},\n" : "}\n";
  }
  out += "  }\n}\n";
  return out;
}

}  // namespace

ProbeRunSummary run_probes_command(const std::filesystem::path& in,
                                   const std::filesystem::path& dir, const ProbeOptions& options) {
  const ProbeRecord record = read_raw_csv(in, options.constants);
  std::optional<DriftSeries> truth;
  if (options.truth_csv) truth = truth_series(*options.truth_csv, record);

  const std::vector<std::pair<AlignmentMethod, std::string>> methods = {
      {AlignmentMethod::information_distance, "drift.csv"},
      {AlignmentMethod::cross_correlation, "drift_xcorr.csv"},
      {AlignmentMethod::none, "drift_noalign.csv"},
      {AlignmentMethod::revolution_mean, "drift_revmean.csv"}};
  std::vector<RecoveredDrift> results;
  for (const auto& [method, file] : methods)
    results.push_back(recovered_drift(record, options.alignment, method));

  ProbeRunSummary summary;
  summary.readings = record.readings.size();
  summary.has_axial = record.has_axial_probe();
  summary.plan = results.front().plan;
  for (std::size_t i = 1; i < results.front().alignment.size(); ++i) {
    const ReadingAlignment& a = results.front().alignment[i];
    if (std::isfinite(a.runner_up_score) && a.runner_up_score > 0.0)
      summary.min_relative_margin = std::min(
          summary.min_relative_margin, (a.runner_up_score - a.best_score) / a.runner_up_score);
  }
  for (std::size_t k = 0; k < methods.size(); ++k) {
    MethodSummary m;
    m.method = methods[k].first;
    m.file = methods[k].second;
    m.max_difference_from_info_m = max_difference(results[k].drift, results.front().drift);
    if (truth) m.error_vs_truth = drift_error(results[k].drift, *truth);
    summary.methods.push_back(m);
  }

  for (std::size_t k = 0; k < methods.size(); ++k)
    write_text_atomically(dir / methods[k].second, drift_csv_text(results[k].drift));
  write_text_atomically(dir / "alignment.csv", alignment_csv_text(record, results[0], results[1]));
  write_text_atomically(dir / "summary.json", summary_json_text(in, summary));
  return summary;
}

VirtualRecord write_virtual_raw_csv(const std::filesystem::path& raw_csv,
                                    const VirtualProbeSetup& setup, const DriftHistory& history,
                                    const std::optional<std::filesystem::path>& truth_csv) {
  VirtualRecord v = virtual_record(setup, history);
  write_text_atomically(raw_csv, raw_csv_text(v.record));
  if (truth_csv)
    write_text_atomically(*truth_csv, drift_csv_text(drift_relative_to_first(
                                          history, setup.probe_distance_m, setup.axial_probe)));
  return v;
}

}  // namespace tt::probes
