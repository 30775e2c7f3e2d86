#include "io/observe_out.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "core/units.hpp"
#include "io/atomic_dir.hpp"
#include "io/reports.hpp"
#include "io/sample_stream.hpp"

namespace tt::io {
namespace {

std::string observer_csv(const solvers::ObserverRun& r,
                         const std::vector<std::string>& target_names,
                         const std::vector<std::string>& sensors) {
  std::ostringstream csv;
  csv << std::setprecision(9) << "time_s";
  for (const auto& t : target_names) csv << "," << t << "_predicted_um," << t << "_sigma_um";
  // With drift readings: each target's reading minus prediction and its sigma (empty between).
  const bool drifts = r.drift_innovation.size() != 0;
  if (drifts)
    for (const auto& t : target_names)
      csv << "," << t << "_drift_innovation_um," << t << "_drift_innovation_sigma_um";
  csv << ",nis,readings,window_nis,window_bound,status\n";
  // Empty where there is no reading; else in um with the file's 9 significant digits.
  const auto um = [](double v) {
    if (!std::isfinite(v)) return std::string();
    std::ostringstream cell;
    cell << std::setprecision(9) << v * core::kMicrometresPerMetre;
    return cell.str();
  };
  for (Eigen::Index i = 0; i < r.times.size(); ++i) {
    csv << r.times(i);
    for (Eigen::Index k = 0; k < r.drift.cols(); ++k)
      csv << "," << r.drift(i, k) * core::kMicrometresPerMetre << ","
          << r.drift_sigma(i, k) * core::kMicrometresPerMetre;
    if (drifts)
      for (Eigen::Index k = 0; k < r.drift.cols(); ++k)
        csv << "," << um(r.drift_innovation(i, k)) << "," << um(r.drift_innovation_sigma(i, k));
    const bool alarm = r.recalibrate && r.times(i) >= r.recalibrate_at_s;
    std::vector<std::string> faulty;
    for (const solvers::HeldSensor& f : r.sensor_faults)
      if (r.times(i) >= f.raised_s) faulty.push_back(sensors[static_cast<std::size_t>(f.sensor)]);
    const std::string status = model_status(alarm, faulty);
    csv << "," << r.nis(i) << "," << r.dof(i) << "," << r.window_nis(i) << "," << r.window_bound(i)
        << "," << (status.empty() ? "ok" : status) << "\n";
  }
  return csv.str();
}

/// Each unknown input's final estimate and sigma (heat inputs in W, the air's and the sensors'
/// offsets in K).
nlohmann::json unknown_inputs_json(const solvers::ObserverRun& r) {
  nlohmann::json unknown = nlohmann::json::object();
  const Eigen::Index last = r.times.size() - 1;
  for (std::size_t k = 0; k < r.unknown_input_names.size(); ++k) {
    const auto j = static_cast<Eigen::Index>(k);
    const bool kelvin = r.unknown_input_kinds[k] != solvers::UnknownInputKind::heat;
    unknown[r.unknown_input_names[k]] = {
        {kelvin ? "final_K" : "final_W", r.unknown_inputs(last, j)},
        {kelvin ? "sigma_K" : "sigma_W", r.unknown_inputs_sigma(last, j)}};
  }
  return unknown;
}

/// Each sensor found off by an offset: its id, the offset's final estimate and sigma [K], since
/// when it was beyond the bound and when the fault was raised [s].
nlohmann::json sensor_faults_json(const solvers::ObserverRun& r,
                                  const std::vector<std::string>& sensors) {
  nlohmann::json faults = nlohmann::json::array();
  const Eigen::Index last = r.times.size() - 1;
  for (const solvers::HeldSensor& f : r.sensor_faults) {
    const std::string& id = sensors[static_cast<std::size_t>(f.sensor)];
    const auto it =
        std::find(r.unknown_input_names.begin(), r.unknown_input_names.end(), "offset:" + id);
    const Eigen::Index j = it - r.unknown_input_names.begin();
    faults.push_back({{"sensor", id},
                      {"offset_K", r.unknown_inputs(last, j)},
                      {"sigma_K", r.unknown_inputs_sigma(last, j)},
                      {"since_s", f.since_s},
                      {"raised_s", f.raised_s}});
  }
  return faults;
}

/// Each sensor whose readings stayed away from the declared model's run: its id, since when, when
/// it was raised and where that began [s].
nlohmann::json departures_json(const solvers::ObserverRun& r,
                               const std::vector<std::string>& sensors) {
  nlohmann::json out = nlohmann::json::array();
  for (const solvers::HeldSensor& d : r.model_departures)
    out.push_back({{"sensor", sensors[static_cast<std::size_t>(d.sensor)]},
                   {"since_s", d.since_s},
                   {"raised_s", d.raised_s},
                   {"onset_s", d.onset_s}});
  return out;
}

/// The drift readings the observer took (a probe cycle): how often, of which targets, how many
/// samples, their noise, and the targets whose readings departed from the model.
nlohmann::json drift_readings_json(const studies::ObserveReport& report) {
  const solvers::ObserverRun& r = report.result;
  nlohmann::json departures = nlohmann::json::array();
  for (const solvers::HeldSensor& d : r.drift_departures)
    departures.push_back({{"target", report.setup.target_names[static_cast<std::size_t>(d.sensor)]},
                          {"since_s", d.since_s},
                          {"raised_s", d.raised_s}});
  return {{"every_s", report.drift_readings_every_s},
          {"targets", report.drift_targets},
          {"samples", report.drift_samples},
          {"sigma_um", 1e6 * report.setup.noise.drift_reading_sigma_m},
          {"departures", departures}};
}

/// Where each sensor was read: at the run's position, or at the named point of its id.
nlohmann::json places_json(const studies::ObserveReport& report) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t k = 0; k < report.sensors.size(); ++k) {
    const studies::SensorPlace& p = report.places.at(k);
    nlohmann::json entry{{"sensor", report.sensors[k]},
                         {"read_at", p.position ? "position" : "named point"}};
    if (p.position) entry["position_m"] = {(*p.position)(0), (*p.position)(1), (*p.position)(2)};
    if (p.from_named_point_m) entry["from_named_point_m"] = *p.from_named_point_m;
    out.push_back(std::move(entry));
  }
  return out;
}

