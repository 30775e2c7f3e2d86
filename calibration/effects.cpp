#include "calibration/effects.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <set>

#include "core/errors.hpp"
#include "core/rng.hpp"
#include "core/units.hpp"
#include "mesh/mesher.hpp"
#include "solvers/loads.hpp"
#include "solvers/thermal.hpp"

namespace tt::calibration {

Whitened whitened(const RunModel& run, const Eigen::VectorXd& sigma) {
  Whitened w;
  const Eigen::Index ns = run.times.size();
  std::vector<double> v;
  for (Eigen::Index c = 0; c < run.measured.cols(); ++c)
    for (Eigen::Index i = 0; i < ns; ++i) {
      const double m = run.measured(i, c);
      if (!std::isfinite(m)) continue;
      v.push_back((m - run.base(i, c)) / sigma(c));
      w.rows.push_back(c * ns + i);
      w.channel.push_back(static_cast<int>(c));
    }
  w.y = Eigen::Map<Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
  return w;
}

Eigen::MatrixXd whitened_rows(const Eigen::MatrixXd& a, const Whitened& w,
                              const Eigen::VectorXd& sigma) {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(w.rows.size()), a.cols());
  for (size_t k = 0; k < w.rows.size(); ++k)
    out.row(static_cast<Eigen::Index>(k)) = a.row(w.rows[k]) / sigma(w.channel[k]);
  return out;
}

Eigen::VectorXd solve_ridge(const Eigen::MatrixXd& g, const Eigen::VectorXd& b, double ridge) {
  const Eigen::Index p = g.rows();
  const double scale = std::max(g.diagonal().mean(), 1e-300);
  Eigen::MatrixXd a = g + (ridge * scale) * Eigen::MatrixXd::Identity(p, p);
  return a.ldlt().solve(b);
}

bool nonlinear_in_parameter(const Candidate& c) {
  switch (kind(c)) {
    case EffectKind::speed_dependent_convection:
    case EffectKind::boundary_conductance:
    case EffectKind::temperature_dependent_heat:
      return true;
    case EffectKind::material_parameter:
      return !changes_expansion(c);  // the readout's change is exact in it
    default:
      return false;
  }
}

bool changes_expansion(const Candidate& c) {
  const auto* m = std::get_if<MaterialParameter>(&c.effect);
  return m && m->field == MaterialField::expansion;
}

int sensor_of(const Candidate& c) {
  if (const auto* o = std::get_if<SensorOffset>(&c.effect)) return o->sensor;
  if (const auto* l = std::get_if<SensorLag>(&c.effect)) return l->sensor;
  return -1;
}

namespace {

/// Whether two alternatives of one kind act at one place.
bool same_place_as(const AmbientTemperature& a, const AmbientTemperature& b) {
  return a.entries == b.entries;
}
bool same_place_as(const HeatInput& a, const HeatInput& b) {
  return a.centre == b.centre && a.box_min == b.box_min && a.box_max == b.box_max &&
         a.area == b.area && a.groups == b.groups && a.body == b.body;
}
bool same_place_as(const SpeedDependentConvection& a, const SpeedDependentConvection& b) {
  return a.entries == b.entries;
}
bool same_place_as(const TemperatureDependentHeat& a, const TemperatureDependentHeat& b) {
  return a.sources == b.sources;
}
bool same_place_as(const BoundaryConductance& a, const BoundaryConductance& b) {
  return a.entries == b.entries;
}
bool same_place_as(const MaterialParameter& a, const MaterialParameter& b) {
  return a.material == b.material && a.field == b.field;
}
bool same_place_as(const SensorOffset& a, const SensorOffset& b) {
  return a.sensor == b.sensor;
}
bool same_place_as(const SensorLag& a, const SensorLag& b) {
  return a.sensor == b.sensor;
}

}  // namespace

bool same_place(const Candidate& a, const Candidate& b) {
  return std::visit(
      [](const auto& x, const auto& y) {
        if constexpr (std::is_same_v<std::decay_t<decltype(x)>, std::decay_t<decltype(y)>>)
          return same_place_as(x, y);
        else
          return false;
      },
      a.effect, b.effect);
}

namespace {

/// Normal-equation pieces of one candidate on one run.
struct Normal {
  Eigen::MatrixXd g;  /// A^T A
  Eigen::VectorXd b;  /// A^T y
  double s = 0;       /// y^T y
};

double gain_of(const Normal& n, const Eigen::VectorXd& theta) {
  return 2 * theta.dot(n.b) - theta.dot(n.g * theta);
}

/// Channels a candidate moves (response norm above 1e-3 of its largest channel).
std::vector<char> touched(const Candidate& c, Eigen::Index samples_first_run,
                          Eigen::Index channels) {
  std::vector<char> t(static_cast<size_t>(channels), 0);
  const Eigen::MatrixXd& a = c.columns.front();
  Eigen::VectorXd norm(channels);
  for (Eigen::Index ch = 0; ch < channels; ++ch)
    norm(ch) = a.middleRows(ch * samples_first_run, samples_first_run).norm();
  const double mx = norm.maxCoeff();
  for (Eigen::Index ch = 0; ch < channels; ++ch)
    t[static_cast<size_t>(ch)] = mx > 0 && norm(ch) > 1e-3 * mx;
  return t;
}

double hat(double t, double tk, double dk) {
  return std::max(0.0, 1 - std::abs(t - tk) / dk);
}

double knot_spacing(const std::vector<double>& knots) {
  return knots.size() > 1 ? knots[1] - knots[0] : 1e300;
}

/// The air change at `c`'s knots that the run's ambient sensor reads: least squares of the hats
/// to the reading minus the sink of the candidate's first entry [K].
Eigen::VectorXd air_from_sensor(const AmbientTemperature& c, const RunModel& run) {
  const Eigen::Index p = static_cast<Eigen::Index>(c.knots.size());
  const double dk = knot_spacing(c.knots);
  const auto& sink = run.spec.thermal.convection.at(static_cast<size_t>(c.entries.at(0))).sink;
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(p, p);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(p);
  for (Eigen::Index i = 0; i < run.times.size(); ++i) {
    if (!std::isfinite(run.air(i))) continue;
    Eigen::VectorXd h(p);
    for (Eigen::Index k = 0; k < p; ++k) h(k) = hat(run.times(i), c.knots[k], dk);
    g += h * h.transpose();
    b += h * (run.air(i) - core::kCelsiusOffset - solvers::table_value(sink, run.times(i)));
  }
  // Knots the run does not reach keep no change.
  return solve_ridge(g, b, 1e-9);
}

/// A per-run air on one run: from its ambient sensor when it has one, else the bounded fit to the
/// normal equations (g, b).
Eigen::VectorXd per_run_theta(const Candidate& c, const RunModel& run, const Eigen::MatrixXd& g,
                              const Eigen::VectorXd& b, const CalibrationOptions& o) {
  const auto& air = std::get<AmbientTemperature>(c.effect);
  if (run.air.size() > 0) return air_from_sensor(air, run);
  return bounded_air(g, b, air.knots, o);
}

/// Parameters of `c` fitted on run `ri` as `f` holds them (in-sample).
Eigen::VectorXd fitted_theta(const Candidate& c, const EffectFit& f, size_t ri) {
  if (c.fixed) return Eigen::VectorXd::Ones(1);
  const std::vector<double>& p = c.per_run ? f.run_parameters.at(ri) : f.parameters;
  return Eigen::Map<const Eigen::VectorXd>(p.data(), static_cast<Eigen::Index>(p.size()));
}

/// The kept rows of `w` that a per-run air is fitted on: the temperatures, when the run has them
/// (the displacements stay a check).
std::vector<Eigen::Index> temperature_rows(const Whitened& w, const Readout& r) {
  std::vector<Eigen::Index> keep;
  for (size_t k = 0; k < w.rows.size(); ++k)
    if (r.sensors == 0 || w.channel[k] < r.sensors) keep.push_back(static_cast<Eigen::Index>(k));
  return keep;
}

/// Rows `keep` of `a`.
Eigen::MatrixXd rows_of(const Eigen::MatrixXd& a, const std::vector<Eigen::Index>& keep) {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(keep.size()), a.cols());
  for (size_t k = 0; k < keep.size(); ++k) out.row(static_cast<Eigen::Index>(k)) = a.row(keep[k]);
  return out;
}

/// Speeds the runs' duty cycles use [rpm].
std::set<double> speeds_used(const std::vector<RunModel>& runs) {
  std::set<double> out;
  for (const auto& rm : runs)
    for (const auto& seg : rm.spec.duty_cycle.segments) out.insert(seg.speed_rpm);
  return out;
}

/// Correlation of a per-run air with the run's speed, each averaged over the knots' hats and
/// centred per run, pooled over the runs.
double duty_correlation(const AmbientTemperature& c, const std::vector<std::vector<double>>& air,
                        const std::vector<RunModel>& runs) {
  const double dk = knot_spacing(c.knots);
  double sxy = 0, sxx = 0, syy = 0;
  for (size_t ri = 0; ri < runs.size() && ri < air.size(); ++ri) {
    const RunModel& rm = runs[ri];
    std::vector<double> x, y;
    for (size_t k = 0; k < c.knots.size(); ++k) {
      double w = 0, ws = 0;
      for (Eigen::Index i = 0; i < rm.times.size(); ++i) {
        const double h = hat(rm.times(i), c.knots[k], dk);
        w += h;
        ws += h * solvers::speed_at(rm.spec.duty_cycle, rm.times(i));
      }
      if (w <= 0) continue;  // a knot past the run's end
      x.push_back(air[ri].at(k));
      y.push_back(ws / w);
    }
    if (x.size() < 2) continue;
    double mx = 0, my = 0;
    for (size_t k = 0; k < x.size(); ++k) {
      mx += x[k] / static_cast<double>(x.size());
      my += y[k] / static_cast<double>(y.size());
    }
    for (size_t k = 0; k < x.size(); ++k) {
      sxy += (x[k] - mx) * (y[k] - my);
      sxx += (x[k] - mx) * (x[k] - mx);
      syy += (y[k] - my) * (y[k] - my);
    }
  }
  return sxx > 0 && syy > 0 ? sxy / std::sqrt(sxx * syy) : 0.0;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

}  // namespace

