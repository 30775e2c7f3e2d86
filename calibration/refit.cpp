#include "calibration/refit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "calibration/calibrate.hpp"
#include "core/errors.hpp"

namespace tt::calibration {

namespace {

Eigen::VectorXd vec(const Eigen::MatrixXd& a) {
  return Eigen::Map<const Eigen::VectorXd>(a.data(), a.size());
}

/// The claims and where their shared parameter sits in the refitted vector (-1: held).
struct Claims {
  const Catalogue* cat = nullptr;
  std::vector<EffectFit> fits;
  std::vector<int> slot;
  const Candidate& candidate(size_t k) const {
    return cat->candidates.at(static_cast<size_t>(fits[k].candidate));
  }
  /// Whether every shared claim is physical at `theta` on the catalogue's runs.
  bool physical(const Eigen::VectorXd& theta, const CalibrationOptions& o) const {
    for (size_t k = 0; k < fits.size(); ++k)
      if (slot[k] >= 0 &&
          !unphysical_reason(candidate(k), {theta(slot[k])}, {}, cat->runs, o).empty())
        return false;
    return true;
  }
  /// The claimed per-run air, fitted on each run beside the shared claims; -1: none. (The choice
  /// claims at most one air: a pair holds one.)
  int air() const {
    for (size_t k = 0; k < fits.size(); ++k)
      if (candidate(k).per_run) return static_cast<int>(k);
    return -1;
  }
  bool changes_operators() const {
    for (size_t k = 0; k < fits.size(); ++k)
      if (kind(candidate(k)) == EffectKind::material_parameter && !changes_expansion(candidate(k)))
        return true;
    return false;
  }
};

/// `base` with every claim but the heat inputs declared at `theta` (the per-run ones at their
/// run-`ri` values): what augmented_case writes, so that the refitted model is the written one.
/// Heat inputs stay out: they need new boundary groups, and the march carries them as columns.
AugmentedCase updated_case(const core::CaseSpec& base, const Claims& cl,
                           const Eigen::VectorXd& theta, size_t ri) {
  AugmentedCase aug{base, {}, {}};
  for (size_t k = 0; k < cl.fits.size(); ++k) {
    const Candidate& c = cl.candidate(k);
    if (kind(c) == EffectKind::heat_input) continue;
    std::vector<double> p = cl.fits[k].parameters;
    if (c.per_run) p = cl.fits[k].run_parameters.at(ri);
    if (cl.slot[k] >= 0) p = {theta(cl.slot[k])};
    aug = augmented_case(aug, c, p, cl.cat->readout);
  }
  return aug;
}

/// The updated model on run `ri`: its whitened residual and the Jacobian of its channels in the
/// shared parameters (whitened rows).
struct Step {
  Eigen::VectorXd y;
  Eigen::MatrixXd jacobian;
  Eigen::MatrixXd prediction;  /// #samples x #channels [K | m]
};

Step linearised_on_run(const MarchModel& model_u, const core::CaseSpec& declared, const Claims& cl,
                       const Eigen::VectorXd& theta, size_t ri, const Eigen::VectorXd& sigma) {
  const RunModel& rm = cl.cat->runs[ri];
  const Readout& r = cl.cat->readout;
  const AugmentedCase aug = updated_case(rm.spec, cl, theta, ri);
  Readout ru = r;
  if (r.displacement.rows()) ru.displacement = displacement_with_expansions(r, declared, aug.spec);
  // Columns: per shared claim, its unit loads (weighted), or its expansion readout.
  std::vector<SeparableColumn> sep;
  std::vector<LoadColumn> loads;
  std::vector<Eigen::MatrixXd> extra;
  struct Where {
    std::vector<int> sep, load;
    std::vector<double> sep_w, load_w;
    int extra = -1;
  };
  std::vector<Where> where(cl.fits.size());
  for (size_t k = 0; k < cl.fits.size(); ++k) {
    if (cl.slot[k] < 0) continue;
    const Candidate& c = cl.candidate(k);
    const size_t ns = c.unit_separable.size();
    for (size_t j = 0; j < ns; ++j) {
      where[k].sep.push_back(static_cast<int>(sep.size()));
      where[k].sep_w.push_back(c.unit_weights.at(j));
      sep.push_back(c.unit_separable[j]);
    }
    for (size_t j = 0; j < c.unit_loads.size(); ++j) {
      where[k].load.push_back(static_cast<int>(loads.size()));
      where[k].load_w.push_back(c.unit_weights.at(ns + j));
      loads.push_back(c.unit_loads[j]);
    }
    if (changes_expansion(c)) {
      where[k].extra = static_cast<int>(extra.size());
      extra.push_back(
          r.expansion.at(static_cast<size_t>(std::get<MaterialParameter>(c.effect).material)));
    }
  }
  const Responses rs = march(model_u, aug.spec, ru, rm.times, sep, loads, extra);
  const Eigen::Index ns = rm.times.size(), nc = r.channels();
  // The heat inputs' share of the prediction, then the sensors' own corrections.
  Eigen::MatrixXd prediction = rs.base;
  for (size_t k = 0; k < cl.fits.size(); ++k)
    if (kind(cl.candidate(k)) == EffectKind::heat_input)
      for (size_t j = 0; j < where[k].sep.size(); ++j)
        prediction += theta(cl.slot[k]) * where[k].sep_w[j] *
                      rs.columns[static_cast<size_t>(where[k].sep[j])];
  prediction = corrected(prediction, rm.times, r, aug.sensors);
  std::vector<SensorCorrection> lags = aug.sensors;  // a lagged channel's tangent is lagged too
  for (auto& s : lags) s.offset_K = 0;
  Eigen::MatrixXd jac = Eigen::MatrixXd::Zero(ns * nc, theta.size());
  for (size_t k = 0; k < cl.fits.size(); ++k) {
    if (cl.slot[k] < 0) continue;
    const Candidate& c = cl.candidate(k);
    Eigen::MatrixXd col = Eigen::MatrixXd::Zero(ns, nc);
    for (size_t j = 0; j < where[k].sep.size(); ++j)
      col += where[k].sep_w[j] * rs.columns[static_cast<size_t>(where[k].sep[j])];
    for (size_t j = 0; j < where[k].load.size(); ++j)
      col += where[k].load_w[j] * rs.columns[sep.size() + static_cast<size_t>(where[k].load[j])];
    if (where[k].extra >= 0) col = rs.extra[static_cast<size_t>(where[k].extra)];
    if (kind(c) == EffectKind::sensor_offset) col.col(sensor_of(c)).setOnes();
    jac.col(cl.slot[k]) = vec(corrected(col, rm.times, r, lags));
  }
  RunModel now = rm;
  now.base = prediction;
  const Whitened w = whitened(now, sigma);
  return {w.y, whitened_rows(jac, w, sigma), prediction};
}

/// A step on run `ri` with the claimed air's least squares eliminated (the air follows the shared
/// parameters instead of being held: held, an air fitted beside a linearised law keeps that law's
/// share when the law is resized), and what gives the air at a step from there.
struct AirFree {
  AirEliminated e;            /// residual and Jacobian, the air eliminated
  Eigen::VectorXd y_without;  /// residual with the air taken out (whitened rows)
  Eigen::MatrixXd jacobian;   /// Jacobian as the step gave it
};
AirFree air_free(const Claims& cl, const Step& s, size_t ri, const Eigen::VectorXd& sigma,
                 const CalibrationOptions& o) {
  const int k = cl.air();
  if (k < 0) return {{s.jacobian, s.y, {}, {}}, s.y, s.jacobian};
  const Candidate& air = cl.candidate(static_cast<size_t>(k));
  const RunModel& rm = cl.cat->runs[ri];
  const Whitened w = whitened(rm, sigma);  // the same rows as the step's: the finite readings
  const std::vector<double>& held = cl.fits[static_cast<size_t>(k)].run_parameters.at(ri);
  const Eigen::VectorXd y = s.y + whitened_rows(air.columns.at(ri), w, sigma) *
                                      Eigen::Map<const Eigen::VectorXd>(
                                          held.data(), static_cast<Eigen::Index>(held.size()));
  return {air_eliminated(&air, rm, cl.cat->readout, w, y, s.jacobian, ri, sigma, o), y, s.jacobian};
}

/// The claimed air on every run at `step` from the point `at` was taken at (within its bounds).
void move_air(Claims& cl, const std::vector<AirFree>& at, const Eigen::VectorXd& step,
              const CalibrationOptions& o) {
  const int k = cl.air();
  if (k < 0) return;
  const Candidate& air = cl.candidate(static_cast<size_t>(k));
  for (size_t ri = 0; ri < at.size(); ++ri) {
    const Eigen::VectorXd a =
        air_at(air, cl.cat->runs[ri], at[ri].e, at[ri].y_without, at[ri].jacobian, step, o);
    cl.fits[static_cast<size_t>(k)].run_parameters.at(ri).assign(a.data(), a.data() + a.size());
  }
}

/// The updated model at `theta` (its operators assembled again when a claim changes them).
std::optional<MarchModel> updated_operators(const MarchModel& model, const core::CaseSpec& declared,
                                            const Claims& cl, const Eigen::VectorXd& theta) {
  if (!cl.changes_operators()) return std::nullopt;
  return model.with_case(model.mesh(), updated_case(declared, cl, theta, 0).spec);
}

Eigen::VectorXd shared_theta(const Claims& cl) {
  Eigen::VectorXd theta(static_cast<Eigen::Index>(
      std::count_if(cl.slot.begin(), cl.slot.end(), [](int s) { return s >= 0; })));
  for (size_t k = 0; k < cl.fits.size(); ++k)
    if (cl.slot[k] >= 0) theta(cl.slot[k]) = cl.fits[k].parameters.at(0);
  return theta;
}

/// Gauss–Newton on the claims' shared parameters from their linearised values.
void gauss_newton(const MarchModel& model, const core::CaseSpec& declared, Claims& cl,
                  const Eigen::VectorXd& sigma, const CalibrationOptions& o) {
  Eigen::VectorXd theta = shared_theta(cl);
  const Eigen::Index p = theta.size();
  double ss_first = 0, ss_last = std::numeric_limits<double>::infinity();
  Eigen::VectorXd last_theta = theta, step = Eigen::VectorXd::Zero(p);
  std::vector<AirFree> last_pieces;  /// the air's pieces at last_theta
  int iterations = 0;
  bool converged = false;
  Eigen::VectorXd beyond;  /// the step that left the bounds, when one did
  for (int it = 0; it < o.refit_max_iterations; ++it) {
    // The operators of the updated model: the declared case's with the claims' materials.
    const std::optional<MarchModel> own = updated_operators(model, declared, cl, theta);
    const MarchModel& model_u = own ? *own : model;
    Eigen::MatrixXd g = Eigen::MatrixXd::Zero(p, p);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(p);
    double ss = 0;
    std::vector<AirFree> pieces;
    for (size_t ri = 0; ri < cl.cat->runs.size(); ++ri) {
      pieces.push_back(
          air_free(cl, linearised_on_run(model_u, declared, cl, theta, ri, sigma), ri, sigma, o));
      const AirEliminated& e = pieces.back().e;
      g += e.m.transpose() * e.m;
      b += e.m.transpose() * e.y;
      ss += e.y.squaredNorm();
    }
    if (it == 0) ss_first = ss;
    if (ss > ss_last && it > 0) {
      // The last step overshot: take half of it from where it started.
      step /= 2;
      theta = last_theta + step;
      move_air(cl, last_pieces, step, o);
      ++iterations;
      continue;
    }
    ss_last = ss;
    last_theta = theta;
    last_pieces = std::move(pieces);
    step = solve_ridge(g, b, 1e-12);
    // Standard errors of the parameters (whitened residuals: unit noise).
    const Eigen::VectorXd se =
        g.ldlt().solve(Eigen::MatrixXd::Identity(p, p)).diagonal().cwiseAbs().cwiseSqrt();
    converged = true;
    for (Eigen::Index k = 0; k < p; ++k)
      converged &= std::abs(step(k)) <= std::max(o.refit_tolerance_sigmas * se(k),
                                                 o.refit_tolerance_rel * std::abs(theta(k)));
    // The step stays within the physical bounds (a film clamped at 5 % of its h stops
    // responding, and Gauss–Newton would walk on): halved until it does; a fit that still
    // leaves them runs into its bound, and its size is not found.
    for (int cut = 0; cut < 8 && !cl.physical(theta + step, o); ++cut) step /= 2;
    if (!cl.physical(theta + step, o)) {
      beyond = theta + step;
      converged = false;
      break;
    }
    theta += step;
    move_air(cl, last_pieces, step, o);
    ++iterations;
    if (converged) break;
  }
  for (size_t k = 0; k < cl.fits.size(); ++k) {
    EffectFit& f = cl.fits[k];
    f.refit_iterations = iterations;
    f.refit_converged = converged;
    f.refit_ss_linearised = ss_first;
    f.refit_ss = ss_last;
    if (cl.slot[k] < 0) continue;
    if (beyond.size() &&
        !unphysical_reason(cl.candidate(k), {beyond(cl.slot[k])}, {}, cl.cat->runs, o).empty())
      f.unphysical = "refitted about the updated model, its size runs into the physical bounds";
    if (f.linearised.empty()) f.linearised = f.parameters;
    f.parameters = {theta(cl.slot[k])};
  }
}

/// The claims' shared parameters fitted linearly (the catalogue's columns about the declared
/// model, as the choice fits them) on the training runs but `out`, the others held as fitted.
Eigen::VectorXd linearised_without(const Claims& cl, size_t out, const Eigen::VectorXd& sigma,
                                   const CalibrationOptions& o) {
  const Eigen::Index p = shared_theta(cl).size();
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(p, p);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(p);
  for (size_t ri = 0; ri < cl.cat->runs.size(); ++ri) {
    if (ri == out) continue;
    const Whitened w = whitened(cl.cat->runs[ri], sigma);
    Eigen::VectorXd y = w.y;
    Eigen::MatrixXd a(y.size(), p);
    for (size_t k = 0; k < cl.fits.size(); ++k) {
      const Candidate& c = cl.candidate(k);
      const Eigen::MatrixXd col = whitened_rows(c.columns.at(ri), w, sigma);
      if (cl.slot[k] >= 0) {
        a.col(cl.slot[k]) = col.col(0);
      } else {
        const std::vector<double>& q =
            c.per_run ? cl.fits[k].run_parameters.at(ri)
                      : (c.fixed ? std::vector<double>{1.0} : cl.fits[k].parameters);
        y -= col * Eigen::Map<const Eigen::VectorXd>(q.data(), static_cast<Eigen::Index>(q.size()));
      }
    }
    g += a.transpose() * a;
    b += a.transpose() * y;
  }
  return solve_ridge(g, b, o.ridge);
}

/// `cl` on the training runs but `out` (per-run parameters with them).
struct Fold {
  Catalogue cat;
  Claims claims;
};
Fold without_run(const Claims& cl, size_t out) {
  Fold f;
  f.cat.readout = cl.cat->readout;
  f.cat.candidates = cl.cat->candidates;
  for (size_t ri = 0; ri < cl.cat->runs.size(); ++ri)
    if (ri != out) f.cat.runs.push_back(cl.cat->runs[ri]);
  f.claims = cl;
  for (auto& fit : f.claims.fits)
    if (!fit.run_parameters.empty()) fit.run_parameters.erase(fit.run_parameters.begin() + out);
  return f;
}

/// The held-out check of the refit (docs/calibration.md, "Refit"): per training run, the claims
/// fitted on the other runs, linearised and refitted, each judged by the updated model's whitened
/// sum of squares on the run left out; summed over the runs. `start`: the claims as chosen.
struct HeldOutCheck {
  double linearised = 0, refitted = 0;
};
HeldOutCheck heldout_check(const MarchModel& model, const core::CaseSpec& declared,
                           const Claims& start, const Eigen::VectorXd& sigma,
                           const CalibrationOptions& o) {
  HeldOutCheck out;
  const Eigen::VectorXd chosen = shared_theta(start);
  // A claim the choice sized about its update (its linearised fit was unphysical) has no
  // physical linearised fit on fewer runs: there both folds start from its chosen size.
  bool resized = false;
  for (const auto& f : start.fits) resized |= !f.linearised.empty();
  auto ss_on = [&](const Claims& cl, const Eigen::VectorXd& theta, size_t ri) {
    const std::optional<MarchModel> own = updated_operators(model, declared, cl, theta);
    return air_free(cl, linearised_on_run(own ? *own : model, declared, cl, theta, ri, sigma), ri,
                    sigma, o)
        .e.y.squaredNorm();
  };
  for (size_t ri = 0; ri < start.cat->runs.size(); ++ri) {
    Eigen::VectorXd lin = resized ? chosen : linearised_without(start, ri, sigma, o);
    if (!start.physical(lin, o)) lin = chosen;
    Fold fold = without_run(start, ri);
    fold.claims.cat = &fold.cat;
    for (size_t k = 0; k < fold.claims.fits.size(); ++k)
      if (fold.claims.slot[k] >= 0) fold.claims.fits[k].parameters = {lin(fold.claims.slot[k])};
    gauss_newton(model, declared, fold.claims, sigma, o);
    out.linearised += ss_on(start, lin, ri);
    out.refitted += ss_on(start, shared_theta(fold.claims), ri);
  }
  return out;
}

bool wants_refit(const Claims& cl) {
  int shared = 0;
  bool nonlinear = false;
  for (size_t k = 0; k < cl.fits.size(); ++k) {
    shared += cl.slot[k] >= 0;
    nonlinear |= nonlinear_in_parameter(cl.candidate(k));
  }
  return shared > 0 && (nonlinear || cl.fits.size() > 1);
}

}  // namespace

Resized refit_alone(const MarchModel& model, const core::CaseSpec& declared, const Catalogue& cat,
                    const EffectFit& fit, const Eigen::VectorXd& sigma,
                    const CalibrationOptions& o) {
  Claims cl;
  cl.cat = &cat;
  cl.fits = {fit};
  cl.slot = {0};
  EffectFit& f = cl.fits[0];
  const Candidate& c = cat.candidates.at(static_cast<size_t>(f.candidate));
  for (int k = 0; k < 6 && !unphysical_reason(c, f.parameters, {}, cat.runs, o).empty(); ++k)
    f.parameters[0] /= 2;
  gauss_newton(model, declared, cl, sigma, o);
  Resized out;
  out.parameters = f.parameters;
  if (!f.unphysical.empty()) return out;  // no physical size: it stays as linearised
  const double size = f.parameters.at(0);
  if (size == 0 || !std::isfinite(size)) return out;
  // The secant response at the size: the updated model's channels minus the declared model's.
  const Eigen::VectorXd theta = Eigen::VectorXd::Constant(1, size);
  const std::optional<MarchModel> own = updated_operators(model, declared, cl, theta);
  for (size_t ri = 0; ri < cat.runs.size(); ++ri) {
    const Step s = linearised_on_run(own ? *own : model, declared, cl, theta, ri, sigma);
    out.columns.push_back(vec(s.prediction - cat.runs[ri].base) / size);
  }
  return out;
}

Selection refit_claimed(const MarchModel& model, const core::CaseSpec& declared,
                        const Catalogue& cat, Selection sel, const CalibrationOptions& o) {
  while (!sel.claimed.empty()) {
    Claims cl;
    cl.cat = &cat;
    cl.fits = sel.claimed;
    int next = 0;
    for (const auto& f : cl.fits) {
      const Candidate& c = cat.candidates.at(static_cast<size_t>(f.candidate));
      const bool shared = !c.per_run && !c.fixed && f.parameters.size() == 1 &&
                          (!c.unit_separable.empty() || !c.unit_loads.empty() ||
                           kind(c) == EffectKind::sensor_offset || changes_expansion(c));
      cl.slot.push_back(shared ? next++ : -1);
    }
    if (!wants_refit(cl) || o.refit_max_iterations <= 0) return sel;
    const Claims start = cl;
    gauss_newton(model, declared, cl, sel.sigma, o);
    // Kept only where it predicts the runs it was not fitted on better than the claims as chosen:
    // sizing a law that is not the truth's to its in-sample optimum can cost on other runs.
    bool checked = false;
    HeldOutCheck check;
    if (cat.runs.size() >= 2 && std::all_of(cl.fits.begin(), cl.fits.end(),
                                            [](const auto& f) { return f.unphysical.empty(); })) {
      check = heldout_check(model, declared, start, sel.sigma, o);
      checked = true;
    }
    for (size_t k = 0; k < cl.fits.size(); ++k) {
      EffectFit& f = cl.fits[k];
      f.refit_heldout_checked = checked;
      f.refit_heldout_ss_linearised = check.linearised;
      f.refit_heldout_ss_refitted = check.refitted;
      f.refit_accepted = !checked || check.refitted < check.linearised;
      f.refitted = f.parameters;
      if (!f.refit_accepted) {
        f.parameters = start.fits[k].parameters;
        f.run_parameters = start.fits[k].run_parameters;
      }
    }
    // A size that is unphysical once found is not claimed; the others are sized without it.
    std::vector<EffectFit> kept;
    for (auto& f : cl.fits) {
      const Candidate& c = cat.candidates.at(static_cast<size_t>(f.candidate));
      if (f.unphysical.empty())
        f.unphysical = unphysical_reason(c, f.parameters, f.run_parameters, cat.runs, o);
      if (f.unphysical.empty())
        kept.push_back(f);
      else
        sel.refit_rejected.push_back(f);
    }
    sel.claimed = kept;
    if (kept.size() == cl.fits.size()) return sel;
    for (auto& f : sel.claimed)
      if (!f.linearised.empty()) f.parameters = f.linearised;
  }
  return sel;
}

}  // namespace tt::calibration
