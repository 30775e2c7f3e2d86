#include "io/calibration_effects_out.hpp"

#include <variant>
#include <vector>

namespace tt::io {

using nlohmann::json;
using namespace calibration;

namespace {

json vector3_json(const Eigen::Vector3d& v) {
  return {v(0), v(1), v(2)};
}

const std::string& group_name(const core::CaseSpec& spec, int group) {
  return spec.groups.at(static_cast<size_t>(group)).name;
}

/// The names of the groups of convection entries `entries`.
json entry_groups_json(const core::CaseSpec& spec, const std::vector<int>& entries) {
  json groups = json::array();
  for (int e : entries)
    groups.push_back(group_name(spec, spec.thermal.convection.at(static_cast<size_t>(e)).group));
  return groups;
}

/// A film change on `entries`: its one group, or every group's when one share of h acts on several.
json film_location_json(const core::CaseSpec& spec, const std::vector<int>& entries) {
  if (entries.size() > 1)
    return {{"groups", entry_groups_json(spec, entries)}, {"share_of_h", true}};
  return {{"group", entry_groups_json(spec, entries).at(0)}};
}

/// A change of `p` spread over the places of `weights`: the value at a single place, or the common
/// parameter (in `j`) and each place's share (location order).
json spread_json(json& j, const std::vector<double>& weights, double p) {
  if (weights.size() <= 1) return p * (weights.empty() ? 1.0 : weights[0]);
  j["common_parameter"] = p;
  json each = json::array();
  for (double w : weights) each.push_back(p * w);
  return each;
}

/// The parameters `p` of `c` with their units in the keys.
json parameters_json(const Candidate& c, const std::vector<double>& p) {
  json j;
  std::visit(
      [&](const auto& e) {
        using E = std::decay_t<decltype(e)>;
        if constexpr (std::is_same_v<E, AmbientTemperature>) {
          j["knots_s"] = e.knots;
          j["delta_air_K"] = p;
        } else if constexpr (std::is_same_v<E, HeatInput>) {
          j["law"] = law_name(e.law);
          j["flux_W_m2"] = p.at(0);
          j["power_W"] = p.at(0) * e.area;
          if (e.law == HeatLaw::speed) j["ref_speed_rpm"] = e.ref_speed_rpm;
        } else if constexpr (std::is_same_v<E, SpeedDependentConvection>) {
          j["h_speed_gain_W_m2K"] = spread_json(j, e.weights, p.at(0));
          j["speed_ref_rpm"] = e.ref_speed_rpm;
          j["speed_exponent"] = e.speed_exponent;
        } else if constexpr (std::is_same_v<E, TemperatureDependentHeat>) {
          j["temperature_coefficient_per_K"] = spread_json(j, e.weights, p.at(0));
        } else if constexpr (std::is_same_v<E, BoundaryConductance>) {
          j["delta_h_W_m2K"] = spread_json(j, e.weights, p.at(0));
        } else if constexpr (std::is_same_v<E, MaterialParameter>) {
          j["relative_change"] = p.at(0);
        } else if constexpr (std::is_same_v<E, SensorOffset>) {
          j["offset_K"] = p.at(0);
        } else {
          static_assert(std::is_same_v<E, SensorLag>);
          j["time_constant_s"] = e.time_constant_s;
        }
      },
      c.effect);
  return j;
}

/// A refitted fit's account: steps, sums of squares, the held-out check and both sizes.
json refit_json(const Candidate& c, const EffectFit& f) {
  // A per-run air follows the others' refit; lags are held as fitted.
  json refit = {{"iterations", f.refit_iterations},
                {"converged", f.refit_converged},
                {"whitened_ss_at_linearised", f.refit_ss_linearised},
                {"whitened_ss_at_refitted", f.refit_ss}};
  if (f.refit_heldout_checked)
    refit["heldout_check"] = {
        {"whitened_ss_linearised", f.refit_heldout_ss_linearised},
        {"whitened_ss_refitted", f.refit_heldout_ss_refitted},
        {"accepted", f.refit_accepted},
        {"rule",
         "per training run, the claims fitted on the other runs (linearised, and refitted about "
         "the updated model) and judged on it; the refit is kept only when it lowers the sum"}};
  if (f.linearised.empty()) {
    refit["held_as_fitted"] = true;
  } else {
    refit["linearised"] = parameters_json(c, f.linearised);
    refit["refitted"] = parameters_json(c, f.refitted.empty() ? f.parameters : f.refitted);
    refit["kept"] = f.refit_accepted;
  }
  return refit;
}

/// A claimed air's sink on each test run: [[t_s, degC], ...].
json test_sinks_json(const std::vector<TestSink>& sinks) {
  json tests = json::array();
  for (const auto& t : sinks) {
    json table = json::array();
    for (size_t k = 0; k < t.sink.time.size(); ++k)
      table.push_back({t.sink.time[k], t.sink.value[k]});
    tests.push_back({{"run", t.run}, {"sink_table_s_degC", table}});
  }
  return tests;
}

}  // namespace

namespace {

/// Whether `c` follows the speed: a film's gain, heat growing with temperature, a speed-law heat.
bool speed_law(const Candidate& c) {
  const auto* heat = std::get_if<HeatInput>(&c.effect);
  return kind(c) == EffectKind::speed_dependent_convection ||
         kind(c) == EffectKind::temperature_dependent_heat || (heat && heat->law == HeatLaw::speed);
}

}  // namespace

std::string telling_apart(const Candidate& a, const Candidate& b, const Naming& names) {
  std::vector<std::string> hints;
  auto either = [&](EffectKind k) { return kind(a) == k || kind(b) == k; };
  if (either(EffectKind::ambient_temperature))
    hints.push_back(
        "an air temperature sensor beside the machine (meta.json `ambient_sensor`): the air is "
        "then read, not fitted");
  if (speed_law(a) != speed_law(b))
    hints.push_back(
        "a duty cycle whose speed changes while the air does not, with holds of an hour or more "
        "at standstill and at the top speed: a speed-driven mechanism follows the steps, the "
        "other does not");
  if (either(EffectKind::temperature_dependent_heat) && speed_law(a) && speed_law(b))
    hints.push_back(
        "a long hold at one speed: heat that grows with temperature keeps rising after a film's "
        "change has settled");
  for (const Candidate* c : {&a, &b}) {
    if (const auto* heat = std::get_if<HeatInput>(&c->effect))
      hints.push_back("a temperature sensor at the heat input's place " +
                      vector3_json(heat->centre).dump() + " m");
    if (const int s = sensor_of(*c); s >= 0)
      hints.push_back("a second sensor beside " + names.channel_ids.at(static_cast<size_t>(s)));
    if (const auto* heat = std::get_if<TemperatureDependentHeat>(&c->effect);
        heat && heat->sources.size() == 1) {
      const auto& src = names.spec.thermal.sources.at(static_cast<size_t>(heat->sources[0]));
      hints.push_back("a sensor on " + names.spec.bodies.at(static_cast<size_t>(src.body)).name);
    }
  }
  if (changes_expansion(a) || changes_expansion(b))
    hints.push_back("a displacement probe in another direction or at another point");
  std::string out;
  for (const auto& h : hints) out += (out.empty() ? "" : "; ") + h;
  return out.empty() ? "a run with another duty cycle, and sensors where the two differ most" : out;
}

json location_json(const Candidate& c, const Naming& names) {
  const core::CaseSpec& spec = names.spec;
  return std::visit(
      [&](const auto& e) -> json {
        using E = std::decay_t<decltype(e)>;
        if constexpr (std::is_same_v<E, AmbientTemperature>) {
          return {{"convection_groups", entry_groups_json(spec, e.entries)}};
        } else if constexpr (std::is_same_v<E, HeatInput>) {
          json groups = json::array();
          for (int g : e.groups) groups.push_back(group_name(spec, g));
          json j = {{"centre_m", vector3_json(e.centre)},
                    {"box_min_m", vector3_json(e.box_min)},
                    {"box_max_m", vector3_json(e.box_max)},
                    {"area_m2", e.area},
                    {"groups", groups}};
          if (e.body >= 0) j["body"] = spec.bodies.at(static_cast<size_t>(e.body)).name;
          return j;
        } else if constexpr (std::is_same_v<E, SpeedDependentConvection> ||
                             std::is_same_v<E, BoundaryConductance>) {
          return film_location_json(spec, e.entries);
        } else if constexpr (std::is_same_v<E, TemperatureDependentHeat>) {
          json sources = json::array();
          for (int i : e.sources)
            sources.push_back(spec.thermal.sources.at(static_cast<size_t>(i)).name);
          if (e.sources.size() > 1) return {{"sources", sources}};
          const auto& src = spec.thermal.sources.at(static_cast<size_t>(e.sources.at(0)));
          return {{"source", src.name},
                  {"body", spec.bodies.at(static_cast<size_t>(src.body)).name}};
        } else if constexpr (std::is_same_v<E, MaterialParameter>) {
          return {{"material", spec.materials.at(static_cast<size_t>(e.material)).name},
                  {"field", field_name(e.field)}};
        } else {
          static_assert(std::is_same_v<E, SensorOffset> || std::is_same_v<E, SensorLag>);
          return {{"sensor", names.channel_ids.at(static_cast<size_t>(e.sensor))}};
        }
      },
      c.effect);
}

json effect_json(const ReportedEffect& e, const Naming& names) {
  const Candidate& c = e.candidate;
  const EffectFit& f = e.fit;
  json j;
  j["kind"] = kind_name(kind(c));
  j["name"] = c.name;
  j["location"] = location_json(c, names);
  if (c.per_run) {
    json runs = json::array();
    for (size_t k = 0; k < f.run_parameters.size() && k < names.runs.size(); ++k)
      runs.push_back(
          {{"run", names.runs[k].name},
           {"parameters", parameters_json(c, f.run_parameters[k])},
           {"air", names.runs[k].air_from_sensor ? "ambient sensor" : "fitted within bounds"}});
    j["parameters"] = {{"per_training_run", runs}};
    if (e.claimed) j["parameters"]["per_test_run"] = test_sinks_json(e.test_sinks);
  } else {
    j["parameters"] = parameters_json(c, f.parameters);
  }
  j["explained_fraction"] = f.explained_fraction;
  j["heldout_gain"] = f.heldout_gain;
  j["score"] = f.score;
  j["model_form_floor"] = f.floor;
  j["heldout_gain_per_training_run"] = f.fold_gains;
  if (kind(c) == EffectKind::ambient_temperature) j["duty_correlation"] = f.duty_correlation;
  if (!f.unphysical.empty()) j["unphysical"] = f.unphysical;
  if (f.refit_iterations > 0) j["refit"] = refit_json(c, f);
  j["claimed"] = e.claimed;
  return j;
}

json effect_json(const Catalogue& cat, const EffectFit& fit, bool claimed) {
  return effect_json(reported(cat, fit, claimed), naming(cat));
}

json ambiguity_json(const ReportedAmbiguity& a, const Naming& names) {
  return {{"candidates", {effect_json(a.first, names), effect_json(a.second, names)}},
          {"score_difference", a.difference},
          {"spread", a.spread},
          {"distinguishing_channel",
           {{"channel", names.channel_ids.at(static_cast<size_t>(a.channel))},
            {"rms_difference_sigmas", a.channel_difference}}},
          {"hint", telling_apart(a.first.candidate, a.second.candidate, names)}};
}

json ambiguity_json(const Catalogue& cat, const Selection& sel) {
  const Naming names = naming(cat);
  json out = json::array();
  for (const auto& a : sel.ambiguous) out.push_back(ambiguity_json(reported(cat, a), names));
  return out;
}

json pair_json(const ReportedPair& p, const Naming& names) {
  return {{"candidates", {effect_json(p.first, names), effect_json(p.second, names)}},
          {"score", p.score},
          {"heldout_gain", p.heldout_gain},
          {"heldout_gain_per_training_run", p.fold_gains},
          {"adds_to_second_alone", p.adds_first},
          {"adds_to_first_alone", p.adds_second},
          {"admissible", p.admissible}};
}

}  // namespace tt::io