Eigen::VectorXd bounded_air(const Eigen::MatrixXd& g0, const Eigen::VectorXd& b,
                            const std::vector<double>& knots, const CalibrationOptions& o) {
  const Eigen::Index p = g0.rows();
  const double scale = std::max(g0.diagonal().mean(), 1e-300);
  const Eigen::MatrixXd g =
      g0 + (std::max(o.ridge, 1e-6) * scale) * Eigen::MatrixXd::Identity(p, p);
  // Bounds on M x: the change at each knot, then its change between neighbouring knots.
  const Eigen::Index m = p + std::max<Eigen::Index>(p - 1, 0);
  Eigen::MatrixXd mat = Eigen::MatrixXd::Zero(m, p);
  Eigen::VectorXd hi(m);
  for (Eigen::Index k = 0; k < p; ++k) {
    mat(k, k) = 1;
    hi(k) = o.air_range_K;
  }
  for (Eigen::Index k = 0; k + 1 < p; ++k) {
    mat(p + k, k) = -1;
    mat(p + k, k + 1) = 1;
    hi(p + k) = o.air_rate_K_per_h * (knots.at(k + 1) - knots.at(k)) / 3600;
  }
  auto clip = [&](const Eigen::VectorXd& v) { return v.cwiseMax(-hi).cwiseMin(hi).eval(); };
  Eigen::VectorXd x = g.ldlt().solve(b);
  if (((mat * x).cwiseAbs().array() <= hi.array()).all()) return x;
  // ADMM on min x'gx/2 - b'x subject to Mx = z, |z| <= hi.
  const double rho = scale;
  const Eigen::LDLT<Eigen::MatrixXd> step(g + rho * mat.transpose() * mat);
  Eigen::VectorXd z = clip(mat * x), u = Eigen::VectorXd::Zero(m);
  const double tol = 1e-7 * std::max(1.0, b.cwiseAbs().maxCoeff());
  for (int it = 0; it < 20000; ++it) {
    x = step.solve(b + rho * mat.transpose() * (z - u));
    const Eigen::VectorXd mx = mat * x, z0 = z;
    z = clip(mx + u);
    u += mx - z;
    if ((mx - z).cwiseAbs().maxCoeff() < 1e-7 &&
        rho * (mat.transpose() * (z - z0)).cwiseAbs().maxCoeff() < tol)
      break;
  }
  return z.head(p);
}

std::string unphysical_reason(const Candidate& c, const std::vector<double>& p,
                              const std::vector<std::vector<double>>& run_parameters,
                              const std::vector<RunModel>& runs, const CalibrationOptions& o,
                              double* correlation) {
  if (runs.empty()) return {};
  const core::CaseSpec& spec = runs.front().spec;
  // A film's change on `entries` (weights per entry): the coefficient stays positive at every
  // speed the runs use, and a gain growing with speed stays >= 0.
  auto film_reason = [&](const std::vector<int>& entries, const std::vector<double>& weights,
                         const SpeedDependentConvection* speed_law) -> std::string {
    for (size_t k = 0; k < entries.size(); ++k) {
      const core::Convection& cv = spec.thermal.convection.at(static_cast<size_t>(entries[k]));
      const double change = p.at(0) * weights.at(k);
      const std::string where =
          entries.size() > 1 ? " on " + spec.groups.at(static_cast<size_t>(cv.group)).name : "";
      if (speed_law && cv.h_speed_gain + change < 0)
        return "a film falling with speed" + where + " (gain " + number(cv.h_speed_gain + change) +
               " W/m2K at " + number(speed_law->ref_speed_rpm) + " rpm): the gain must be >= 0";
      for (double n : speeds_used(runs)) {
        const double h = solvers::film_coefficient(cv, n) +
                         change * (speed_law ? (n > 0 ? std::pow(n / speed_law->ref_speed_rpm,
                                                                 speed_law->speed_exponent)
                                                      : 0.0)
                                             : 1.0);
        if (h <= 0)
          return "film coefficient after the change" + where + " " + number(h) + " W/m2K at " +
                 number(n) + " rpm: must be > 0";
      }
    }
    return {};
  };
  switch (kind(c)) {
    case EffectKind::ambient_temperature: {
      bool fitted = false;  // the air of a run with an ambient sensor is read, not fitted
      for (size_t ri = 0; ri < runs.size(); ++ri) fitted |= runs[ri].air.size() == 0;
      const double r =
          fitted ? duty_correlation(std::get<AmbientTemperature>(c.effect), run_parameters, runs)
                 : 0.0;
      if (correlation) *correlation = r;
      if (std::abs(r) >= o.air_duty_correlation)
        return "the fitted air follows the duty cycle (correlation " + number(r) +
               " with the speed): a sign of a speed-dependent mechanism, not of the shop's air";
      return {};
    }
    case EffectKind::heat_input:
      if (p.at(0) < 0)
        return "a heat input of " + number(p.at(0) * std::get<HeatInput>(c.effect).area) +
               " W: heat cannot be negative";
      return {};
    case EffectKind::speed_dependent_convection: {
      const auto& e = std::get<SpeedDependentConvection>(c.effect);
      return film_reason(e.entries, e.weights, &e);
    }
    case EffectKind::boundary_conductance: {
      const auto& e = std::get<BoundaryConductance>(c.effect);
      return film_reason(e.entries, e.weights, nullptr);
    }
    case EffectKind::temperature_dependent_heat: {
      const auto& e = std::get<TemperatureDependentHeat>(c.effect);
      for (size_t k = 0; k < e.sources.size(); ++k) {
        const auto& src = spec.thermal.sources.at(static_cast<size_t>(e.sources[k]));
        const double a = src.temperature_coefficient + p.at(0) * e.weights.at(k);
        if (a < o.temperature_coefficient_min_per_K || a > o.temperature_coefficient_max_per_K)
          return "temperature coefficient after the change" +
                 (e.sources.size() > 1 ? " of " + src.name : std::string()) + " " + number(a) +
                 " 1/K: outside " + number(o.temperature_coefficient_min_per_K) + " .. " +
                 number(o.temperature_coefficient_max_per_K) + " 1/K";
      }
      return {};
    }
    case EffectKind::material_parameter:
      if (p.at(0) < o.material_change_min || p.at(0) > o.material_change_max)
        return field_name(std::get<MaterialParameter>(c.effect).field) + " changed by " +
               number(100 * p.at(0)) + " %: outside " + number(100 * o.material_change_min) +
               " .. " + number(100 * o.material_change_max) + " %";
      return {};
    case EffectKind::sensor_offset:
    case EffectKind::sensor_lag:
      return {};
  }
  return {};
}

std::string kind_name(EffectKind kind) {
  return std::string(core::name_in(kEffectKindNames, kind));
}

std::string law_name(HeatLaw law) {
  return std::string(core::name_in(kHeatLawNames, law));
}

std::string field_name(MaterialField field) {
  return std::string(core::name_in(kMaterialFieldNames, field));
}

double& material_value(core::Material& m, MaterialField field) {
  switch (field) {
    case MaterialField::conductivity:
      return m.conductivity;
    case MaterialField::heat_capacity:
      return m.specific_heat;
    case MaterialField::expansion:
      break;
  }
  return m.expansion;
}

Eigen::VectorXd lagged(const Eigen::VectorXd& times, const Eigen::VectorXd& x, double tau) {
  Eigen::VectorXd y(x.size());
  if (x.size() == 0) return y;
  y(0) = x(0);
  for (Eigen::Index k = 0; k + 1 < x.size(); ++k) {
    const double d = times(k + 1) - times(k);
    const double s = (x(k + 1) - x(k)) / d;
    y(k + 1) = x(k + 1) - s * tau + (y(k) - x(k) + s * tau) * std::exp(-d / tau);
  }
  return y;
}

Eigen::VectorXd face_load(const mesh::TetMesh& m, const std::vector<int>& faces) {
  Eigen::VectorXd b = Eigen::VectorXd::Zero(m.nodes.rows());
  for (int f : faces) {
    const Eigen::Vector3d a = m.nodes.row(m.faces(f, 0)), p = m.nodes.row(m.faces(f, 1)),
                          q = m.nodes.row(m.faces(f, 2));
    const double area = 0.5 * (p - a).cross(q - a).norm();
    // int N dA: corners of a linear triangle A/3 each; a quadratic one puts A/3 on each mid-edge
    // node.
    const int first = m.order == 1 ? 0 : 3;
    for (int k = 0; k < 3; ++k) b(m.faces(f, first + k)) += area / 3;
  }
  return b;
}

namespace {

/// Exterior faces that belong to a boundary group, with centroid and area.
struct ExteriorFaces {
  std::vector<int> face;
  std::vector<Eigen::Vector3d> centroid;
  std::vector<double> area;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300);
};

ExteriorFaces exterior_faces(const mesh::TetMesh& m) {
  ExteriorFaces x;
  for (Eigen::Index f = 0; f < m.faces.rows(); ++f) {
    if (m.face_other_tet[f] >= 0 || core::index_of(m.face_group[f]) < 0) continue;
    const Eigen::Vector3d a = m.nodes.row(m.faces(f, 0)), p = m.nodes.row(m.faces(f, 1)),
                          q = m.nodes.row(m.faces(f, 2));
    x.face.push_back(static_cast<int>(f));
    x.centroid.push_back((a + p + q) / 3);
    x.area.push_back(0.5 * (p - a).cross(q - a).norm());
    x.lo = x.lo.cwiseMin(x.centroid.back());
    x.hi = x.hi.cwiseMax(x.centroid.back());
  }
  return x;
}

std::vector<Patch> box_patches(const mesh::TetMesh& m, const ExteriorFaces& ext,
                               const std::vector<Eigen::Vector3d>& centres, double half) {
  std::vector<Patch> out;
  std::set<std::vector<int>> seen;
  // The case's selectors' tolerance: the group written for a patch (augmented_case) holds the
  // same faces, also those whose centroid lies on the box's edge.
  const double tol = mesh::selection_tolerance(m.nodes);
  for (const Eigen::Vector3d& c : centres) {
    // One patch per boundary group and body in the box: heat through the bore is not heat through
    // the housing's outside, nor heat into the shaft across the gap, and a patch mixing them would
    // sit at neither.
    std::map<std::pair<int, int>, Patch> by_place;
    for (size_t e = 0; e < ext.face.size(); ++e) {
      if ((ext.centroid[e].array() < (c.array() - half - tol)).any() ||
          (ext.centroid[e].array() > (c.array() + half + tol)).any())
        continue;
      const int f = ext.face[e];
      const int body = core::index_of(m.tet_region[static_cast<size_t>(m.face_tet[f])]);
      Patch& p = by_place[{core::index_of(m.face_group[f]), body}];
      p.faces.push_back(f);
      p.area += ext.area[e];
      p.centre += ext.area[e] * ext.centroid[e];
    }
    for (auto& [place, p] : by_place) {
      if (p.area < 0.15 * (2 * half) * (2 * half) || !seen.insert(p.faces).second) continue;
      p.box_min = c.array() - half;
      p.box_max = c.array() + half;
      p.centre /= p.area;
      p.groups = {place.first};
      p.body = place.second;
      out.push_back(std::move(p));
    }
  }
  return out;
}

/// A heat-input candidate on patch `p` under `law`, without columns.
Candidate heat_candidate(const Patch& p, HeatLaw law, double ref_speed) {
  Candidate c;
  c.effect = HeatInput{law, ref_speed, p.box_min, p.box_max, p.centre, p.area, p.groups, p.body};
  char buf[160];
  std::snprintf(buf, sizeof buf, "heat input at (%.3f, %.3f, %.3f) m, %s", p.centre(0), p.centre(1),
                p.centre(2), law_name(law).c_str());
  c.name = buf;
  c.parameters = {law == HeatLaw::speed ? "flux_W_m2 at " + std::to_string(ref_speed) + " rpm"
                                        : "flux_W_m2"};
  return c;
}

