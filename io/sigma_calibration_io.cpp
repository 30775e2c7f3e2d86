#include "io/sigma_calibration_io.hpp"

#include <algorithm>
#include <sstream>

#include "core/errors.hpp"
#include "core/units.hpp"
#include "io/fit_json_keys.hpp"
#include "io/observe_out.hpp"
#include "io/reports.hpp"

namespace tt::io {
namespace {

using nlohmann::json;

constexpr const char* kFormat = "thermotwin-sigma-calibration/1";

/// Per target: samples, rms_error_um and coverage (null where no sample had a measured drift).
json score_json(const solvers::DriftBandScore& s, const std::vector<std::string>& targets) {
  json out = json::object();
  for (std::size_t t = 0; t < targets.size(); ++t) {
    const auto k = static_cast<Eigen::Index>(t);
    out[targets[t]] = {
        {"samples", s.samples(k)},
        {"rms_error_um", finite_or_null(s.rms_error_m(k), core::kMicrometresPerMetre)},
        {"rms_sigma_um", finite_or_null(s.rms_sigma_m(k), core::kMicrometresPerMetre)},
        {"coverage", finite_or_null(s.coverage(k))}};
  }
  return out;
}

/// Per target, which rule gave the factor written: "averaged" or "coverage".
std::vector<std::string> rules(const studies::SigmaPass& pass) {
  std::vector<std::string> out;
  for (const studies::SigmaRule r : pass.rules)
    out.push_back(r == studies::SigmaRule::averaged ? "averaged" : "coverage");
  return out;
}

json pass_json(const studies::SigmaPass& pass, const studies::SigmaCalibration& c) {
  json runs = json::array();
  for (std::size_t k = 0; k < c.runs.size(); ++k)
    runs.push_back({{"run", c.runs[k]},
                    {"before", score_json(pass.before[k], c.targets)},
                    {"after", score_json(pass.after[k], c.targets)}});
  return {{"drift_sigma_scale", as_vector(pass.drift_sigma_scale)},
          {"rules", rules(pass)},
          {"coverage_drift_sigma_scale", as_vector(pass.coverage_drift_sigma_scale)},
          {"nees_drift_sigma_scale", as_vector(pass.nees_drift_sigma_scale)},
          {"averaged_drift_sigma_scale", pass.averaged_drift_sigma_scale.size() != 0
                                             ? json(as_vector(pass.averaged_drift_sigma_scale))
                                             : json(nullptr)},
          {"observed_with", as_vector(pass.observed_with)},
          {"before", score_json(pass.pooled_before, c.targets)},
          {"after", score_json(pass.pooled_after, c.targets)},
          {"runs", runs}};
}

json changed_json(const studies::ChangedMachineSigma& ch, const studies::SigmaCalibration& c) {
  json grid = json::array();
  for (const studies::SigmaTermsCandidate& pair : ch.grid)
    grid.push_back({{"correction_relative_sigma", pair.correction_relative_sigma},
                    {"expansion_relative_sigma", pair.expansion_relative_sigma},
                    {"score", score_json(pair.score, c.targets)},
                    {"width", pair.width},
                    {"reaches_goal", pair.reaches_goal}});
  json runs = json::array();
  for (std::size_t k = 0; k < ch.runs.size(); ++k)
    runs.push_back({{"run", ch.runs[k]},
                    {"before", score_json(ch.before[k], c.targets)},
                    {"after", score_json(ch.after[k], c.targets)}});
  json gates = json::array();
  for (const studies::GateChoice& g : ch.gates)
    gates.push_back({{"gate", changed_terms_gate_name(g.gate)},
                     {"correction_relative_sigma", g.pick.correction_relative_sigma},
                     {"expansion_relative_sigma", g.pick.expansion_relative_sigma},
                     {"changed", score_json(g.pick.score, c.targets)},
                     {"changed_width", g.pick.width},
                     {"training", score_json(g.training, c.targets)},
                     {"training_width", g.training_width}});
  json evidence = json::array();
  for (std::size_t k = 0; k < ch.evidence_settings.size(); ++k) {
    const studies::EvidenceChoice& e = ch.evidence_settings[k];
    evidence.push_back({{"evidence_time_s", e.settings.time_s},
                        {"onset_sigmas", e.settings.onset_sigmas},
                        {"bound_sigmas", e.settings.bound_sigmas},
                        {"correction_relative_sigma", e.choice.pick.correction_relative_sigma},
                        {"expansion_relative_sigma", e.choice.pick.expansion_relative_sigma},
                        {"changed", score_json(e.choice.pick.score, c.targets)},
                        {"training", score_json(e.choice.training, c.targets)},
                        {"training_width", e.choice.training_width},
                        {"reaches_goal", e.reaches_goal},
                        {"chosen", k == ch.evidence_chosen}});
  }
  const studies::SigmaTermsCandidate& pick = ch.pick();
  // The alarm's settings the pair was chosen with, and the evidence's it was scored under.
  solvers::ConsistencyOptions chosen_with = c.setup.consistency;
  chosen_with.evidence_time_s = ch.evidence.time_s;
  chosen_with.evidence_onset_sigmas = ch.evidence.onset_sigmas;
  std::vector<std::string> out_of_reach;
  for (std::size_t t = 0; t < c.targets.size(); ++t)
    if (ch.out_of_reach[t]) out_of_reach.push_back(c.targets[t]);
  return {{"runs", ch.runs},
          {"correction_relative_sigma", pick.correction_relative_sigma},
          {"expansion_relative_sigma", pick.expansion_relative_sigma},
          {"gate", changed_terms_gate_name(ch.gate)},
          {"after_alarm", ch.gate == solvers::ChangedTermsGate::after_alarm},
          {"out_of_reach", out_of_reach},
          {"grid", grid},
          {"per_run", runs},
          {"gates", gates},
          {"evidence_settings", evidence},
          {"consistency", consistency_json(chosen_with)}};
}

/// changed_machine's gate: its "gate" (from session 19 on), which agrees with its "after_alarm";
/// a file of session 18 has only the latter.
solvers::ChangedTermsGate gate_at(const json& changed, const fit_keys::Place& p) {
  const json& alarm = fit_keys::member(changed, "after_alarm", p, "changed_machine.");
  if (!alarm.is_boolean())
    throw core::DataError(p.at("changed_machine.after_alarm") + " = " + alarm.dump() +
                          ": expected true or false");
  if (!changed.contains("gate"))
    return alarm.get<bool>() ? solvers::ChangedTermsGate::after_alarm
                             : solvers::ChangedTermsGate::always;
  for (const auto gate : solvers::kChangedTermsGates)
    if (changed["gate"] == changed_terms_gate_name(gate)) {
      if (alarm.get<bool>() != (gate == solvers::ChangedTermsGate::after_alarm))
        throw core::DataError(p.at("changed_machine.after_alarm") + " = " + alarm.dump() +
                              ": disagrees with changed_machine.gate = " + changed["gate"].dump());
      return gate;
    }
  throw core::DataError(p.at("changed_machine.gate") + " = " + changed["gate"].dump() +
                        ": expected \"always\", \"on_evidence\" or \"after_alarm\"");
}

/// "a,b,c": the factors as a flag's value.
std::string flag_value(const Eigen::VectorXd& v) {
  std::ostringstream s;
  s.precision(6);
  for (Eigen::Index i = 0; i < v.size(); ++i) s << (i ? "," : "") << v(i);
  return s.str();
}

/// Factors at `key`: one per target, each finite and above 0.
Eigen::VectorXd factors_at(const json& j, const std::string& key, const fit_keys::Place& p,
                           const std::string& path, std::size_t targets) {
  const Eigen::VectorXd v = fit_keys::vector_at(j, key, p, path);
  if (static_cast<std::size_t>(v.size()) != targets)
    throw core::DataError(p.at(path + key) + " has " + std::to_string(v.size()) +
                          " factors; expected one per target (" + std::to_string(targets) + ")");
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!(v(i) > 0))
      throw core::DataError(p.at(path + key) + "[" + std::to_string(i) +
                            "] = " + j[key][static_cast<std::size_t>(i)].dump() +
                            ": expected a factor above 0");
  return v;
}

}  // namespace