std::string final_status(const solvers::ObserverRun& r) {
  if (r.recalibrate) return "recalibrate";
  return r.sensor_faults.empty() ? "ok" : "sensor_fault";
}

}  // namespace

nlohmann::json consistency_json(const solvers::ConsistencyOptions& c) {
  return {{"window_s", c.window_s},
          {"sustain_s", c.sustain_s},
          {"probability", c.probability},
          {"sensor_fault_sigmas", c.sensor_fault_sigmas},
          {"model_residual_sigmas", c.model_residual_sigmas},
          {"departure_onset_sigmas", c.departure_onset_sigmas},
          {"evidence_time_s", c.evidence_time_s},
          {"evidence_onset_sigmas", c.evidence_onset_sigmas}};
}

void write_observe(const std::filesystem::path& dir, const studies::ObserveReport& report,
                   const ObserveSource& source) {
  const solvers::ObserverRun& r = report.result;
  const solvers::ObserverSetup& setup = report.setup;
  write_file_atomically(dir / "observer.csv", observer_csv(r, setup.target_names, report.sensors));
  nlohmann::json doc = {
      {"run", source.run},
      {"case", source.case_name},
      {"model", {{"kind", "reduced"}, {"order", source.order}, {"rom", source.rom.string()}}},
      {"sensors", report.sensors},
      {"sensor_places", places_json(report)},
      {"noise", source.noise},
      {"consistency", consistency_json(setup.consistency)},
      {"status", final_status(r)},
      {"unknown_inputs", unknown_inputs_json(r)},
      {"sensor_faults", sensor_faults_json(r, report.sensors)},
      {"model_departures", departures_json(r, report.sensors)},
      {"recalibrate_since_s", nullptr},
      {"recalibrate_raised_s", nullptr}};
  if (report.drift_readings_every_s > 0) doc["drift_readings"] = drift_readings_json(report);
  if (r.recalibrate) {
    doc["recalibrate_since_s"] = r.recalibrate_since_s;
    doc["recalibrate_raised_s"] = r.recalibrate_at_s;
  }
  write_json(dir / "observer.json", doc);
}

}  // namespace tt::io