SeparableColumn heat_column(const mesh::TetMesh& m, const Patch& p, const Candidate& c) {
  SeparableColumn col;
  col.name = c.name;
  col.shape = face_load(m, p.faces);
  const HeatInput& h = std::get<HeatInput>(c.effect);
  const double ref_speed = h.ref_speed_rpm;
  if (h.law == HeatLaw::speed)
    col.law = [ref_speed](double, double speed) { return speed > 0 ? speed / ref_speed : 0.0; };
  else
    col.law = [](double, double) { return 1.0; };
  return col;
}

/// The lag candidate of sensor `s` with time constant `tau` [s]: one fixed column per run.
Candidate lag_candidate(const std::vector<RunModel>& runs, const Readout& r, int s, double tau) {
  Candidate l;
  l.effect = SensorLag{s, tau};
  l.fixed = true;
  l.name = "lag of sensor " + r.ids[s] + " (" + std::to_string(static_cast<int>(std::lround(tau))) +
           " s)";
  l.parameters = {"time_constant_s"};
  for (const auto& rm : runs) {
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(rm.base.size(), 1);
    const Eigen::VectorXd x = rm.base.col(s);
    a.block(s * rm.times.size(), 0, rm.times.size(), 1) = lagged(rm.times, x, tau) - x;
    l.columns.push_back(a);
  }
  return l;
}

/// `cands` with mechanisms that act in several places at once with one parameter, their columns
/// and unit loads the weighted sums of the single places' (no further march): every film (and
/// every film of a group that is not fixed, the air's) growing with speed, or changed, by the same
/// share of its declared h; every heat source's heat growing with temperature by one coefficient.
std::vector<Candidate> with_several_places(std::vector<Candidate> cands,
                                           const core::CaseSpec& declared, double ref_speed) {
  const auto& conv = declared.thermal.convection;
  // The places (convection entries, heat sources) a film or heat candidate acts on.
  auto places = [](const Candidate& c) -> const std::vector<int>* {
    if (const auto* e = std::get_if<SpeedDependentConvection>(&c.effect)) return &e->entries;
    if (const auto* e = std::get_if<BoundaryConductance>(&c.effect)) return &e->entries;
    if (const auto* e = std::get_if<TemperatureDependentHeat>(&c.effect)) return &e->sources;
    return nullptr;
  };
  auto single = [&](EffectKind k, int entry) -> const Candidate* {
    for (const auto& c : cands)
      if (kind(c) == k && places(c) && *places(c) == std::vector<int>{entry}) return &c;
    return nullptr;
  };
  std::vector<Candidate> added;
  auto add = [&](const Effect& effect, const std::vector<int>& entries,
                 const std::vector<double>& weights, const std::string& name,
                 const std::string& parameter) {
    if (entries.size() < 2) return;
    Candidate c;
    c.effect = effect;
    c.name = name;
    c.parameters = {parameter};
    for (size_t k = 0; k < entries.size(); ++k) {
      const Candidate* one = single(kind(effect), entries[k]);
      if (!one) return;
      for (size_t ri = 0; ri < one->columns.size(); ++ri) {
        if (c.columns.size() <= ri)
          c.columns.push_back(Eigen::MatrixXd::Zero(one->columns[ri].rows(), 1));
        c.columns[ri] += weights[k] * one->columns[ri];
      }
      for (size_t j = 0; j < one->unit_loads.size(); ++j) {
        c.unit_loads.push_back(one->unit_loads[j]);
        c.unit_weights.push_back(weights[k] * one->unit_weights.at(j));
      }
    }
    added.push_back(std::move(c));
  };
  std::vector<int> all, free;
  std::vector<double> h_all, h_free;
  const auto& fixed = declared.mechanical.fixed_groups;
  for (size_t e = 0; e < conv.size(); ++e) {
    all.push_back(static_cast<int>(e));
    h_all.push_back(conv[e].h);
    if (std::find(fixed.begin(), fixed.end(), conv[e].group) == fixed.end()) {
      free.push_back(static_cast<int>(e));
      h_free.push_back(conv[e].h);
    }
  }
  const std::string at_ref = " at " + std::to_string(ref_speed) + " rpm";
  for (int v = 0; v < 2; ++v) {
    const auto& entries = v ? free : all;
    const auto& shares = v ? h_free : h_all;
    if (v && free.size() == all.size()) break;
    const std::string which = v ? "every film of an unfixed group" : "every film";
    add(SpeedDependentConvection{entries, shares, ref_speed, 1}, entries, shares,
        which + " growing with speed by one share of its h", "h_speed_gain / h" + at_ref);
    add(BoundaryConductance{entries, shares}, entries, shares,
        which + " changed by one share of its h", "delta_h / h");
  }
  std::vector<int> sources;
  for (size_t i = 0; i < declared.thermal.sources.size(); ++i)
    sources.push_back(static_cast<int>(i));
  const std::vector<double> ones(sources.size(), 1.0);
  add(TemperatureDependentHeat{sources, ones}, sources, ones,
      "heat of every source growing with its temperature by one coefficient",
      "temperature_coefficient_per_K");
  for (auto& c : added) cands.push_back(std::move(c));
  return cands;
}

}  // namespace

std::vector<Patch> surface_patches(const mesh::TetMesh& m, double spacing, double half) {
  const ExteriorFaces ext = exterior_faces(m);
  const Eigen::Vector3i count =
      (((ext.hi - ext.lo) / spacing).array().floor().cast<int>() + 1).matrix();
  const Eigen::Vector3d start =
      0.5 * (ext.lo + ext.hi) - 0.5 * spacing * (count.cast<double>() - Eigen::Vector3d::Ones());
  std::vector<Eigen::Vector3d> centres;
  for (int i = 0; i < count(0); ++i)
    for (int j = 0; j < count(1); ++j)
      for (int k = 0; k < count(2); ++k)
        centres.push_back(start + spacing * Eigen::Vector3d(i, j, k));
  return box_patches(m, ext, centres, half);
}

Eigen::VectorXd noise_sigma(const std::vector<RunModel>& runs, int sensors,
                            const CalibrationOptions& o) {
  const Eigen::Index nc = runs.front().measured.cols();
  Eigen::VectorXd sigma(nc);
  for (Eigen::Index c = 0; c < nc; ++c) {
    std::vector<double> d2;
    for (const auto& r : runs) {
      const Eigen::VectorXd e = r.measured.col(c) - r.base.col(c);
      for (Eigen::Index i = 1; i + 1 < e.size(); ++i) {
        const double v = e(i + 1) - 2 * e(i) + e(i - 1);
        if (std::isfinite(v)) d2.push_back(std::abs(v));
      }
    }
    double s = 0;
    if (!d2.empty()) {
      std::nth_element(d2.begin(), d2.begin() + d2.size() / 2, d2.end());
      s = 1.4826 * d2[d2.size() / 2] / std::sqrt(6.0);
    }
    sigma(c) = std::max(s, c < sensors ? o.noise_floor_K : o.noise_floor_m);
  }
  return sigma;
}