json sigma_calibration_json(const studies::SigmaCalibration& c,
                            const SigmaCalibrationSource& source) {
  std::string flags = "--drift-sigma-scale " + flag_value(c.temperatures.drift_sigma_scale);
  json out = {{"format", kFormat},
              {"case", source.case_name},
              {"reduced_model", {{"dir", source.rom.string()}, {"order", source.order}}},
              {"training_runs", c.runs},
              {"sensors", c.sensors},
              {"targets", c.targets},
              {"measured_targets", c.measured_targets},
              {"coverage", c.coverage},
              {"truth_sigma_um", c.truth_sigma_m * core::kMicrometresPerMetre},
              {"noise", source.noise},
              {"drift_sigma_scale", as_vector(c.temperatures.drift_sigma_scale)},
              {"temperatures", pass_json(c.temperatures, c)},
              {"probe_cycle", nullptr}};
  if (c.probed) {
    out["probe_cycle"] = pass_json(*c.probed, c);
    out["probe_cycle"]["every_s"] = c.drift_readings_every_s;
    out["probed_drift_sigma_scale"] = as_vector(c.probed->drift_sigma_scale);
    flags += " --probed-drift-sigma-scale " + flag_value(c.probed->drift_sigma_scale);
  }
  out["changed_machine"] = nullptr;
  if (c.changed) {
    out["changed_machine"] = changed_json(*c.changed, c);
    const studies::SigmaTermsCandidate& pick = c.changed->pick();
    out["correction_relative_sigma"] = pick.correction_relative_sigma;
    out["expansion_relative_sigma"] = pick.expansion_relative_sigma;
    std::ostringstream more;
    more << " --correction-relative-sigma " << pick.correction_relative_sigma;
    if (pick.expansion_relative_sigma > 0)
      more << " --expansion-relative-sigma " << pick.expansion_relative_sigma;
    if (c.changed->gate != solvers::ChangedTermsGate::always)
      more << " " << changed_terms_gate_flag(c.changed->gate);
    if (c.changed->gate == solvers::ChangedTermsGate::on_evidence)
      more << " --evidence-time-s " << c.changed->evidence.time_s << " --evidence-onset-sigmas "
           << c.changed->evidence.onset_sigmas;
    flags += more.str();
  }
  out["flags"] = flags;
  return out;
}

