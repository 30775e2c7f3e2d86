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

/// `stem`, or `stem`_2, _3, ...: the first name no group of `spec` has.
std::string unique_group_name(const core::CaseSpec& spec, const std::string& stem) {
  auto taken = [&](const std::string& name) {
    return std::any_of(spec.groups.begin(), spec.groups.end(),
                       [&](const core::BoundaryGroup& g) { return g.name == name; });
  };
  std::string name = stem;
  for (int k = 2; taken(name); ++k) name = stem + "_" + std::to_string(k);
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

/// `out` with the heat input `h` of flux `flux` [W/m^2] declared: per covered group, a new group
/// (the box's part of it, the patch's body only) just before it, with its convection and fluxes.
void declare_heat_input(AugmentedCase& out, const HeatInput& h, double flux) {
  core::CaseSpec& s = out.spec;
  auto& conv = s.thermal.convection;
  if (out.group_at.empty())
    for (size_t g = 0; g < s.groups.size(); ++g) out.group_at.push_back(static_cast<int>(g));
  for (const int declared : h.groups) {
    if (declared < 0 || static_cast<size_t>(declared) >= out.group_at.size()) continue;
    const int g = out.group_at[static_cast<size_t>(declared)];
    core::BoundaryGroup ng;
    ng.name = unique_group_name(s, "heat_input_" + s.groups[g].name);
    ng.rest = s.groups[g].rest;
    for (core::FaceSelector sel : s.groups[g].select) {
      // Only the patch's body: the bore's group also holds the shaft's faces across the gap.
      if (h.body >= 0) {
        if (!sel.bodies.empty() &&
            std::find(sel.bodies.begin(), sel.bodies.end(), h.body) == sel.bodies.end())
          continue;
        sel.bodies = {h.body};
      }
      sel.within_min = sel.within_min ? sel.within_min->cwiseMax(h.box_min) : h.box_min;
      sel.within_max = sel.within_max ? sel.within_max->cwiseMin(h.box_max) : h.box_max;
      ng.select.push_back(sel);
    }
    if (ng.select.empty()) continue;
    insert_group(s, g, ng);  // the covered group is now at g + 1
    for (int& at : out.group_at)
      if (at >= g) ++at;
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
    f.flux = flux;
    f.follows_speed = h.law == HeatLaw::speed;
    f.ref_speed_rpm = f.follows_speed ? h.ref_speed_rpm : 0.0;
    s.thermal.fluxes.push_back(f);
    // A named point inside the patch may now sit on the new group only.
    for (auto& pt : s.points)
      if (pt.on_group == covered && (pt.position.array() >= h.box_min.array() - 1e-9).all() &&
          (pt.position.array() <= h.box_max.array() + 1e-9).all())
        pt.on_group = -1;
  }
}

/// The correction of sensor `sensor` in `out`, added when it has none.
SensorCorrection& correction_of(AugmentedCase& out, const Readout& r, int sensor) {
  const std::string& id = r.ids.at(static_cast<size_t>(sensor));
  auto it = std::find_if(out.sensors.begin(), out.sensors.end(),
                         [&](const auto& x) { return x.sensor == id; });
  if (it == out.sensors.end())
    it = out.sensors.insert(out.sensors.end(), SensorCorrection{id, 0, 0});
  return *it;
}

}  // namespace