namespace {

/// Which of the march's responses make a candidate's columns: a separable column, a load column,
/// an extra readout (indices into each list).
struct ColumnSource {
  enum { separable, load, extra_readout, ambient, none } type;
  std::vector<int> index;
};

/// The candidates that need a march, with what the march must respond to for their columns:
/// `sources[i]` names the responses of `cands[i]`.
struct MarchedCandidates {
  std::vector<Candidate> cands;
  std::vector<SeparableColumn> sep;
  std::vector<LoadColumn> loads;
  std::vector<Eigen::MatrixXd> extra;
  std::vector<ColumnSource> sources;
};

/// The speed a speed law is referred to [rpm]: the sources' own, else the runs' fastest, else 1.
double reference_speed(const core::CaseSpec& declared, const std::vector<core::CaseSpec>& runs) {
  double ref_speed = 0;
  for (const auto& s : declared.thermal.sources) ref_speed = std::max(ref_speed, s.ref_speed_rpm);
  if (ref_speed <= 0)
    for (const auto& s : runs)
      for (const auto& seg : s.duty_cycle.segments) ref_speed = std::max(ref_speed, seg.speed_rpm);
  if (ref_speed <= 0) ref_speed = 1;
  return ref_speed;
}

/// Air temperature: hat functions on the sinks of (a) every convection entry, (b) every entry
/// whose group is not mechanically fixed (a bed that keeps its own temperature).
void add_air_candidates(MarchedCandidates& mc, const core::CaseSpec& declared, double end_max,
                        const CalibrationOptions& o) {
  const auto& conv = declared.thermal.convection;
  std::vector<double> knots;
  const int intervals = std::max(1, static_cast<int>(std::ceil(end_max / o.ambient_knot_interval)));
  for (int k = 0; k <= intervals; ++k) knots.push_back(end_max * k / intervals);
  std::vector<std::vector<int>> variants;
  std::vector<int> all, free;
  for (size_t c = 0; c < conv.size(); ++c) {
    all.push_back(static_cast<int>(c));
    const auto& fixed = declared.mechanical.fixed_groups;
    if (std::find(fixed.begin(), fixed.end(), conv[c].group) == fixed.end())
      free.push_back(static_cast<int>(c));
  }
  if (!all.empty()) variants.push_back(all);
  if (!free.empty() && free.size() != all.size()) variants.push_back(free);
  for (size_t v = 0; v < variants.size(); ++v) {
    Candidate c;
    c.effect = AmbientTemperature{variants[v], knots};
    c.per_run = true;
    c.name = v == 0 ? "air temperature on every convective sink"
                    : "air temperature on the sinks of unfixed groups";
    ColumnSource src{ColumnSource::load, {}};
    for (size_t k = 0; k < knots.size(); ++k) {
      c.parameters.push_back("delta_air_K at t = " + std::to_string(knots[k]) + " s");
      const std::vector<int> entries = variants[v];
      const double tk = knots[k], dk = end_max / intervals;
      src.index.push_back(static_cast<int>(mc.loads.size()));
      // The hat at knot k on every entry's sink: h(n) int N dA per kelvin.
      LoadColumn lc;
      lc.name = c.name + " knot " + std::to_string(k);
      lc.form = SinkHat{entries, tk, dk};
      mc.loads.push_back(std::move(lc));
    }
    mc.cands.push_back(std::move(c));
    mc.sources.push_back(src);
  }
}

/// Heat entering through an undeclared surface patch, under each law.
void add_heat_candidates(MarchedCandidates& mc, const mesh::TetMesh& m, const CalibrationOptions& o,
                         double ref_speed) {
  for (const Patch& p : surface_patches(m, o.patch_spacing, o.patch_half_size)) {
    for (const HeatLaw law : o.heat_laws) {
      Candidate c = heat_candidate(p, law, ref_speed);
      mc.sources.push_back({ColumnSource::separable, {static_cast<int>(mc.sep.size())}});
      mc.sep.push_back(heat_column(m, p, c));
      c.unit_separable = {mc.sep.back()};
      c.unit_weights = {1};
      mc.cands.push_back(std::move(c));
    }
  }
}

/// `c` responding to the one load column `lc`, appended with it.
void add_load_candidate(MarchedCandidates& mc, Candidate c, LoadColumn lc) {
  mc.sources.push_back({ColumnSource::load, {static_cast<int>(mc.loads.size())}});
  c.unit_loads = {lc};
  c.unit_weights = {1};
  mc.loads.push_back(std::move(lc));
  mc.cands.push_back(std::move(c));
}

/// Per convection entry: a wrong conductance, and a conductance growing with speed.
void add_film_candidates(MarchedCandidates& mc, const core::CaseSpec& declared, double ref_speed) {
  const auto& conv = declared.thermal.convection;
  for (size_t e = 0; e < conv.size(); ++e) {
    const std::string gname = declared.groups[conv[e].group].name;
    for (int speed_law = 0; speed_law < 2; ++speed_law) {
      Candidate c;
      const std::vector<int> entry{static_cast<int>(e)};
      if (speed_law)
        c.effect = SpeedDependentConvection{entry, {1}, ref_speed, 1};
      else
        c.effect = BoundaryConductance{entry, {1}};
      c.name = (speed_law ? "convection growing with speed on " : "conductance of ") + gname;
      c.parameters = {speed_law ? "h_speed_gain_W_m2K at " + std::to_string(ref_speed) + " rpm"
                                : "delta_h_W_m2K"};
      LoadColumn lc;
      lc.name = c.name;
      lc.form = FilmChange{static_cast<int>(e), speed_law == 1, ref_speed};
      add_load_candidate(mc, std::move(c), std::move(lc));
    }
  }
}

/// Heat that grows with the source's temperature.
void add_source_growth_candidates(MarchedCandidates& mc, const core::CaseSpec& declared) {
  const double t0_k = declared.thermal.initial_temperature_c + core::kCelsiusOffset;
  for (size_t i = 0; i < declared.thermal.sources.size(); ++i) {
    const auto& srcspec = declared.thermal.sources[i];
    Candidate c;
    c.effect = TemperatureDependentHeat{{static_cast<int>(i)}, {1}};
    c.name = "heat of " + srcspec.name + " growing with its temperature";
    c.parameters = {"temperature_coefficient_per_K"};
    LoadColumn lc;
    lc.name = c.name;
    lc.form = SourceGrowth{static_cast<int>(i), t0_k};
    add_load_candidate(mc, std::move(c), std::move(lc));
  }
}

/// Material parameters, each as a relative change: conductivity, heat capacity, expansion.
void add_material_candidates(MarchedCandidates& mc, const MarchModel& model,
                             const core::CaseSpec& declared, const Readout& r) {
  const mesh::TetMesh& m = model.mesh();
  const solvers::FullThermalSystem& ops = model.full();
  for (size_t mi = 0; mi < declared.materials.size(); ++mi) {
    core::CaseSpec doubled = declared;
    doubled.materials[mi].conductivity *= 2;
    doubled.materials[mi].density *= 2;
    const solvers::FullThermalSystem dops = solvers::thermal_system(m, doubled);
    const auto km = std::make_shared<Eigen::SparseMatrix<double>>(dops.conduction - ops.conduction);
    const auto cm = std::make_shared<Eigen::SparseMatrix<double>>(dops.capacity - ops.capacity);
    if (km->norm() == 0) continue;  // a material no body uses
    const std::string mname = declared.materials[mi].name;
    for (const auto& [field, fname] : kMaterialFieldNames) {
      if (field == MaterialField::expansion &&
          (r.displacement.rows() == 0 || !declared.mechanical.enabled))
        continue;
      Candidate c;
      c.effect = MaterialParameter{static_cast<int>(mi), field};
      c.name = std::string(fname) + " of " + mname;
      c.parameters = {"relative_change"};
      if (field == MaterialField::expansion) {
        // The probes' rows gain the material's part per unit relative change.
        mc.extra.push_back(r.expansion.at(mi));
        mc.sources.push_back(
            {ColumnSource::extra_readout, {static_cast<int>(mc.extra.size()) - 1}});
        mc.cands.push_back(std::move(c));
        continue;
      }
      // A relative change of conductivity (capacity) adds -dK T (-dC dT/dt).
      OperatorChange change;
      const bool conductivity = field == MaterialField::conductivity;
      change.which =
          conductivity ? OperatorChange::Operator::conduction : OperatorChange::Operator::capacity;
      change.full = conductivity ? km : cm;
      if (model.is_reduced())
        change.reduced = std::make_shared<const Eigen::MatrixXd>(model.projected(*change.full));
      LoadColumn lc;
      lc.name = c.name;
      lc.form = std::move(change);
      add_load_candidate(mc, std::move(c), std::move(lc));
    }
  }
}

/// One march per run with every column of `mc`, each read at its `times`; `progress` gets the
/// simulated time over the runs' total.
std::vector<Responses> marched_runs(const MarchModel& model, const Readout& r,
                                    const std::vector<core::CaseSpec>& specs,
                                    const std::vector<Eigen::VectorXd>& times,
                                    const MarchedCandidates& mc,
                                    const solvers::Progress& progress) {
  std::vector<Responses> resp;
  double simulated = 0, total = 0;
  for (const auto& t : times) total += t(t.size() - 1);
  for (size_t k = 0; k < specs.size(); ++k) {
    resp.push_back(march(model, specs[k], r, times[k], mc.sep, mc.loads, mc.extra));
    simulated += times[k](times[k].size() - 1);
    if (progress) progress(simulated, total);
  }
  return resp;
}

/// The candidates' identities and unit loads (no columns yet): the air, and unless `ambient_only`
/// the heat inputs, films, sources' growth and materials.
MarchedCandidates candidate_loads(const MarchModel& model, const core::CaseSpec& declared,
                                  const Readout& r, const std::vector<core::CaseSpec>& specs,
                                  double end_max, const CalibrationOptions& o, bool ambient_only) {
  const double ref_speed = reference_speed(declared, specs);
  MarchedCandidates mc;
  add_air_candidates(mc, declared, end_max, o);
  if (!ambient_only) {
    add_heat_candidates(mc, model.mesh(), o, ref_speed);
    add_film_candidates(mc, declared, ref_speed);
    add_source_growth_candidates(mc, declared);
    add_material_candidates(mc, model, declared, r);
  }
  return mc;
}

/// Each candidate's columns per run, gathered from the runs' responses `resp` by its source.
void fill_columns(MarchedCandidates& mc, const std::vector<Responses>& resp) {
  auto vec = [](const Eigen::MatrixXd& a) {
    return Eigen::Map<const Eigen::VectorXd>(a.data(), a.size()).eval();
  };
  const auto& sources = mc.sources;
  for (size_t ci = 0; ci < mc.cands.size(); ++ci) {
    Candidate& c = mc.cands[ci];
    for (size_t ri = 0; ri < resp.size(); ++ri) {
      const Responses& rs = resp[ri];
      const Eigen::Index rows = rs.base.size();
      Eigen::MatrixXd a(rows, static_cast<Eigen::Index>(sources[ci].index.size()));
      for (size_t k = 0; k < sources[ci].index.size(); ++k) {
        const int idx = sources[ci].index[k];
        const Eigen::MatrixXd& m_k = sources[ci].type == ColumnSource::separable ? rs.columns[idx]
                                     : sources[ci].type == ColumnSource::load
                                         ? rs.columns[mc.sep.size() + static_cast<size_t>(idx)]
                                         : rs.extra[idx];
        a.col(static_cast<Eigen::Index>(k)) = vec(m_k);
      }
      c.columns.push_back(std::move(a));
    }
  }
}

/// Sensors' own effects, from the base histories of `runs`: an offset and a lag per grid value.
void add_sensor_candidates(std::vector<Candidate>& cands, const std::vector<RunModel>& runs,
                           const Readout& r, const CalibrationOptions& o) {
  for (int s = 0; s < r.sensors; ++s) {
    Candidate c;
    c.effect = SensorOffset{s};
    c.name = "offset of sensor " + r.ids[s];
    c.parameters = {"offset_K"};
    for (const auto& rm : runs) {
      Eigen::MatrixXd a = Eigen::MatrixXd::Zero(rm.base.size(), 1);
      a.block(s * rm.times.size(), 0, rm.times.size(), 1).setOnes();
      c.columns.push_back(a);
    }
    cands.push_back(std::move(c));
    for (double tau : o.lag_grid_s) cands.push_back(lag_candidate(runs, r, s, tau));
  }
}

}  // namespace

Catalogue catalogue(const MarchModel& model, const core::CaseSpec& declared, const Readout& r,
                    const std::vector<io::MeasuredRun>& runs, const CalibrationOptions& o,
                    bool ambient_only, const solvers::Progress& progress) {
  Catalogue cat;
  cat.readout = r;
  std::vector<core::CaseSpec> specs;
  std::vector<Eigen::VectorXd> times;
  double end_max = 0;
  for (const auto& run : runs) {
    specs.push_back(case_for_run(declared, run));
    times.push_back(run.time);
    end_max = std::max(end_max, run.time(run.time.size() - 1));
  }
  // 1. The candidates' identities and their unit loads.
  MarchedCandidates mc = candidate_loads(model, declared, r, specs, end_max, o, ambient_only);
  // 2. One march per run with every column; sensors' own effects from the base histories.
  const std::vector<Responses> resp = marched_runs(model, r, specs, times, mc, progress);
  for (size_t k = 0; k < runs.size(); ++k) {
    RunModel rm;
    rm.name = runs[k].run;
    rm.spec = specs[k];
    rm.times = runs[k].time;
    rm.measured = measured_channels(runs[k], r);
    rm.base = resp[k].base;
    // The air the run's ambient sensor reads (the readout leaves it out of the channels).
    rm.air = ambient_reading(runs[k]);
    cat.runs.push_back(std::move(rm));
  }
  fill_columns(mc, resp);
  std::vector<Candidate> cands = std::move(mc.cands);
  if (!ambient_only)
    cands = with_several_places(std::move(cands), declared, reference_speed(declared, specs));
  if (!ambient_only) add_sensor_candidates(cands, cat.runs, r, o);
  cat.candidates = std::move(cands);
  return cat;
}

std::vector<Candidate> heat_flow_candidates(const MarchModel& model, const core::CaseSpec& declared,
                                            const Readout& r,
                                            const std::vector<core::CaseSpec>& runs,
                                            const std::vector<Eigen::VectorXd>& times,
                                            const CalibrationOptions& o,
                                            const solvers::Progress& progress) {
  if (runs.empty() || runs.size() != times.size())
    throw core::DataError("heat-flow candidates: " + std::to_string(runs.size()) + " runs and " +
                          std::to_string(times.size()) + " time vectors: expected one per run");
  double end_max = 0;
  for (const auto& t : times) {
    if (t.size() == 0) throw core::DataError("heat-flow candidates: a run read at no time");
    end_max = std::max(end_max, t(t.size() - 1));
  }
  MarchedCandidates mc = candidate_loads(model, declared, r, runs, end_max, o, false);
  fill_columns(mc, marched_runs(model, r, runs, times, mc, progress));
  return with_several_places(std::move(mc.cands), declared, reference_speed(declared, runs));
}