SigmaCalibrationFile read_sigma_calibration(const std::filesystem::path& path) {
  const json j = fit_keys::read_json(path, "a sigma_calibration.json file");
  const fit_keys::Place p{path.string(), "",
                          "give a sigma_calibration.json written by `thermotwin observe --train`"};
  const json& format = fit_keys::member(j, "format", p, "");
  if (format != kFormat)
    throw core::DataError(p.at("format") + " = " + format.dump() + ": expected \"" + kFormat +
                          "\"");
  SigmaCalibrationFile f;
  f.sensors = fit_keys::names_at(j, "sensors", p, "");
  f.targets = fit_keys::names_at(j, "targets", p, "");
  f.drift_sigma_scale = factors_at(j, "drift_sigma_scale", p, "", f.targets.size());
  if (!fit_keys::member(j, "probe_cycle", p, "").is_null()) {
    f.probe_every_s = fit_keys::number_at(j["probe_cycle"], "every_s", p, "probe_cycle.");
    f.probed_drift_sigma_scale = factors_at(j, "probed_drift_sigma_scale", p, "", f.targets.size());
  }
  // Written from session 18 on: a file of before has no changed_machine.
  if (j.contains("changed_machine") && !j["changed_machine"].is_null()) {
    const auto relative = [&](const std::string& key) {
      const double v = fit_keys::number_at(j["changed_machine"], key, p, "changed_machine.");
      if (!(v >= 0))
        throw core::DataError(p.at("changed_machine." + key) + " = " +
                              j["changed_machine"][key].dump() + ": expected a value >= 0");
      return v;
    };
    f.correction_relative_sigma = relative("correction_relative_sigma");
    f.expansion_relative_sigma = relative("expansion_relative_sigma");
    f.changed_terms = gate_at(j["changed_machine"], p);
    // Written from session 19 on: the settings the gates' alarm and evidence were scored with.
    if (j["changed_machine"].contains("consistency")) {
      const json& c = j["changed_machine"]["consistency"];
      const std::string at = "changed_machine.consistency.";
      solvers::ConsistencyOptions o;
      o.window_s = fit_keys::number_at(c, "window_s", p, at);
      o.sustain_s = fit_keys::number_at(c, "sustain_s", p, at);
      o.probability = fit_keys::number_at(c, "probability", p, at);
      o.sensor_fault_sigmas = fit_keys::number_at(c, "sensor_fault_sigmas", p, at);
      o.model_residual_sigmas = fit_keys::number_at(c, "model_residual_sigmas", p, at);
      o.evidence_time_s = fit_keys::number_at(c, "evidence_time_s", p, at);
      // Written from session 20 on; before, the evidence's onset was 1 sigma.
      if (c.contains("evidence_onset_sigmas"))
        o.evidence_onset_sigmas = fit_keys::number_at(c, "evidence_onset_sigmas", p, at);
      f.consistency = o;
    }
  }
  return f;
}

std::string changed_terms_gate_flag(solvers::ChangedTermsGate gate) {
  std::string flag = "--changed-terms-" + changed_terms_gate_name(gate);
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

std::string changed_terms_gate_name(solvers::ChangedTermsGate gate) {
  switch (gate) {
    case solvers::ChangedTermsGate::on_evidence:
      return "on_evidence";
    case solvers::ChangedTermsGate::after_alarm:
      return "after_alarm";
    case solvers::ChangedTermsGate::always:
      break;
  }
  return "always";
}

}  // namespace tt::io