AugmentedCase augmented_case(const AugmentedCase& base, const Candidate& c,
                             const std::vector<double>& p, const Readout& r) {
  AugmentedCase out = base;
  core::CaseSpec& s = out.spec;
  auto& conv = s.thermal.convection;
  switch (kind(c)) {
    case EffectKind::ambient_temperature: {
      const auto& air = std::get<AmbientTemperature>(c.effect);
      for (int e : air.entries) {
        core::TimeTable t;
        for (size_t k = 0; k < air.knots.size(); ++k) {
          t.time.push_back(air.knots[k]);
          t.value.push_back(solvers::table_value(conv[e].sink, air.knots[k]) + p.at(k));
        }
        conv[e].sink = t;
      }
      break;
    }
    case EffectKind::heat_input:
      declare_heat_input(out, std::get<HeatInput>(c.effect), p.at(0));
      break;
    case EffectKind::speed_dependent_convection: {
      const auto& film = std::get<SpeedDependentConvection>(c.effect);
      for (size_t k = 0; k < film.entries.size(); ++k) {
        auto& cv = conv.at(static_cast<size_t>(film.entries[k]));
        cv.h_speed_gain = std::max(0.0, cv.h_speed_gain + p.at(0) * film.weights.at(k));
        cv.speed_ref_rpm = film.ref_speed_rpm;
        cv.speed_exponent = film.speed_exponent;
      }
      break;
    }
    case EffectKind::temperature_dependent_heat: {
      const auto& heat = std::get<TemperatureDependentHeat>(c.effect);
      for (size_t k = 0; k < heat.sources.size(); ++k)
        s.thermal.sources.at(static_cast<size_t>(heat.sources[k])).temperature_coefficient +=
            p.at(0) * heat.weights.at(k);
      break;
    }
    case EffectKind::boundary_conductance: {
      const auto& film = std::get<BoundaryConductance>(c.effect);
      for (size_t k = 0; k < film.entries.size(); ++k) {
        auto& cv = conv.at(static_cast<size_t>(film.entries[k]));
        cv.h = std::max(0.05 * cv.h, cv.h + p.at(0) * film.weights.at(k));
      }
      break;
    }
    case EffectKind::material_parameter: {
      const auto& change = std::get<MaterialParameter>(c.effect);
      material_value(s.materials.at(static_cast<size_t>(change.material)), change.field) *=
          std::max(0.1, 1 + p.at(0));
      break;
    }
    case EffectKind::sensor_offset:
      correction_of(out, r, std::get<SensorOffset>(c.effect).sensor).offset_K += p.at(0);
      break;
    case EffectKind::sensor_lag: {
      const auto& lag = std::get<SensorLag>(c.effect);
      correction_of(out, r, lag.sensor).lag_s = lag.time_constant_s;
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
  return {nt > 0 ? std::sqrt(st / nt) : 0.0, nu > 0 ? std::sqrt(su / nu) : 0.0};
}

namespace {

/// `res`'s reported claims, runners-up, ambiguities, pairs and refit rejections, from `cat`.
void describe(CalibrationResult& res, const Catalogue& cat) {
  const Selection& sel = res.selection;
  res.naming = naming(cat);
  for (const auto& f : sel.claimed) {
    ReportedEffect e = reported(cat, f, true);
    if (const auto* air = std::get_if<AmbientTemperature>(&e.candidate.effect);
        air && e.candidate.per_run)
      for (const auto& t : res.tests)
        e.test_sinks.push_back({t.name, air->entries.empty()
                                            ? core::TimeTable{}
                                            : t.augmented.spec.thermal.convection
                                                  .at(static_cast<size_t>(air->entries[0]))
                                                  .sink});
    res.effects.push_back(std::move(e));
  }
  for (const auto& f : sel.ranking)
    if (sel.claimed.empty() || f.candidate != sel.claimed.front().candidate)
      res.runners_up.push_back(reported(cat, f, false));
  for (const auto& a : sel.ambiguous) res.ambiguous.push_back(reported(cat, a));
  for (const auto& p : sel.pairs)
    res.pairs.push_back({reported(cat, p.first, false), reported(cat, p.second, false), p.score,
                         p.heldout_gain, p.fold_gains, p.adds_first, p.adds_second, p.admissible});
  for (const auto& f : sel.refit_rejected) res.refit_rejected.push_back(reported(cat, f, false));
}

/// A heat input or a sensor lag found on its grid: `train` with the place (the time constant)
/// refined on finer grids around the best ones, so that the choice can be made again with those
/// candidates and the noise rule and the ranking see them too; nothing when the claims have nothing
/// to refine. A heat input that is not the first claim is refined too (when the first has nothing
/// to refine); its places are scored with the other claims' fits removed, so that an offset sensor
/// or an air does not pull them.
std::optional<Catalogue> refined_catalogue(const MarchModel& model, const Catalogue& train,
                                           const Selection& selection,
                                           const CalibrationOptions& o) {
  std::optional<Catalogue> refined;
  const std::vector<EffectFit>& claimed = selection.claimed;
  const Candidate& first = train.candidates[claimed.front().candidate];
  const auto heat = std::find_if(claimed.begin(), claimed.end(), [&](const EffectFit& f) {
    return f.kind == EffectKind::heat_input;
  });
  const bool heat_first = kind(first) == EffectKind::heat_input;
  if (const auto* lag = std::get_if<SensorLag>(&first.effect); lag && o.lag_refine_steps > 1)
    refined = with_refined_lag(train, lag->sensor, lag->time_constant_s, o);
  else if (kind(first) == EffectKind::speed_dependent_convection && !o.speed_exponent_grid.empty())
    refined = with_speed_exponents(model, train, claimed.front().candidate, o);
  else if ((heat_first || heat != claimed.end()) && o.heat_refine_levels > 0) {
    std::vector<EffectFit> others;
    for (auto it = claimed.begin(); it != claimed.end(); ++it)
      if (it != heat) others.push_back(*it);
    refined = with_refined_heat_inputs(model, train, o, others);
  }
  return refined;
}

/// The test run `run` simulated with `aug` as its written file reads back (meshed again: heat
/// inputs add boundary groups), sensor corrections applied; `rt` is the run's readout on `model`.
Eigen::MatrixXd simulated_test_run(const MarchModel& model, const core::CaseSpec& declared,
                                   const Readout& rt, const io::MeasuredRun& run,
                                   const AugmentedCase& aug) {
  const mesh::TetMesh& mesh = model.mesh();
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
    return corrected(march(augmented, again, r2, run.time, {}, {}).base, run.time, r2, aug.sensors);
  }
  const Readout r2 = readout(m2, again, run);
  return corrected(march(MarchModel(m2, again), again, r2, run.time, {}, {}).base, run.time, r2,
                   aug.sensors);
}

/// What the calibration needs to simulate one test run with its claims.
struct TestContext {
  const MarchModel& model;
  const core::CaseSpec& declared;
  const Catalogue& cat;       ///< the training catalogue the claims index
  const Catalogue& test_cat;  ///< the test runs' ambient columns (when a claim is per run)
  const Selection& selection;
  const CalibrationOptions& o;
};

/// Test run `ti`'s case (`spec`, readout `rt`) with the claims declared: the shared claims first;
/// a per-run air is then fitted to what the model with them leaves of the test run (fitted against
/// the declared model alone, it would take the other claims' signal a second time), and declared
/// before them (a heat input's new group copies the covered group's sink).
AugmentedCase claimed_case(const TestContext& tc, const io::MeasuredRun& run, size_t ti,
                           const Readout& rt, const core::CaseSpec& spec) {
  const Catalogue& cat = tc.cat;
  const Readout& r = cat.readout;
  const Selection& sel = tc.selection;
  AugmentedCase aug{spec, {}, {}};
  std::vector<const EffectFit*> airs;
  for (const auto& f : sel.claimed) {
    const Candidate& c = cat.candidates[f.candidate];
    if (c.per_run)
      airs.push_back(&f);
    else
      aug = augmented_case(aug, c, f.parameters, r);
  }
  if (airs.empty()) return aug;
  RunModel left = tc.test_cat.runs[ti];
  if (airs.size() < sel.claimed.size())
    left.base = simulated_test_run(tc.model, tc.declared, rt, run, aug);
  AugmentedCase with_air{spec, {}, {}};
  for (const EffectFit* f : airs) {
    const Candidate& c = cat.candidates[f->candidate];
    const auto it = std::find_if(tc.test_cat.candidates.begin(), tc.test_cat.candidates.end(),
                                 [&](const Candidate& x) { return same_place(x, c); });
    const std::vector<double> p =
        fit_run_parameters(*it, static_cast<int>(ti), left, r, sel.sigma, tc.o);
    with_air = augmented_case(with_air, *it, p, r);
    // A second air is fitted to what the first leaves (its columns are the declared model's).
    const Eigen::VectorXd moved =
        it->columns[ti] *
        Eigen::Map<const Eigen::VectorXd>(p.data(), static_cast<Eigen::Index>(p.size()));
    left.base +=
        Eigen::Map<const Eigen::MatrixXd>(moved.data(), left.base.rows(), left.base.cols());
  }
  for (const auto& f : sel.claimed) {
    const Candidate& c = cat.candidates[f.candidate];
    if (!c.per_run) with_air = augmented_case(with_air, c, f.parameters, r);
  }
  return with_air;
}

/// Test run `ti` simulated before (the declared case) and after (with the claims).
TestRun test_run(const TestContext& tc, const io::MeasuredRun& run, size_t ti) {
  const Readout& r = tc.cat.readout;
  TestRun tr;
  tr.name = run.run;
  tr.times = run.time;
  const Readout rt = readout_like(tc.model.mesh(), tc.declared, run, r);
  if (rt.ids != r.ids)
    throw core::DataError("test run '" + run.run +
                          "' has other located channels than the training runs; " +
                          "every run must list the same sensors and probes");
  tr.measured = measured_channels(run, rt);
  const core::CaseSpec spec = case_for_run(tc.declared, run);
  tr.before = march(tc.model, spec, rt, run.time, {}, {}).base;
  const AugmentedCase aug = claimed_case(tc, run, ti, rt, spec);
  tr.after = tc.selection.claimed.empty() ? tr.before
                                          : simulated_test_run(tc.model, tc.declared, rt, run, aug);
  tr.augmented = aug;
  return tr;
}

}  // namespace

CalibrationResult calibrate(const MarchModel& model, const core::CaseSpec& declared,
                            const Catalogue& train, const std::vector<io::MeasuredRun>& test,
                            const CalibrationOptions& o) {
  CalibrationResult res;
  // Nonlinear candidates judged on their size, not on their linearisation's (refit_alone).
  auto resizer = [&](const Catalogue& c) -> Resizer {
    const Eigen::VectorXd sigma = noise_sigma(c.runs, c.readout.sensors, o);
    return [&model, &declared, &c, sigma, &o](const EffectFit& f) {
      return refit_alone(model, declared, c, f, sigma, o);
    };
  };
  res.selection = select_effects(train, o, resizer(train));
  // A heat input or a sensor lag found on its grid: the choice made again with the refined
  // candidates (refined_catalogue).
  std::optional<Catalogue> refined;
  if (!res.selection.claimed.empty()) {
    refined = refined_catalogue(model, train, res.selection, o);
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

  const TestContext tc{model, declared, cat, test_cat, res.selection, o};
  std::vector<Eigen::MatrixXd> meas, before, after;
  for (size_t ti = 0; ti < test.size(); ++ti) {
    TestRun tr = test_run(tc, test[ti], ti);
    meas.push_back(tr.measured);
    before.push_back(tr.before);
    after.push_back(tr.after);
    res.tests.push_back(std::move(tr));
  }
  res.before = rms_figures(meas, before, r.sensors);
  res.after = rms_figures(meas, after, r.sensors);

  describe(res, cat);
  return res;
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