std::vector<double> fit_run_parameters(const Candidate& c, int run, const RunModel& model,
                                       const Readout& r, const Eigen::VectorXd& sigma,
                                       const CalibrationOptions& o) {
  const Whitened w = whitened(model, sigma);
  const std::vector<Eigen::Index> keep = temperature_rows(w, r);
  const Eigen::MatrixXd a = rows_of(whitened_rows(c.columns[run], w, sigma), keep);
  const Eigen::VectorXd y = rows_of(w.y, keep);
  const Eigen::VectorXd theta = per_run_theta(c, model, a.transpose() * a, a.transpose() * y, o);
  return std::vector<double>(theta.data(), theta.data() + theta.size());
}

AirEliminated air_eliminated(const Candidate* air, const RunModel& run, const Readout& r,
                             const Whitened& w, const Eigen::VectorXd& y,
                             const Eigen::MatrixXd& shared, size_t ri, const Eigen::VectorXd& sigma,
                             const CalibrationOptions& o) {
  AirEliminated out{shared, y, {}, {}};
  if (!air) return out;
  out.a = whitened_rows(air->columns[ri], w, sigma);
  out.keep = temperature_rows(w, r);
  if (run.air.size() > 0) {  // read from the ambient sensor: nothing to fit
    out.y -= out.a * air_from_sensor(std::get<AmbientTemperature>(air->effect), run);
    return out;
  }
  const Eigen::MatrixXd at = rows_of(out.a, out.keep);
  Eigen::MatrixXd gt = at.transpose() * at;
  gt.diagonal().array() += std::max(o.ridge, 1e-6) * std::max(gt.diagonal().mean(), 1e-300);
  const Eigen::LDLT<Eigen::MatrixXd> f(gt);
  out.y -= out.a * f.solve(at.transpose() * rows_of(y, out.keep));
  out.m -= out.a * f.solve(at.transpose() * rows_of(shared, out.keep));
  return out;
}

Eigen::VectorXd air_at(const Candidate& air, const RunModel& run, const AirEliminated& e,
                       const Eigen::VectorXd& y, const Eigen::MatrixXd& shared,
                       const Eigen::VectorXd& x, const CalibrationOptions& o) {
  const Eigen::MatrixXd at = rows_of(e.a, e.keep);
  const Eigen::VectorXd left = rows_of(y - shared * x, e.keep);
  return per_run_theta(air, run, at.transpose() * at, at.transpose() * left, o);
}

namespace {

/// Shared parameters fitted across the runs from their normal equations: leave-one-run-out gains
/// and the in-sample fit on all runs.
struct SharedFit {
  std::vector<double> fold_gains;
  double heldout = 0, insample = 0;
  Eigen::VectorXd full;
};

SharedFit shared_fit(const std::vector<Normal>& normals, const CalibrationOptions& o) {
  SharedFit out;
  Normal sum{Eigen::MatrixXd::Zero(normals[0].g.rows(), normals[0].g.cols()),
             Eigen::VectorXd::Zero(normals[0].b.size()), 0};
  for (const auto& nm : normals) {
    sum.g += nm.g;
    sum.b += nm.b;
  }
  for (size_t ri = 0; ri < normals.size(); ++ri) {
    const Eigen::VectorXd th = solve_ridge(sum.g - normals[ri].g, sum.b - normals[ri].b, o.ridge);
    out.fold_gains.push_back(gain_of(normals[ri], th));
    out.heldout += out.fold_gains.back();
  }
  out.full = solve_ridge(sum.g, sum.b, o.ridge);
  for (const auto& nm : normals) out.insample += gain_of(nm, out.full);
  return out;
}

/// Scores every candidate on whitened residuals `ys` (per run); fills fits in candidate order.
/// Every run whitened with `sigma`: the kept rows, and their values apart (score_all's inputs).
struct WhitenedRuns {
  std::vector<Whitened> ws;
  std::vector<Eigen::VectorXd> ys;
};
WhitenedRuns whitened_runs(const std::vector<RunModel>& runs, const Eigen::VectorXd& sigma) {
  WhitenedRuns out;
  for (const auto& rm : runs) {
    out.ws.push_back(whitened(rm, sigma));
    out.ys.push_back(out.ws.back().y);
  }
  return out;
}

std::vector<EffectFit> score_all(const Catalogue& cat, const std::vector<Whitened>& ws,
                                 const std::vector<Eigen::VectorXd>& ys,
                                 const Eigen::VectorXd& sigma, const CalibrationOptions& o,
                                 bool with_parameters, const std::vector<int>& subset = {}) {
  const auto& r = cat.readout;
  const size_t nr = cat.runs.size();
  const size_t count = subset.empty() ? cat.candidates.size() : subset.size();
  std::vector<EffectFit> fits(count);
  for (size_t fi = 0; fi < count; ++fi) {
    const size_t ci = subset.empty() ? fi : static_cast<size_t>(subset[fi]);
    const Candidate& c = cat.candidates[ci];
    EffectFit& f = fits[fi];
    f.candidate = static_cast<int>(ci);
    f.kind = kind(c);
    f.name = c.name;
    const double p = static_cast<double>(c.columns.front().cols());
    std::vector<Normal> normals(nr);
    double total_s = 0;
    for (size_t ri = 0; ri < nr; ++ri) {
      const Eigen::MatrixXd a = whitened_rows(c.columns[ri], ws[ri], sigma);
      normals[ri] = {a.transpose() * a, a.transpose() * ys[ri], ys[ri].squaredNorm()};
      total_s += normals[ri].s;
    }
    double heldout = 0, insample = 0;
    f.fold_gains.assign(nr, 0.0);
    if (c.fixed) {
      const Eigen::VectorXd one = Eigen::VectorXd::Ones(1);
      for (size_t ri = 0; ri < nr; ++ri) f.fold_gains[ri] = gain_of(normals[ri], one);
      for (double g : f.fold_gains) heldout += g;
      insample = heldout;
      f.heldout_gain = heldout;
      f.score = heldout - o.penalty_per_parameter;
      f.parameters = {std::get<SensorLag>(c.effect).time_constant_s};
    } else if (c.per_run) {
      for (size_t ri = 0; ri < nr; ++ri) {
        // Fit on the run's temperatures, score on all of its channels.
        const std::vector<Eigen::Index> keep = temperature_rows(ws[ri], r);
        const Eigen::MatrixXd at = rows_of(whitened_rows(c.columns[ri], ws[ri], sigma), keep);
        const Eigen::VectorXd yt = rows_of(ys[ri], keep);
        const RunModel& rm = cat.runs[ri];
        const Eigen::VectorXd th =
            per_run_theta(c, rm, at.transpose() * at, at.transpose() * yt, o);
        f.fold_gains[ri] = gain_of(normals[ri], th);
        heldout += f.fold_gains[ri];
        const Eigen::VectorXd full = per_run_theta(c, rm, normals[ri].g, normals[ri].b, o);
        insample += gain_of(normals[ri], full);
        if (with_parameters) f.run_parameters.emplace_back(th.data(), th.data() + th.size());
        // A run's air read from its ambient sensor is not fitted: no parameters to pay for.
        if (rm.air.size() == 0) f.score -= o.penalty_per_parameter * p;
      }
      f.heldout_gain = heldout;
      f.score += heldout;
    } else {
      const SharedFit sf = shared_fit(normals, o);
      f.fold_gains = sf.fold_gains;
      heldout = sf.heldout;
      insample = sf.insample;
      const Eigen::VectorXd& full = sf.full;
      f.heldout_gain = heldout;
      f.score = heldout - o.penalty_per_parameter * p;
      if (with_parameters) f.parameters.assign(full.data(), full.data() + full.size());
    }
    f.explained_fraction = total_s > 0 ? insample / total_s : 0;
  }
  return fits;
}

/// The whitened residuals `ys` with the in-sample fit of each claim in `fits` removed, in order: a
/// shared claim at its fitted parameters, a per-run air fitted again on what is left of each run,
/// a lag at its amplitude 1.
std::vector<Eigen::VectorXd> without_fits(const Catalogue& cat, const std::vector<Whitened>& ws,
                                          std::vector<Eigen::VectorXd> ys,
                                          const Eigen::VectorXd& sigma,
                                          const std::vector<EffectFit>& fits,
                                          const CalibrationOptions& o) {
  for (const EffectFit& f : fits) {
    const Candidate& c = cat.candidates[static_cast<size_t>(f.candidate)];
    for (size_t ri = 0; ri < cat.runs.size(); ++ri) {
      const Eigen::MatrixXd a = whitened_rows(c.columns[ri], ws[ri], sigma);
      Eigen::VectorXd th;
      if (c.fixed)
        th = Eigen::VectorXd::Ones(1);
      else if (c.per_run)
        th = per_run_theta(c, cat.runs[ri], a.transpose() * a, a.transpose() * ys[ri], o);
      else
        th = Eigen::Map<const Eigen::VectorXd>(f.parameters.data(),
                                               static_cast<Eigen::Index>(f.parameters.size()));
      ys[ri] -= a * th;
    }
  }
  return ys;
}

/// sqrt(#runs) x the standard deviation of the per-run held-out gain differences of a and b: how
/// much their score difference could change with other runs. With two runs it exceeds the
/// difference exactly when b gains more than a on one of them.
double gain_spread(const std::vector<double>& a, const std::vector<double>& b) {
  const size_t n = std::min(a.size(), b.size());
  if (n < 2) return 0;
  double mean = 0, ss = 0;
  for (size_t r = 0; r < n; ++r) mean += (a[r] - b[r]) / static_cast<double>(n);
  for (size_t r = 0; r < n; ++r) {
    const double d = a[r] - b[r] - mean;
    ss += d * d;
  }
  return std::sqrt(static_cast<double>(n) * ss / static_cast<double>(n - 1));
}

/// A pair's joint design on every run: the shared members' whitened columns side by side, the
/// run's air (if any) eliminated beside them, their normal equations, and the number of
/// parameters the pair pays for.
struct PairDesign {
  std::vector<Normal> normals;
  std::vector<Eigen::MatrixXd> cols;
  std::vector<AirEliminated> design;
  double penalty = 0;
};

PairDesign pair_design(const Catalogue& cat, const std::vector<Whitened>& ws,
                       const std::vector<Eigen::VectorXd>& ys, const Eigen::VectorXd& sigma,
                       const std::vector<const Candidate*>& shared, const Candidate* air,
                       const CalibrationOptions& o) {
  const size_t nr = cat.runs.size();
  PairDesign d;
  d.cols.resize(nr);
  for (const Candidate* c : shared) d.penalty += static_cast<double>(c->columns.front().cols());
  for (size_t ri = 0; ri < nr; ++ri) {
    Eigen::Index p = 0;
    for (const Candidate* c : shared) p += c->columns.front().cols();
    d.cols[ri].resize(static_cast<Eigen::Index>(ws[ri].rows.size()), p);
    Eigen::Index at = 0;
    for (const Candidate* c : shared) {
      const Eigen::Index k = c->columns.front().cols();
      d.cols[ri].middleCols(at, k) = whitened_rows(c->columns[ri], ws[ri], sigma);
      at += k;
    }
    d.design.push_back(
        air_eliminated(air, cat.runs[ri], cat.readout, ws[ri], ys[ri], d.cols[ri], ri, sigma, o));
    const AirEliminated& e = d.design.back();
    d.normals.push_back({e.m.transpose() * e.m, e.m.transpose() * e.y, e.y.squaredNorm()});
    if (air && cat.runs[ri].air.size() == 0)
      d.penalty += static_cast<double>(air->columns.front().cols());
  }
  return d;
}

/// Gains against the residual itself into `fold_gains`, with each run's air fitted within its
/// bounds beside the shared parameters of its fold (those of the other runs); returns each run's
/// air fitted beside the in-sample shared parameters `sf.full`.
std::vector<std::vector<double>> air_fold_gains(const Catalogue& cat,
                                                const std::vector<Eigen::VectorXd>& ys,
                                                const Candidate& air, const PairDesign& d,
                                                const SharedFit& sf, const CalibrationOptions& o,
                                                std::vector<double>& fold_gains) {
  const auto& normals = d.normals;
  const auto& cols = d.cols;
  const auto& design = d.design;
  std::vector<std::vector<double>> airs;
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(sf.full.size(), sf.full.size());
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(sf.full.size());
  for (const auto& nm : normals) {
    g += nm.g;
    rhs += nm.b;
  }
  for (size_t ri = 0; ri < cat.runs.size(); ++ri) {
    const Eigen::VectorXd x = solve_ridge(g - normals[ri].g, rhs - normals[ri].b, o.ridge);
    const Eigen::VectorXd th = air_at(air, cat.runs[ri], design[ri], ys[ri], cols[ri], x, o);
    fold_gains[ri] =
        ys[ri].squaredNorm() - (ys[ri] - cols[ri] * x - design[ri].a * th).squaredNorm();
    const Eigen::VectorXd full =
        air_at(air, cat.runs[ri], design[ri], ys[ri], cols[ri], sf.full, o);
    airs.emplace_back(full.data(), full.data() + full.size());
  }
  return airs;
}

/// Each member of `pf` given its joint parameters (the shared ones from `full` in member order,
/// an air its per-run `airs`) and judged physical with them.
void size_members(const Catalogue& cat, PairFit& pf, const Eigen::VectorXd& full,
                  const std::vector<std::vector<double>>& airs, const CalibrationOptions& o) {
  Eigen::Index at = 0;
  for (EffectFit* f : {&pf.first, &pf.second}) {
    const Candidate& c = cat.candidates[static_cast<size_t>(f->candidate)];
    if (c.per_run) {
      f->parameters.clear();
      f->run_parameters = airs;
    } else {
      const Eigen::Index k = c.columns.front().cols();
      f->parameters.assign(full.data() + at, full.data() + at + k);
      at += k;
    }
    f->unphysical =
        unphysical_reason(c, f->parameters, f->run_parameters, cat.runs, o, &f->duty_correlation);
  }
}

/// Candidates `a` and `b` (their single fits of the first round) fitted together: the joint
/// leave-one-run-out gains, the joint in-sample parameters, each member judged physical with them.
/// One member may be a per-run air: it is fitted on each run beside the other's shared parameters
/// (on the held-out run too, as a single air is), so that an air and a mechanism it can shadow are
/// sized together.
PairFit pair_fit(const Catalogue& cat, const std::vector<Whitened>& ws,
                 const std::vector<Eigen::VectorXd>& ys, const Eigen::VectorXd& sigma,
                 const EffectFit& a, const EffectFit& b, double null_score,
                 const CalibrationOptions& o) {
  const Candidate& ca = cat.candidates[static_cast<size_t>(a.candidate)];
  const Candidate& cb = cat.candidates[static_cast<size_t>(b.candidate)];
  PairFit pf;
  pf.first = a;
  pf.second = b;
  if ((ca.per_run && cb.per_run) || ca.fixed || cb.fixed) {
    pf.score = -std::numeric_limits<double>::infinity();  // no joint least squares
    return pf;
  }
  const Candidate* air = ca.per_run ? &ca : (cb.per_run ? &cb : nullptr);
  // The shared columns: both members', or the one that is not the air.
  std::vector<const Candidate*> shared;
  for (const Candidate* c : {&ca, &cb})
    if (!c->per_run) shared.push_back(c);
  const PairDesign d = pair_design(cat, ws, ys, sigma, shared, air, o);
  const SharedFit sf = shared_fit(d.normals, o);
  pf.fold_gains = sf.fold_gains;
  std::vector<std::vector<double>> airs;
  if (air) airs = air_fold_gains(cat, ys, *air, d, sf, o, pf.fold_gains);
  for (double gain : pf.fold_gains) pf.heldout_gain += gain;
  pf.score = pf.heldout_gain - o.penalty_per_parameter * d.penalty;
  size_members(cat, pf, sf.full, airs, o);
  pf.adds_first = pf.score - b.score;
  pf.adds_second = pf.score - a.score;
  pf.admissible = pf.first.unphysical.empty() && pf.second.unphysical.empty() &&
                  pf.adds_first > std::max(null_score, a.floor) &&
                  pf.adds_second > std::max(null_score, b.floor);
  return pf;
}

/// `cat` with the columns of its best nonlinear candidates whose linearised fit is unphysical
/// replaced by their secant responses at the size `resize` finds (their `linearised` parameters
/// kept by candidate); nothing when no candidate needs it.
std::optional<Catalogue> resized_catalogue(const Catalogue& cat, const CalibrationOptions& o,
                                           const Resizer& resize,
                                           std::map<int, std::vector<double>>& linearised) {
  const Eigen::VectorXd sigma = noise_sigma(cat.runs, cat.readout.sensors, o);
  const auto [ws, ys] = whitened_runs(cat.runs, sigma);
  std::vector<EffectFit> fits = score_all(cat, ws, ys, sigma, o, true);
  std::vector<size_t> order(fits.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return fits[a].score > fits[b].score; });
  std::optional<Catalogue> out;
  int done = 0;
  for (size_t i : order) {
    const EffectFit& f = fits[i];
    if (done >= o.resize_pool || f.score <= 0) break;
    const Candidate& c = cat.candidates[static_cast<size_t>(f.candidate)];
    if (!nonlinear_in_parameter(c) || c.per_run || f.parameters.size() != 1 ||
        unphysical_reason(c, f.parameters, {}, cat.runs, o).empty())
      continue;
    ++done;
    Resized r = resize(f);
    if (r.columns.size() != cat.runs.size()) continue;  // no size found: stays as linearised
    if (!out) out = cat;
    out->candidates[i].columns = std::move(r.columns);
    linearised[f.candidate] = f.parameters;
  }
  return out;
}

