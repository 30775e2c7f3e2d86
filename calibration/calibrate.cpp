#include "calibration/calibrate.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "calibration/refit.hpp"
#include "core/errors.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"
#include "solvers/loads.hpp"

namespace tt::calibration {

namespace {

/// Whether two meshes have the same nodes and tets (a case meshed again with other groups).
bool same_tets(const mesh::TetMesh& a, const mesh::TetMesh& b) {
  return a.nodes.rows() == b.nodes.rows() && a.tets.rows() == b.tets.rows() &&
         a.tets.cols() == b.tets.cols() && a.tets == b.tets && a.nodes == b.nodes;
}

int group_index(const core::CaseSpec& spec, const std::string& name) {
  for (size_t g = 0; g < spec.groups.size(); ++g)
    if (spec.groups[g].name == name) return static_cast<int>(g);
  return -1;
}

std::string unique_group_name(const core::CaseSpec& spec, const std::string& stem) {
  std::string name = stem;
  for (int k = 2; group_index(spec, name) >= 0; ++k) name = stem + "_" + std::to_string(k);
  return name;
}

/// Inserts `g` at `at`, shifting every reference to later groups.
void insert_group(core::CaseSpec& spec, int at, core::BoundaryGroup g) {
  auto shift = [at](int& i) {
    if (i >= at) ++i;
  };
  for (auto& c : spec.thermal.convection) shift(c.group);
  for (auto& f : spec.thermal.fluxes) shift(f.group);
  for (auto& i : spec.mechanical.fixed_groups) shift(i);
  for (auto& p : spec.points) shift(p.on_group);
  spec.groups.insert(spec.groups.begin() + at, std::move(g));
}

nlohmann::json parameters_json(const Candidate& c, const std::vector<double>& p) {
  nlohmann::json j;
  // A change in several places: the common parameter and each place's share (location order).
  auto spread = [&](double v) -> nlohmann::json {
    if (c.entries.size() <= 1) return v * (c.weights.empty() ? 1.0 : c.weights[0]);
    j["common_parameter"] = v;
    nlohmann::json each = nlohmann::json::array();
    for (double w : c.weights) each.push_back(v * w);
    return each;
  };
  switch (c.kind) {
    case EffectKind::ambient_temperature:
      j["knots_s"] = c.knots;
      j["delta_air_K"] = p;
      break;
    case EffectKind::heat_input:
      j["law"] = c.law;
      j["flux_W_m2"] = p.at(0);
      j["power_W"] = p.at(0) * c.area;
      if (c.law == "speed") j["ref_speed_rpm"] = c.ref_speed_rpm;
      break;
    case EffectKind::speed_dependent_convection:
      j["h_speed_gain_W_m2K"] = spread(p.at(0));
      j["speed_ref_rpm"] = c.ref_speed_rpm;
      j["speed_exponent"] = c.speed_exponent;
      break;
    case EffectKind::temperature_dependent_heat:
      j["temperature_coefficient_per_K"] = spread(p.at(0));
      break;
    case EffectKind::boundary_conductance:
      j["delta_h_W_m2K"] = spread(p.at(0));
      break;
    case EffectKind::material_parameter:
      j["relative_change"] = p.at(0);
      break;
    case EffectKind::sensor_offset:
      j["offset_K"] = p.at(0);
      break;
    case EffectKind::sensor_lag:
      j["time_constant_s"] = c.time_constant;
      break;
  }
  return j;
}

bool speed_law(const nlohmann::json& c) {
  const std::string k = c.at("kind");
  return k == "speed_dependent_convection" || k == "temperature_dependent_heat" ||
         (k == "heat_input" && c.at("parameters").value("law", "") == "speed");
}

}  // namespace

std::string telling_apart(const nlohmann::json& a, const nlohmann::json& b) {
  std::vector<std::string> hints;
  auto either = [&](const std::string& kind) {
    return a.at("kind") == kind || b.at("kind") == kind;
  };
  if (either("ambient_temperature"))
    hints.push_back(
        "an air temperature sensor beside the machine (meta.json `ambient_sensor`): the air is "
        "then read, not fitted");
  if (speed_law(a) != speed_law(b))
    hints.push_back(
        "a duty cycle whose speed changes while the air does not, with holds of an hour or more "
        "at standstill and at the top speed: a speed-driven mechanism follows the steps, the "
        "other does not");
  if (either("temperature_dependent_heat") && speed_law(a) && speed_law(b))
    hints.push_back(
        "a long hold at one speed: heat that grows with temperature keeps rising after a film's "
        "change has settled");
  for (const auto* c : {&a, &b}) {
    const std::string k = c->at("kind");
    if (k == "heat_input" && c->at("location").contains("centre_m"))
      hints.push_back("a temperature sensor at the heat input's place " +
                      c->at("location").at("centre_m").dump() + " m");
    if ((k == "sensor_offset" || k == "sensor_lag") && c->at("location").contains("sensor"))
      hints.push_back("a second sensor beside " +
                      c->at("location").at("sensor").get<std::string>());
    if (k == "temperature_dependent_heat" && c->at("location").contains("body"))
      hints.push_back("a sensor on " + c->at("location").at("body").get<std::string>());
  }
  if (a.at("location").value("field", "") == "expansion" ||
      b.at("location").value("field", "") == "expansion")
    hints.push_back("a displacement probe in another direction or at another point");
  std::string out;
  for (const auto& h : hints) out += (out.empty() ? "" : "; ") + h;
  return out.empty() ? "a run with another duty cycle, and sensors where the two differ most" : out;
}

AugmentedCase augmented_case(const AugmentedCase& base, const Candidate& c,
                             const std::vector<double>& p, const Readout& r) {
  AugmentedCase out = base;
  core::CaseSpec& s = out.spec;
  auto& conv = s.thermal.convection;
  switch (c.kind) {
    case EffectKind::ambient_temperature:
      for (int e : c.entries) {
        core::TimeTable t;
        for (size_t k = 0; k < c.knots.size(); ++k) {
          t.time.push_back(c.knots[k]);
          t.value.push_back(solvers::table_value(conv[e].sink, c.knots[k]) + p.at(k));
        }
        conv[e].sink = t;
      }
      break;
    case EffectKind::heat_input: {
      for (const auto& gname : c.location.at("groups")) {
        const int g = group_index(s, gname.get<std::string>());
        if (g < 0) continue;
        core::BoundaryGroup ng;
        ng.name = unique_group_name(s, "heat_input_" + gname.get<std::string>());
        ng.rest = s.groups[g].rest;
        for (core::FaceSelector sel : s.groups[g].select) {
          // Only the patch's body: the bore's group also holds the shaft's faces across the gap.
          if (c.body >= 0) {
            if (!sel.bodies.empty() &&
                std::find(sel.bodies.begin(), sel.bodies.end(), c.body) == sel.bodies.end())
              continue;
            sel.bodies = {c.body};
          }
          sel.within_min = sel.within_min ? sel.within_min->cwiseMax(c.box_min) : c.box_min;
          sel.within_max = sel.within_max ? sel.within_max->cwiseMin(c.box_max) : c.box_max;
          ng.select.push_back(sel);
        }
        if (ng.select.empty()) continue;
        insert_group(s, g, ng);  // the covered group is now at g + 1
        const int covered = g + 1;
        std::vector<core::Convection> copies;
        for (const auto& cv : conv)
          if (cv.group == covered) {
            core::Convection copy = cv;
            copy.group = g;
            copies.push_back(copy);
          }
        conv.insert(conv.end(), copies.begin(), copies.end());
        std::vector<core::SurfaceFlux> fcopies;
        for (const auto& fl : s.thermal.fluxes)
          if (fl.group == covered) {
            core::SurfaceFlux copy = fl;
            copy.group = g;
            fcopies.push_back(copy);
          }
        s.thermal.fluxes.insert(s.thermal.fluxes.end(), fcopies.begin(), fcopies.end());
        auto& fixed = s.mechanical.fixed_groups;
        if (std::find(fixed.begin(), fixed.end(), covered) != fixed.end()) fixed.push_back(g);
        core::SurfaceFlux f;
        f.group = g;
        f.flux = p.at(0);
        f.follows_speed = c.law == "speed";
        f.ref_speed_rpm = f.follows_speed ? c.ref_speed_rpm : 0.0;
        s.thermal.fluxes.push_back(f);
        // A named point inside the patch may now sit on the new group only.
        for (auto& pt : s.points)
          if (pt.on_group == covered && (pt.position.array() >= c.box_min.array() - 1e-9).all() &&
              (pt.position.array() <= c.box_max.array() + 1e-9).all())
            pt.on_group = -1;
      }
      break;
    }
    case EffectKind::speed_dependent_convection:
      for (size_t k = 0; k < c.entries.size(); ++k) {
        auto& cv = conv.at(static_cast<size_t>(c.entries[k]));
        cv.h_speed_gain = std::max(0.0, cv.h_speed_gain + p.at(0) * c.weights.at(k));
        cv.speed_ref_rpm = c.ref_speed_rpm;
        cv.speed_exponent = c.speed_exponent;
      }
      break;
    case EffectKind::temperature_dependent_heat:
      for (size_t k = 0; k < c.entries.size(); ++k)
        s.thermal.sources.at(static_cast<size_t>(c.entries[k])).temperature_coefficient +=
            p.at(0) * c.weights.at(k);
      break;
    case EffectKind::boundary_conductance:
      for (size_t k = 0; k < c.entries.size(); ++k) {
        auto& cv = conv.at(static_cast<size_t>(c.entries[k]));
        cv.h = std::max(0.05 * cv.h, cv.h + p.at(0) * c.weights.at(k));
      }
      break;
    case EffectKind::material_parameter: {
      auto& mat = s.materials.at(static_cast<size_t>(c.material));
      const double factor = std::max(0.1, 1 + p.at(0));
      if (c.field == "conductivity")
        mat.conductivity *= factor;
      else if (c.field == "heat_capacity")
        mat.specific_heat *= factor;
      else
        mat.expansion *= factor;
      break;
    }
    case EffectKind::sensor_offset:
    case EffectKind::sensor_lag: {
      const std::string id = r.ids.at(static_cast<size_t>(c.sensor));
      auto it = std::find_if(out.sensors.begin(), out.sensors.end(),
                             [&](const auto& x) { return x.sensor == id; });
      if (it == out.sensors.end())
        it = out.sensors.insert(out.sensors.end(), SensorCorrection{id, 0, 0});
      if (c.kind == EffectKind::sensor_offset)
        it->offset_K += p.at(0);
      else
        it->lag_s = c.time_constant;
      break;
    }
  }
  return out;
}

Eigen::MatrixXd corrected(const Eigen::MatrixXd& ch, const Eigen::VectorXd& times, const Readout& r,
                          const std::vector<SensorCorrection>& corrections) {
  Eigen::MatrixXd out = ch;
  for (const auto& c : corrections) {
    const auto it = std::find(r.ids.begin(), r.ids.end(), c.sensor);
    if (it == r.ids.end()) continue;
    const Eigen::Index k = it - r.ids.begin();
    if (c.lag_s > 0) out.col(k) = lagged(times, out.col(k), c.lag_s);
    out.col(k).array() += c.offset_K;
  }
  return out;
}

RmsFigures rms_figures(const std::vector<Eigen::MatrixXd>& measured,
                       const std::vector<Eigen::MatrixXd>& simulated, int sensors) {
  double st = 0, su = 0, nt = 0, nu = 0;
  for (size_t r = 0; r < measured.size(); ++r)
    for (Eigen::Index c = 0; c < measured[r].cols(); ++c)
      for (Eigen::Index i = 0; i < measured[r].rows(); ++i) {
        const double e = measured[r](i, c) - simulated[r](i, c);
        if (!std::isfinite(e)) continue;
        if (c < sensors) {
          st += e * e;
          nt += 1;
        } else {
          su += e * e;
          nu += 1;
        }
      }
  return {nt > 0 ? std::sqrt(st / nt) : 0.0, nu > 0 ? 1e6 * std::sqrt(su / nu) : 0.0};
}

CalibrationResult calibrate(const MarchModel& model, const core::CaseSpec& declared,
                            const Catalogue& train, const std::vector<io::MeasuredRun>& test,
                            const CalibrationOptions& o) {
  CalibrationResult res;
  const mesh::TetMesh& mesh = model.mesh();
  // Nonlinear candidates judged on their size, not on their linearisation's (refit_alone).
  auto resizer = [&](const Catalogue& c) -> Resizer {
    const Eigen::VectorXd sigma = noise_sigma(c.runs, c.readout.sensors, o);
    return [&model, &declared, &c, sigma, &o](const EffectFit& f) {
      return refit_alone(model, declared, c, f, sigma, o);
    };
  };
  res.selection = select_effects(train, o, resizer(train));
  // A heat input or a sensor lag found on its grid: the place (the time constant) refined on finer
  // grids around the best ones, and the choice made again with those candidates, so that the
  // noise rule and the ranking see them too.
  // A heat input that is not the first claim is refined too (when the first has nothing to
  // refine); its places are scored with the other claims' fits removed, so that an offset sensor
  // or an air does not pull them.
  std::optional<Catalogue> refined;
  if (!res.selection.claimed.empty()) {
    const std::vector<EffectFit>& claimed = res.selection.claimed;
    const Candidate& first = train.candidates[claimed.front().candidate];
    const auto heat = std::find_if(claimed.begin(), claimed.end(), [&](const EffectFit& f) {
      return f.kind == EffectKind::heat_input;
    });
    const bool heat_first = first.kind == EffectKind::heat_input;
    if (first.kind == EffectKind::sensor_lag && o.lag_refine_steps > 1)
      refined = with_refined_lag(train, first.sensor, first.time_constant, o);
    else if (first.kind == EffectKind::speed_dependent_convection && !o.speed_exponent_grid.empty())
      refined = with_speed_exponents(model, train, claimed.front().candidate, o);
    else if ((heat_first || heat != claimed.end()) && o.heat_refine_levels > 0) {
      std::vector<EffectFit> others;
      for (auto it = claimed.begin(); it != claimed.end(); ++it)
        if (it != heat) others.push_back(*it);
      refined = with_refined_heat_inputs(model, train, o, others);
    }
    if (refined) res.selection = select_effects(*refined, o, resizer(*refined));
  }
  const Catalogue& cat = refined ? *refined : train;
  const Readout& r = cat.readout;
  // The claims' sizes about the model they update, not their linearisation about the declared one.
  res.selection = refit_claimed(model, declared, cat, res.selection, o);
  // Per-run effects need their own fit on each test run (the air temperature is a signal of the
  // run, not of the machine): the ambient columns for the test runs.
  bool per_run = false;
  for (const auto& f : res.selection.claimed) per_run |= cat.candidates[f.candidate].per_run;
  Catalogue test_cat;
  if (per_run && !test.empty()) test_cat = catalogue(model, declared, r, test, o, true);

  std::vector<Eigen::MatrixXd> meas, before, after;
  for (size_t ti = 0; ti < test.size(); ++ti) {
    const io::MeasuredRun& run = test[ti];
    TestRun tr;
    tr.name = run.run;
    tr.times = run.time;
    const Readout rt = readout_like(mesh, declared, run, r);
    if (rt.ids != r.ids)
      throw core::DataError("test run '" + run.run +
                            "' has other located channels than the training runs; " +
                            "every run must list the same sensors and probes");
    tr.measured = measured_channels(run, rt);
    const core::CaseSpec spec = case_for_run(declared, run);
    tr.before = march(model, spec, rt, run.time, {}, {}).base;
    // The test run simulated with `aug` as its written file reads back (meshed again: heat inputs
    // add boundary groups), sensor corrections applied.
    auto simulated = [&](const AugmentedCase& aug) -> Eigen::MatrixXd {
      const core::CaseSpec again =
          io::case_from_toml(io::resolved_case_toml(aug.spec), "augmented.toml");
      // The augmented case's own mesh: its new boundary groups take faces of the same tets.
      const mesh::TetMesh m2 = mesh::mesh_case(again);
      if (model.is_reduced() && same_tets(m2, mesh)) {
        // The same basis: the augmented operators projected; the channels' rows kept (the sensor
        // weights depend on the tets only), the probes' with any change of expansion (exact:
        // the stiffness and the supports are the declared case's).
        Readout r2 = rt;
        r2.displacement = displacement_with_expansions(rt, declared, again);
        const MarchModel augmented = model.with_case(m2, again);
        return corrected(march(augmented, again, r2, run.time, {}, {}).base, run.time, r2,
                         aug.sensors);
      }
      const Readout r2 = readout(m2, again, run);
      return corrected(march(MarchModel(m2, again), again, r2, run.time, {}, {}).base, run.time, r2,
                       aug.sensors);
    };
    // The shared claims first; a per-run air is then fitted to what the model with them leaves of
    // the test run (fitted against the declared model alone, it would take the other claims'
    // signal a second time), and declared before them (a heat input's new group copies the
    // covered group's sink).
    AugmentedCase aug{spec, {}};
    std::vector<const EffectFit*> airs;
    for (const auto& f : res.selection.claimed) {
      const Candidate& c = cat.candidates[f.candidate];
      if (c.per_run)
        airs.push_back(&f);
      else
        aug = augmented_case(aug, c, f.parameters, r);
    }
    if (!airs.empty()) {
      RunModel left = test_cat.runs[ti];
      if (airs.size() < res.selection.claimed.size()) left.base = simulated(aug);
      AugmentedCase with_air{spec, {}};
      for (const EffectFit* f : airs) {
        const Candidate& c = cat.candidates[f->candidate];
        const auto it = std::find_if(test_cat.candidates.begin(), test_cat.candidates.end(),
                                     [&](const Candidate& x) { return x.name == c.name; });
        const std::vector<double> p =
            fit_run_parameters(*it, static_cast<int>(ti), left, r, res.selection.sigma, o);
        with_air = augmented_case(with_air, *it, p, r);
        // A second air is fitted to what the first leaves (its columns are the declared model's).
        const Eigen::VectorXd moved =
            it->columns[ti] *
            Eigen::Map<const Eigen::VectorXd>(p.data(), static_cast<Eigen::Index>(p.size()));
        left.base +=
            Eigen::Map<const Eigen::MatrixXd>(moved.data(), left.base.rows(), left.base.cols());
      }
      for (const auto& f : res.selection.claimed) {
        const Candidate& c = cat.candidates[f.candidate];
        if (!c.per_run) with_air = augmented_case(with_air, c, f.parameters, r);
      }
      aug = with_air;
    }
    tr.after = res.selection.claimed.empty() ? tr.before : simulated(aug);
    tr.augmented = aug;
    meas.push_back(tr.measured);
    before.push_back(tr.before);
    after.push_back(tr.after);
    res.tests.push_back(std::move(tr));
  }
  res.before = rms_figures(meas, before, r.sensors);
  res.after = rms_figures(meas, after, r.sensors);

  auto describe = [&](const EffectFit& f, bool claimed) {
    const Candidate& c = cat.candidates[f.candidate];
    nlohmann::json j = effect_json(cat, f, claimed);
    if (c.per_run && claimed) {
      nlohmann::json tests = nlohmann::json::array();
      for (const auto& t : res.tests) {
        const auto& sinks = t.augmented.spec.thermal.convection;
        nlohmann::json table = nlohmann::json::array();
        if (!c.entries.empty())
          for (size_t k = 0; k < sinks[c.entries[0]].sink.time.size(); ++k)
            table.push_back({sinks[c.entries[0]].sink.time[k], sinks[c.entries[0]].sink.value[k]});
        tests.push_back({{"run", t.name}, {"sink_table_s_degC", table}});
      }
      j["parameters"]["per_test_run"] = tests;
    }
    return j;
  };
  res.effects = nlohmann::json::array();
  for (const auto& f : res.selection.claimed) res.effects.push_back(describe(f, true));
  res.runners_up = nlohmann::json::array();
  for (const auto& f : res.selection.ranking) {
    const bool is_claimed =
        !res.selection.claimed.empty() && f.candidate == res.selection.claimed.front().candidate;
    if (!is_claimed) res.runners_up.push_back(describe(f, false));
  }
  res.ambiguous = ambiguity_json(cat, res.selection);
  res.pairs = nlohmann::json::array();
  for (const auto& p : res.selection.pairs)
    res.pairs.push_back(
        {{"candidates", {effect_json(cat, p.first, false), effect_json(cat, p.second, false)}},
         {"score", p.score},
         {"heldout_gain", p.heldout_gain},
         {"heldout_gain_per_training_run", p.fold_gains},
         {"adds_to_second_alone", p.adds_first},
         {"adds_to_first_alone", p.adds_second},
         {"admissible", p.admissible}});
  res.refit_rejected = nlohmann::json::array();
  for (const auto& f : res.selection.refit_rejected)
    res.refit_rejected.push_back(effect_json(cat, f, false));
  return res;
}

nlohmann::json effect_json(const Catalogue& cat, const EffectFit& f, bool claimed) {
  const Candidate& c = cat.candidates[static_cast<size_t>(f.candidate)];
  nlohmann::json j;
  j["kind"] = kind_name(c.kind);
  j["name"] = c.name;
  j["location"] = c.location;
  if (c.per_run) {
    nlohmann::json runs = nlohmann::json::array();
    for (size_t k = 0; k < f.run_parameters.size() && k < cat.runs.size(); ++k)
      runs.push_back({{"run", cat.runs[k].name},
                      {"parameters", parameters_json(c, f.run_parameters[k])},
                      {"air", cat.runs[k].air.size() ? "ambient sensor" : "fitted within bounds"}});
    j["parameters"] = {{"per_training_run", runs}};
  } else {
    j["parameters"] = parameters_json(c, f.parameters);
  }
  j["explained_fraction"] = f.explained_fraction;
  j["heldout_gain"] = f.heldout_gain;
  j["score"] = f.score;
  j["model_form_floor"] = f.floor;
  j["heldout_gain_per_training_run"] = f.fold_gains;
  if (c.kind == EffectKind::ambient_temperature) j["duty_correlation"] = f.duty_correlation;
  if (!f.unphysical.empty()) j["unphysical"] = f.unphysical;
  if (f.refit_iterations > 0) {
    // A per-run air follows the others' refit; lags are held as fitted.
    nlohmann::json refit = {{"iterations", f.refit_iterations},
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
    j["refit"] = refit;
  }
  j["claimed"] = claimed;
  return j;
}

nlohmann::json ambiguity_json(const Catalogue& cat, const Selection& sel) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& a : sel.ambiguous) {
    const nlohmann::json first = effect_json(cat, a.first, false),
                         second = effect_json(cat, a.second, false);
    out.push_back({{"candidates", {first, second}},
                   {"score_difference", a.difference},
                   {"spread", a.spread},
                   {"distinguishing_channel",
                    {{"channel", cat.readout.ids.at(static_cast<size_t>(a.channel))},
                     {"rms_difference_sigmas", a.channel_difference}}},
                   {"hint", telling_apart(first, second)}});
  }
  return out;
}

ChannelFigures channel_figures(const std::vector<Eigen::MatrixXd>& measured,
                               const std::vector<Eigen::MatrixXd>& simulated, int channel) {
  Eigen::Index n = 0;
  for (const auto& m : measured) n += m.rows();
  Eigen::VectorXd residual(n);
  Eigen::Index at = 0;
  for (size_t r = 0; r < measured.size(); ++r) {
    residual.segment(at, measured[r].rows()) = measured[r].col(channel) - simulated[r].col(channel);
    at += measured[r].rows();
  }
  return core::error_figures(residual);
}

}  // namespace tt::calibration