/// The first round's best candidates (`fits` in `order`) that may be paired: physical, not fixed,
/// scoring above zero; at most o.pair_pool_per_kind of a kind and o.pair_pool in all.
std::vector<int> pair_pool(const Catalogue& cat, const std::vector<EffectFit>& fits,
                           const std::vector<int>& order, const CalibrationOptions& o) {
  std::vector<int> pool;
  std::map<EffectKind, int> per_kind;
  for (int i : order) {
    const EffectFit& f = fits[static_cast<size_t>(i)];
    const Candidate& c = cat.candidates[static_cast<size_t>(f.candidate)];
    // A fixed lag has no joint least squares; a per-run air is fitted per run beside the other.
    if (!f.unphysical.empty() || c.fixed || f.score <= 0) continue;
    if (per_kind[f.kind]++ >= o.pair_pool_per_kind) continue;
    pool.push_back(i);
    if (static_cast<int>(pool.size()) >= o.pair_pool) break;
  }
  return pool;
}

/// The best partner of each kind over the whole catalogue for `member`, each candidate fitted
/// jointly with it (pair_fit), as kind -> (score, candidate); only physical pairs, one air at most.
std::map<EffectKind, std::pair<double, int>> best_partners(
    const Catalogue& cat, const std::vector<Whitened>& ws, const std::vector<Eigen::VectorXd>& ys,
    const std::vector<EffectFit>& fits, const EffectFit& member, const Selection& sel,
    const CalibrationOptions& o) {
  const bool member_per_run = cat.candidates[static_cast<size_t>(member.candidate)].per_run;
  std::map<EffectKind, std::pair<double, int>> best_of_kind;
  for (const EffectFit& f : fits) {
    const Candidate& c = cat.candidates[static_cast<size_t>(f.candidate)];
    if (f.candidate == member.candidate || c.fixed || (c.per_run && member_per_run)) continue;
    const PairFit pf = pair_fit(cat, ws, ys, sel.sigma, member, f, sel.null_score, o);
    if (!pf.first.unphysical.empty() || !pf.second.unphysical.empty()) continue;
    const auto it = best_of_kind.find(f.kind);
    if (it == best_of_kind.end() || pf.score > it->second.first)
      best_of_kind[f.kind] = {pf.score, f.candidate};
  }
  return best_of_kind;
}

/// Whether the best admissible pair `best` replaces the greedy claims of `sel`: not when nothing
/// is claimed or a claim is fixed; with two claims, when it beats their own pair by more than the
/// spread of the per-run gains; with one, when it adds more than noise and both floors.
bool pair_overrules(const Catalogue& cat, const std::vector<Whitened>& ws,
                    const std::vector<Eigen::VectorXd>& ys, const std::vector<EffectFit>& fits,
                    const PairFit& best, const Selection& sel, const CalibrationOptions& o) {
  // Nothing claimed (below noise, or undecided in the first round): a pair does not overrule it.
  if (sel.claimed.empty()) return false;
  for (const auto& f : sel.claimed) {
    const Candidate& c = cat.candidates[static_cast<size_t>(f.candidate)];
    if (c.fixed) return false;  // the greedy choice holds what pairs cannot
  }
  auto same = [](const PairFit& p, int a, int b) {
    return (p.first.candidate == a && p.second.candidate == b) ||
           (p.first.candidate == b && p.second.candidate == a);
  };
  if (sel.claimed.size() >= 2) {
    const EffectFit &g0 = sel.claimed[0], &g1 = sel.claimed[1];
    if (same(best, g0.candidate, g1.candidate)) return false;
    // The greedy pair scored the same way (its members from the first round's fits).
    const PairFit greedy = pair_fit(cat, ws, ys, sel.sigma, fits[static_cast<size_t>(g0.candidate)],
                                    fits[static_cast<size_t>(g1.candidate)], sel.null_score, o);
    if (!std::isfinite(greedy.score)) return false;  // two airs: no joint fit to compare with
    if (best.score - greedy.score <= gain_spread(best.fold_gains, greedy.fold_gains)) return false;
  } else if (best.score - sel.claimed[0].score <=
             std::max(sel.null_score, std::max(best.first.floor, best.second.floor))) {
    return false;
  }
  return true;
}

/// The pairs among the first round's best candidates (`fits` in `order`), scored jointly into
/// sel.pairs; the claims replaced by the best admissible pair when it beats the greedy choice.
void choose_pair(const Catalogue& cat, const std::vector<Whitened>& ws,
                 const std::vector<Eigen::VectorXd>& ys, const std::vector<EffectFit>& fits,
                 const std::vector<int>& order, Selection& sel, const CalibrationOptions& o) {
  const std::vector<int> pool = pair_pool(cat, fits, order, o);
  std::vector<PairFit> pairs;
  std::set<std::pair<int, int>> scored;
  auto per_run = [&](int i) {
    return cat.candidates[static_cast<size_t>(fits[static_cast<size_t>(i)].candidate)].per_run;
  };
  auto add_pair = [&](int a, int b) {
    if (a == b || (per_run(a) && per_run(b))) return;  // one air per pair
    if (!scored.insert({std::min(a, b), std::max(a, b)}).second) return;
    pairs.push_back(pair_fit(cat, ws, ys, sel.sigma, fits[static_cast<size_t>(a)],
                             fits[static_cast<size_t>(b)], sel.null_score, o));
  };
  for (size_t x = 0; x < pool.size(); ++x)
    for (size_t y = x + 1; y < pool.size(); ++y) add_pair(pool[x], pool[y]);
  // Each pool member's best partner of each kind over the whole catalogue, each candidate fitted
  // jointly with the member (pair_fit): a partner that the first round ranks low because the
  // member took part of its signal is scored with it too. Found on the residual the member's own
  // fit leaves, the partner is the one that best matches that remainder, not the one that best
  // fits beside the member: an air fitted alone takes part of a heat law's signal (heat that
  // grows with temperature warms the machine slowly, as a drifting air does), and what it leaves
  // favoured a conductivity; a heat law fitted alone takes part of a film's, and what it leaves
  // favoured the bearing's conductivity over the film. A candidate's score alone does not matter.
  for (size_t x = 0; x < pool.size() && static_cast<int>(x) < o.pair_partner_searches; ++x) {
    const int a = pool[x];
    for (const auto& [kind, best] :
         best_partners(cat, ws, ys, fits, fits[static_cast<size_t>(a)], sel, o))
      add_pair(a, best.second);
  }
  std::sort(pairs.begin(), pairs.end(),
            [](const PairFit& a, const PairFit& b) { return a.score > b.score; });
  const auto best =
      std::find_if(pairs.begin(), pairs.end(), [](const PairFit& p) { return p.admissible; });
  sel.pairs.assign(pairs.begin(),
                   pairs.begin() + std::min<std::ptrdiff_t>(5, pairs.end() - pairs.begin()));
  if (best == pairs.end() || !pair_overrules(cat, ws, ys, fits, *best, sel, o)) return;
  const bool swap = best->second.score > best->first.score;
  sel.claimed = {swap ? best->second : best->first, swap ? best->first : best->second};
  sel.by_pair = true;
  sel.ambiguous.clear();  // a later round's indecision is settled by the pair
}

/// The channel on which the two candidates' in-sample responses differ most, in sigmas (RMS over
/// the training runs' samples).
void distinguishing_channel(const Catalogue& cat, const Eigen::VectorXd& sigma, Ambiguity& amb) {
  const Candidate& a = cat.candidates[static_cast<size_t>(amb.first.candidate)];
  const Candidate& b = cat.candidates[static_cast<size_t>(amb.second.candidate)];
  const Eigen::Index nc = sigma.size();
  Eigen::VectorXd ss = Eigen::VectorXd::Zero(nc), count = Eigen::VectorXd::Zero(nc);
  for (size_t ri = 0; ri < cat.runs.size(); ++ri) {
    const Eigen::VectorXd d = a.columns[ri] * fitted_theta(a, amb.first, ri) -
                              b.columns[ri] * fitted_theta(b, amb.second, ri);
    const Eigen::Index ns = cat.runs[ri].times.size();
    for (Eigen::Index ch = 0; ch < nc; ++ch) {
      ss(ch) += d.segment(ch * ns, ns).squaredNorm() / (sigma(ch) * sigma(ch));
      count(ch) += static_cast<double>(ns);
    }
  }
  const Eigen::VectorXd rms = (ss.array() / count.array().max(1.0)).sqrt();
  rms.maxCoeff(&amb.channel);
  amb.channel_difference = rms(amb.channel);
}

}  // namespace

Catalogue with_refined_heat_inputs(const MarchModel& model, const Catalogue& cat,
                                   const CalibrationOptions& o,
                                   const std::vector<EffectFit>& others) {
  Catalogue out = cat;
  if (out.runs.empty()) return out;
  const mesh::TetMesh& m = model.mesh();
  const Eigen::VectorXd sigma = noise_sigma(out.runs, out.readout.sensors, o);
  const auto [ws, all] = whitened_runs(out.runs, sigma);
  const std::vector<Eigen::VectorXd> ys = without_fits(out, ws, all, sigma, others, o);
  const ExteriorFaces ext = exterior_faces(m);
  const double half = o.patch_half_size * o.heat_refine_half_scale;
  std::set<std::pair<HeatLaw, std::vector<int>>> seen;
  double spacing = o.patch_spacing;
  for (int level = 0; level < o.heat_refine_levels; ++level) {
    spacing /= 3;
    std::vector<int> heat;
    for (size_t ci = 0; ci < out.candidates.size(); ++ci)
      if (kind(out.candidates[ci]) == EffectKind::heat_input) heat.push_back(static_cast<int>(ci));
    if (heat.empty()) return out;
    const std::vector<EffectFit> fits = score_all(out, ws, ys, sigma, o, false, heat);
    std::vector<size_t> order(fits.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(),
              [&](size_t a, size_t b) { return fits[a].score > fits[b].score; });
    // The best places (a box scored under both laws counts once), each with its best law.
    std::vector<const HeatInput*> parents;
    for (size_t i : order) {
      const auto& c =
          std::get<HeatInput>(out.candidates[static_cast<size_t>(fits[i].candidate)].effect);
      const Eigen::Vector3d centre = 0.5 * (c.box_min + c.box_max);
      const bool again = std::any_of(parents.begin(), parents.end(), [&](const HeatInput* p) {
        return (0.5 * (p->box_min + p->box_max) - centre).norm() < 1e-9;
      });
      if (!again) parents.push_back(&c);
      if (static_cast<int>(parents.size()) >= o.heat_refine_parents) break;
    }
    std::vector<Candidate> added;
    std::vector<SeparableColumn> sep;
    for (const HeatInput* parent : parents) {
      const Eigen::Vector3d centre = 0.5 * (parent->box_min + parent->box_max);
      std::vector<Eigen::Vector3d> centres;
      for (int i = -1; i <= 1; ++i)
        for (int j = -1; j <= 1; ++j)
          for (int k = -1; k <= 1; ++k)
            centres.push_back(centre + spacing * Eigen::Vector3d(i, j, k));
      for (const Patch& p : box_patches(m, ext, centres, half)) {
        if (!seen.insert({parent->law, p.faces}).second) continue;
        Candidate c = heat_candidate(p, parent->law, parent->ref_speed_rpm);
        sep.push_back(heat_column(m, p, c));
        c.unit_separable = {sep.back()};
        c.unit_weights = {1};
        added.push_back(std::move(c));
      }
    }
    if (added.empty()) break;
    // One march per run with the new patches as columns, as in the catalogue.
    for (const auto& rm : out.runs) {
      const Responses rs = march(model, rm.spec, out.readout, rm.times, sep, {});
      for (size_t k = 0; k < added.size(); ++k)
        added[k].columns.push_back(
            Eigen::Map<const Eigen::VectorXd>(rs.columns[k].data(), rs.columns[k].size()));
    }
    for (auto& c : added) out.candidates.push_back(std::move(c));
  }
  return out;
}

Catalogue with_speed_exponents(const MarchModel& model, const Catalogue& cat, int candidate,
                               const CalibrationOptions& o) {
  Catalogue out = cat;
  const Candidate& parent = cat.candidates.at(static_cast<size_t>(candidate));
  const auto* film = std::get_if<SpeedDependentConvection>(&parent.effect);
  if (!film) return out;
  std::vector<Candidate> added;
  std::vector<LoadColumn> loads;
  for (double x : o.speed_exponent_grid) {
    if (std::abs(x - film->speed_exponent) < 1e-9) continue;
    Candidate c = parent;
    std::get<SpeedDependentConvection>(c.effect).speed_exponent = x;
    c.name = parent.name + " (speed^" + number(x) + ")";
    c.columns.clear();
    for (auto& lc : c.unit_loads) {
      std::get<FilmChange>(lc.form).speed_exponent = x;
      lc.name = c.name;
      loads.push_back(lc);
    }
    added.push_back(std::move(c));
  }
  if (added.empty()) return out;
  // One march per run with every copy's loads as columns; a copy's column sums its loads'.
  for (const auto& rm : out.runs) {
    const Responses rs = march(model, rm.spec, out.readout, rm.times, {}, loads);
    size_t j = 0;
    for (auto& c : added) {
      Eigen::MatrixXd col = Eigen::MatrixXd::Zero(rs.base.rows(), rs.base.cols());
      for (double w : c.unit_weights) col += w * rs.columns[j++];
      c.columns.push_back(Eigen::Map<const Eigen::VectorXd>(col.data(), col.size()));
    }
  }
  for (auto& c : added) out.candidates.push_back(std::move(c));
  return out;
}

Catalogue with_refined_lag(const Catalogue& cat, int sensor, double tau,
                           const CalibrationOptions& o) {
  Catalogue out = cat;
  double lo = tau / 2, hi = tau * 2;
  for (double g : o.lag_grid_s) {
    if (g < tau) lo = std::max(lo, g);
    if (g > tau) hi = std::min(hi, g);
  }
  for (int k = 1; k < o.lag_refine_steps; ++k) {
    const double t = lo * std::pow(hi / lo, static_cast<double>(k) / o.lag_refine_steps);
    if (std::abs(t - tau) > 1e-9 * tau)
      out.candidates.push_back(lag_candidate(out.runs, out.readout, sensor, t));
  }
  return out;
}

namespace {

/// Noise alone: the best score over every candidate on white noise at the estimated level.
double null_score(const Catalogue& cat, const std::vector<Whitened>& ws,
                  const std::vector<Eigen::VectorXd>& ys, const Eigen::VectorXd& sigma,
                  const CalibrationOptions& o) {
  std::mt19937_64 rng = core::generator(o.seed, 7);
  std::normal_distribution<double> normal(0.0, 1.0);
  double best = -1e300;
  for (int trial = 0; trial < o.null_trials; ++trial) {
    std::vector<Eigen::VectorXd> noise;
    for (const auto& y : ys) {
      Eigen::VectorXd e(y.size());
      for (Eigen::Index i = 0; i < e.size(); ++i) e(i) = normal(rng);
      noise.push_back(e);
    }
    for (const auto& f : score_all(cat, ws, noise, sigma, o, false)) best = std::max(best, f.score);
  }
  return best;
}

/// Model-form allowance per channel [whitened SS per sample].
Eigen::VectorXd channel_allowance(const Catalogue& cat, const Eigen::VectorXd& sigma,
                                  const CalibrationOptions& o) {
  const auto& r = cat.readout;
  Eigen::VectorXd allowance(r.channels());
  for (int ch = 0; ch < r.channels(); ++ch) {
    double tol = o.temperature_tolerance_K;
    if (ch >= r.sensors) {
      double ss = 0, cnt = 0;
      for (const auto& rm : cat.runs) {
        ss += rm.base.col(ch).squaredNorm();
        cnt += static_cast<double>(rm.base.rows());
      }
      tol = o.displacement_tolerance_rel * std::sqrt(ss / cnt) + o.displacement_tolerance_m;
    }
    allowance(ch) = (tol / sigma(ch)) * (tol / sigma(ch));
  }
  return allowance;
}

/// What every round of the choice scores against: the catalogue, its whitened runs, the floors.
struct Scoring {
  const Catalogue& cat;
  const std::vector<Whitened>& ws;
  const Selection& sel;  ///< its sigma and null score
  const CalibrationOptions& o;
  /// A resized candidate's fits report the linearised parameters it was found unphysical at.
  const std::map<int, std::vector<double>>& linearised;
  Eigen::VectorXd allowance;
  double total = 0;  ///< the whole training residual [whitened SS]
};

/// Every candidate's fit, and their indices by descending score.
struct Ranked {
  std::vector<EffectFit> fits;
  std::vector<int> order;
};

/// Every candidate scored on the residual `left_of` (what the claims so far leave), with its
/// floor and physical check; `order` ranks them by score.
Ranked evaluated(const Scoring& sc, const std::vector<Eigen::VectorXd>& left_of) {
  const Catalogue& cat = sc.cat;
  const auto& r = cat.readout;
  const CalibrationOptions& o = sc.o;
  Ranked out;
  std::vector<EffectFit>& fits = out.fits;
  fits = score_all(cat, sc.ws, left_of, sc.sel.sigma, o, true);
  for (auto& f : fits)
    if (const auto it = sc.linearised.find(f.candidate); it != sc.linearised.end())
      f.linearised = it->second;
  double left = 0;
  for (const auto& y : left_of) left += y.squaredNorm();
  for (auto& f : fits) {
    const Candidate& c = cat.candidates[f.candidate];
    const std::vector<char> t = touched(c, cat.runs.front().times.size(), r.channels());
    f.floor = 0;
    for (const auto& w : sc.ws)
      for (int ch : w.channel) f.floor += t[static_cast<size_t>(ch)] ? sc.allowance(ch) : 0.0;
    // explained_fraction relative to the whole training residual, not what is left of it.
    f.explained_fraction *= sc.total > 0 ? left / sc.total : 0;
    f.unphysical =
        unphysical_reason(c, f.parameters, f.run_parameters, cat.runs, o, &f.duty_correlation);
  }
  out.order.resize(fits.size());
  for (size_t i = 0; i < out.order.size(); ++i) out.order[i] = static_cast<int>(i);
  std::sort(out.order.begin(), out.order.end(),
            [&](int a, int b) { return fits[a].score > fits[b].score; });
  return out;
}

/// Whether `f` may be claimed: physical, above noise, above its floor and above zero.
bool claimable(const EffectFit& f, double null_score) {
  return f.unphysical.empty() && f.score > null_score && f.score > f.floor && f.score > 0;
}

/// The first round's ranking: the best fit at each place, best first, at most o.ranking_size.
std::vector<EffectFit> ranking(const Catalogue& cat, const Ranked& first,
                               const CalibrationOptions& o) {
  std::vector<EffectFit> out;
  std::vector<const Candidate*> places;
  for (int i : first.order) {
    const Candidate& c = cat.candidates[i];
    if (std::any_of(places.begin(), places.end(),
                    [&](const Candidate* p) { return same_place(*p, c); }))
      continue;
    places.push_back(&c);
    out.push_back(first.fits[i]);
    if (static_cast<int>(out.size()) >= o.ranking_size) break;
  }
  return out;
}

/// The claims chosen one after the other into sel.claimed (an undecided round into sel.ambiguous):
/// the best physical candidate, claimed when it beats noise and floor and no candidate of another
/// kind that would be claimed too comes within the spread of their per-run gains; its fit removed
/// before the next round. Returns the first round's fits (and sets sel.ranking from them).
Ranked claimed_greedily(const Scoring& sc, const std::vector<Eigen::VectorXd>& ys, Selection& sel) {
  const Catalogue& cat = sc.cat;
  const CalibrationOptions& o = sc.o;
  std::vector<Eigen::VectorXd> current = ys;
  Ranked first;
  for (int round = 0; round < o.max_effects; ++round) {
    const Ranked ranked = evaluated(sc, current);
    const std::vector<EffectFit>& fits = ranked.fits;
    const std::vector<int>& order = ranked.order;
    if (round == 0) {
      first = ranked;
      sel.ranking = ranking(cat, first, o);
    }
    const auto best_at =
        std::find_if(order.begin(), order.end(), [&](int i) { return fits[i].unphysical.empty(); });
    if (best_at == order.end() || !claimable(fits[*best_at], sel.null_score)) break;
    const EffectFit& best = fits[*best_at];
    const auto second_at = std::find_if(best_at + 1, order.end(), [&](int i) {
      return fits[i].kind != best.kind && claimable(fits[i], sel.null_score);
    });
    if (second_at != order.end()) {
      Ambiguity amb{best, fits[*second_at]};
      amb.difference = best.score - amb.second.score;
      amb.spread = gain_spread(best.fold_gains, amb.second.fold_gains);
      if (amb.difference < amb.spread) {
        distinguishing_channel(cat, sel.sigma, amb);
        sel.ambiguous.push_back(std::move(amb));
        break;
      }
    }
    sel.claimed.push_back(best);
    // Remove the claimed effect's in-sample fit before looking for the next one.
    current = without_fits(cat, sc.ws, std::move(current), sel.sigma, {best}, o);
  }
  return first;
}

/// Backfitting: each claim's place and size chosen again among the candidates of its kind on the
/// training residual with the other claims' fits removed, until no claim changes. A claim that
/// took part of a later one's signal (a heat input placed where an offset sensor pulls it) is
/// then placed where the rest of the data puts it, and every claim is sized beside the others,
/// not before them. A claim is replaced only when its replacement scores above it by more than
/// the noise threshold and the spread of their per-run gains (the ambiguity rule's margin). The
/// kinds stay the one-after-the-other choice's: letting them change made claims of kinds that
/// share a signal (an air, a heat law, a conductivity) swap from sweep to sweep, and put a
/// conductivity first where an air and a heat law were true (docs/calibration.md, §3).
void backfit(const Scoring& sc, const std::vector<Eigen::VectorXd>& ys, Selection& sel) {
  const Catalogue& cat = sc.cat;
  const CalibrationOptions& o = sc.o;
  std::set<std::vector<int>> visited;
  for (int sweep = 0; sweep < o.backfit_sweeps && sel.claimed.size() >= 2; ++sweep) {
    bool changed = false;
    std::vector<int> state;
    for (const auto& f : sel.claimed) state.push_back(f.candidate);
    if (!visited.insert(state).second) break;  // a cycle: keep where it is
    for (size_t i = 0; i < sel.claimed.size(); ++i) {
      std::vector<EffectFit> others;
      for (size_t j = 0; j < sel.claimed.size(); ++j)
        if (j != i) others.push_back(sel.claimed[j]);
      const Ranked ranked = evaluated(sc, without_fits(cat, sc.ws, ys, sel.sigma, others, o));
      const std::vector<EffectFit>& fits = ranked.fits;
      const std::vector<int>& order = ranked.order;
      const auto best_at = std::find_if(order.begin(), order.end(), [&](int k) {
        return fits[static_cast<size_t>(k)].kind == sel.claimed[i].kind &&
               claimable(fits[static_cast<size_t>(k)], sel.null_score) &&
               std::none_of(others.begin(), others.end(), [&](const EffectFit& f) {
                 return f.candidate == fits[static_cast<size_t>(k)].candidate;
               });
      });
      if (best_at == order.end()) {
        // Nothing of its kind beats noise and floor beside the others, itself included. A
        // per-run air among them is fitted on each run alone here and takes what it can of this
        // claim's share (an air and the mechanism it shadows are sized only jointly, as a pair),
        // so then that shows nothing and the claim is kept.
        if (std::any_of(others.begin(), others.end(), [&](const EffectFit& f) {
              return cat.candidates[static_cast<size_t>(f.candidate)].per_run;
            }))
          continue;
        // Otherwise the claim explains nothing they leave (a second heat input that took an
        // offset sensor's signal, once the offset is claimed): dropped, as the greedy rule would
        // not claim it.
        sel.backfit_replaced.push_back({sel.claimed[i].name, ""});
        sel.claimed.erase(sel.claimed.begin() + static_cast<std::ptrdiff_t>(i));
        changed = true;
        break;
      }
      const EffectFit* chosen = &fits[static_cast<size_t>(*best_at)];
      const EffectFit& now = fits[static_cast<size_t>(sel.claimed[i].candidate)];
      if (chosen->candidate != now.candidate && claimable(now, sel.null_score) &&
          chosen->score - now.score <=
              std::max(sel.null_score, gain_spread(chosen->fold_gains, now.fold_gains)))
        chosen = &now;
      const EffectFit& best = *chosen;
      if (best.candidate != sel.claimed[i].candidate) {
        sel.backfit_replaced.push_back({sel.claimed[i].name, best.name});
        changed = true;
      }
      sel.claimed[i] = best;
    }
    if (!changed) break;
  }
}

}  // namespace

Selection select_effects(const Catalogue& given, const CalibrationOptions& o,
                         const Resizer& resize) {
  if (given.runs.size() < 2)
    throw core::DataError(
        "calibration needs at least two training runs (got " + std::to_string(given.runs.size()) +
        "): effects are chosen by how much they explain on a run held out from the fit");
  std::map<int, std::vector<double>> linearised;
  const std::optional<Catalogue> resized =
      resize ? resized_catalogue(given, o, resize, linearised) : std::nullopt;
  const Catalogue& cat = resized ? *resized : given;
  Selection sel;
  sel.sigma = noise_sigma(cat.runs, cat.readout.sensors, o);
  const auto [ws, ys] = whitened_runs(cat.runs, sel.sigma);
  for (const auto& y : ys) sel.residual_ss += y.squaredNorm();
  sel.null_score = null_score(cat, ws, ys, sel.sigma, o);
  const Scoring sc{
      cat, ws, sel, o, linearised, channel_allowance(cat, sel.sigma, o), sel.residual_ss};
  const Ranked first = claimed_greedily(sc, ys, sel);
  backfit(sc, ys, sel);
  if (o.max_effects >= 2 && !first.fits.empty())
    choose_pair(cat, ws, ys, first.fits, first.order, sel, o);
  return sel;
}

}  // namespace tt::calibration
