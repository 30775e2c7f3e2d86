#include "calibration/generator.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <tuple>

#include "calibration/calibrate.hpp"
#include "core/errors.hpp"
#include "core/rng.hpp"
#include "core/units.hpp"
#include "mesh/mesher.hpp"
#include "solvers/elastic.hpp"
#include "solvers/loads.hpp"
#include "solvers/thermal.hpp"

namespace tt::calibration {

namespace {

double uniform(std::mt19937_64& rng, double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(rng);
}
double log_uniform(std::mt19937_64& rng, double a, double b) {
  return std::exp(uniform(rng, std::log(a), std::log(b)));
}
int pick(std::mt19937_64& rng, int n) {
  return std::uniform_int_distribution<int>(0, n - 1)(rng);
}
double signed_factor(std::mt19937_64& rng, double lo, double hi) {
  const double f = uniform(rng, lo, hi);
  return pick(rng, 2) ? f : -f / (1 + f);  // +f or the matching decrease
}

int point_node(const mesh::TetMesh& m, const std::string& id) {
  for (const auto& p : m.points)
    if (p.id == id) return p.node;
  throw core::DataError("generator: named point '" + id +
                        "' is not in the mesh; expected one of the case's points");
}

/// A smooth random air signal [K, change from the run's start]: a drift plus two slow waves,
/// every 300 s up to `end`.
core::TimeTable waves_air(double magnitude, std::uint64_t seed, int run_index, double end) {
  std::mt19937_64 rng = core::generator(seed, static_cast<std::uint64_t>(run_index));
  const double drift = uniform(rng, -1, 1), ph1 = uniform(rng, 0, 6.3), ph2 = uniform(rng, 0, 6.3);
  const double p1 = uniform(rng, 7200, 14400), p2 = uniform(rng, 2400, 5400);
  core::TimeTable t;
  for (double x = 0; x <= end + 1e-9; x += 300) {
    const double v = drift * x / std::max(end, 1.0) + 0.7 * std::sin(6.2832 * x / p1 + ph1) +
                     0.3 * std::sin(6.2832 * x / p2 + ph2) -
                     (0.7 * std::sin(ph1) + 0.3 * std::sin(ph2));
    t.time.push_back(x);
    t.value.push_back(v * magnitude);
  }
  return t;
}

}  // namespace

core::CaseSpec generator_case(const core::CaseSpec& declared, const GeneratorOptions& o) {
  core::CaseSpec s = declared;
  for (auto& b : s.bodies) b.max_edge *= o.mesh_scale;
  s.mesh.circle_segments = static_cast<int>(std::lround(s.mesh.circle_segments / o.mesh_scale));
  s.thermal.step = o.step_s;
  s.thermal.output_interval = o.step_s;
  s.outputs.fields = false;
  return s;
}

core::DutyCycle random_duty_cycle(double hours, std::mt19937_64& rng) {
  core::DutyCycle d;
  d.end = hours * 3600;
  const double speeds[] = {1500, 2000, 3000, 4000};
  double t = 0;
  bool running = true;
  while (t < d.end) {
    d.segments.push_back({t, running ? speeds[pick(rng, 4)] : 0.0});
    t += 300.0 * (1 + pick(rng, 6));
    running = !running || pick(rng, 3) == 0;
  }
  return d;
}

namespace {

/// A heat input's place drawn into `e`: a box around a random point of the housing's unfixed
/// exterior, sized at random, with its magnitude [W], groups, area and centre.
void draw_heat_box(InjectedEffect& e, const core::CaseSpec& declared, const mesh::TetMesh& m,
                   std::mt19937_64& rng) {
  std::vector<int> faces;
  std::vector<double> cum;
  double total = 0;
  for (Eigen::Index f = 0; f < m.faces.rows(); ++f) {
    const int g = core::index_of(m.face_group[f]);
    if (m.face_other_tet[f] >= 0 || g < 0) continue;
    const auto& fixed = declared.mechanical.fixed_groups;
    if (std::find(fixed.begin(), fixed.end(), g) != fixed.end()) continue;
    if (m.region_names[core::index_of(m.tet_region[m.face_tet[f]])] != declared.bodies.front().name)
      continue;
    const Eigen::Vector3d a = m.nodes.row(m.faces(f, 0)), b = m.nodes.row(m.faces(f, 1)),
                          c = m.nodes.row(m.faces(f, 2));
    total += 0.5 * (b - a).cross(c - a).norm();
    faces.push_back(static_cast<int>(f));
    cum.push_back(total);
  }
  const double u = uniform(rng, 0, total);
  const int f = faces[std::lower_bound(cum.begin(), cum.end(), u) - cum.begin()];
  const Eigen::Vector3d p =
      (m.nodes.row(m.faces(f, 0)) + m.nodes.row(m.faces(f, 1)) + m.nodes.row(m.faces(f, 2))) / 3;
  Eigen::Vector3d half(uniform(rng, 0.03, 0.06), uniform(rng, 0.03, 0.06),
                       uniform(rng, 0.03, 0.06));
  e.box_min = p - half;
  e.box_max = p + half;
  e.magnitude = log_uniform(rng, 4, 25);  // W
  // The faces whose centroid is in the box (the case format's rule) give area and centre.
  Eigen::Vector3d wc = Eigen::Vector3d::Zero();
  for (int k : faces) {
    const Eigen::Vector3d a = m.nodes.row(m.faces(k, 0)), b = m.nodes.row(m.faces(k, 1)),
                          c = m.nodes.row(m.faces(k, 2));
    const Eigen::Vector3d g = (a + b + c) / 3;
    if ((g.array() < e.box_min.array()).any() || (g.array() > e.box_max.array()).any()) continue;
    const double ar = 0.5 * (b - a).cross(c - a).norm();
    const std::string gname = m.group_names[core::index_of(m.face_group[k])];
    if (std::find(e.groups.begin(), e.groups.end(), gname) == e.groups.end())
      e.groups.push_back(gname);
    e.area += ar;
    wc += ar * g;
  }
  e.centre = wc / e.area;
}

}  // namespace

InjectedEffects random_effect_of_each_kind(const core::CaseSpec& declared,
                                           const mesh::TetMesh& mesh,
                                           const std::vector<std::string>& sensor_ids,
                                           std::mt19937_64& rng) {
  InjectedEffects out;
  for (int k = 0; k <= static_cast<int>(EffectKind::sensor_lag); ++k)
    out.push_back(random_effect(static_cast<EffectKind>(k), declared, mesh, sensor_ids, rng));
  return out;
}

InjectedEffect random_effect(EffectKind kind, const core::CaseSpec& declared,
                             const mesh::TetMesh& m, const std::vector<std::string>& sensors,
                             std::mt19937_64& rng) {
  InjectedEffect e;
  e.present = true;
  e.kind = kind;
  e.seed = rng();
  const auto& conv = declared.thermal.convection;
  std::vector<int> unfixed;
  for (size_t c = 0; c < conv.size(); ++c) {
    const auto& f = declared.mechanical.fixed_groups;
    if (std::find(f.begin(), f.end(), conv[c].group) == f.end())
      unfixed.push_back(static_cast<int>(c));
  }
  switch (kind) {
    case EffectKind::ambient_temperature:
      e.magnitude = log_uniform(rng, 0.3, 2.5);
      break;
    case EffectKind::heat_input:
      draw_heat_box(e, declared, m, rng);
      e.follows_speed = pick(rng, 2) == 1;
      break;
    case EffectKind::speed_dependent_convection: {
      const int c = unfixed[static_cast<size_t>(pick(rng, static_cast<int>(unfixed.size())))];
      e.target = declared.groups[conv[c].group].name;
      e.magnitude = conv[c].h * log_uniform(rng, 1.5, 5);  // gain at 3000 rpm [W/(m2 K)]
      break;
    }
    case EffectKind::temperature_dependent_heat: {
      const int s = pick(rng, static_cast<int>(declared.thermal.sources.size()));
      e.target = declared.thermal.sources[s].name;
      e.magnitude = log_uniform(rng, 0.02, 0.08);
      break;
    }
    case EffectKind::boundary_conductance: {
      const int c = pick(rng, static_cast<int>(conv.size()));
      e.target = declared.groups[conv[c].group].name;
      e.magnitude = signed_factor(rng, 0.6, 2.0);
      break;
    }
    case EffectKind::material_parameter: {
      // The materials of the two largest bodies (housing, shaft), where a wrong value matters.
      const int body = pick(rng, std::min(2, static_cast<int>(declared.bodies.size())));
      const int mi = declared.bodies[body].material;
      const auto field =
          static_cast<size_t>(pick(rng, static_cast<int>(kMaterialFieldNames.size())));
      e.target = declared.materials[mi].name + "." + std::string(kMaterialFieldNames[field].name);
      // Within the calibrator's physical bounds (a factor of 1.5 either way), with room for the
      // linearised fit's error.
      e.magnitude = signed_factor(rng, 0.15, 0.4);
      break;
    }
    case EffectKind::sensor_offset:
      e.target = sensors[static_cast<size_t>(pick(rng, static_cast<int>(sensors.size())))];
      e.magnitude = (pick(rng, 2) ? 1 : -1) * log_uniform(rng, 0.15, 1.0);
      break;
    case EffectKind::sensor_lag:
      e.target = sensors[static_cast<size_t>(pick(rng, static_cast<int>(sensors.size())))];
      e.magnitude = uniform(rng, 120, 600);
      break;
  }
  return e;
}

namespace {

/// The injected air `e` of run `run_index` added to the sinks of `s` it acts on (its target's, or
/// every unfixed group's).
void add_injected_air(core::CaseSpec& s, const InjectedEffect& e, const core::DutyCycle& duty,
                      int run_index) {
  auto& conv = s.thermal.convection;
  auto on = [&](const core::Convection& c) {
    if (!e.target.empty()) return s.groups[c.group].name == e.target;
    const auto& f = s.mechanical.fixed_groups;
    return std::find(f.begin(), f.end(), c.group) == f.end();
  };
  const core::TimeTable t = e.air == InjectedEffect::Air::shop_day
                                ? shop_day_air(e.magnitude, e.seed, run_index, duty.end)
                                : waves_air(e.magnitude, e.seed, run_index, duty.end);
  for (auto& c : conv) {
    if (!on(c)) continue;
    core::TimeTable own = t;
    for (size_t k = 0; k < own.time.size(); ++k)
      own.value[k] += solvers::table_value(c.sink, own.time[k]);
    c.sink = own;
  }
}

/// The injected heat input `e` declared in `s`: every group the box covers gets its part (the
/// case format's way to put heat on faces).
void add_injected_heat(core::CaseSpec& s, const InjectedEffect& e) {
  HeatInput h;
  h.box_min = e.box_min;
  h.box_max = e.box_max;
  h.law = e.follows_speed ? HeatLaw::speed : HeatLaw::constant;
  h.ref_speed_rpm = 3000;
  h.body = 0;  // the housing's faces only: its area and centre are those of the housing's faces
  // The drawn effect names its groups (InjectedEffect is written as truth.json).
  for (const auto& name : e.groups)
    for (size_t g = 0; g < s.groups.size(); ++g)
      if (s.groups[g].name == name) h.groups.push_back(static_cast<int>(g));
  Candidate c;
  c.effect = h;
  AugmentedCase a{s, {}, {}};
  a = augmented_case(a, c, {e.magnitude / e.area}, Readout{});
  s = a.spec;
}

}  // namespace

core::CaseSpec truth_case(const core::CaseSpec& gen, const InjectedEffect& e,
                          const core::DutyCycle& duty, int run_index) {
  core::CaseSpec s = gen;
  s.duty_cycle = duty;
  if (!e.present) return s;
  auto& conv = s.thermal.convection;
  auto entry_of = [&](const std::string& group) -> core::Convection& {
    for (auto& c : conv)
      if (s.groups[c.group].name == group) return c;
    throw core::DataError("generator: no convection on group '" + group + "'");
  };
  switch (e.kind) {
    case EffectKind::ambient_temperature:
      add_injected_air(s, e, duty, run_index);
      break;
    case EffectKind::heat_input:
      add_injected_heat(s, e);
      break;
    case EffectKind::speed_dependent_convection: {
      auto& c = entry_of(e.target);
      c.h_speed_gain = e.magnitude;
      c.speed_ref_rpm = 3000;
      c.speed_exponent = e.speed_exponent;
      break;
    }
    case EffectKind::temperature_dependent_heat:
      for (auto& src : s.thermal.sources)
        if (src.name == e.target) src.temperature_coefficient = e.magnitude;
      break;
    case EffectKind::boundary_conductance:
      entry_of(e.target).h *= 1 + e.magnitude;
      break;
    case EffectKind::material_parameter: {
      const auto dot = e.target.find('.');
      const std::string name = e.target.substr(0, dot), field = e.target.substr(dot + 1);
      const std::optional<MaterialField> f = core::value_in(kMaterialFieldNames, field);
      if (!f)
        throw std::invalid_argument("injected material_parameter target '" + e.target +
                                    "': field '" + field + "' is not " +
                                    core::names_list(kMaterialFieldNames));
      for (auto& mat : s.materials)
        if (mat.name == name) material_value(mat, *f) *= 1 + e.magnitude;
      break;
    }
    case EffectKind::sensor_offset:
    case EffectKind::sensor_lag:
      break;  // applied to the readings
  }
  return s;
}

core::CaseSpec truth_case(const core::CaseSpec& gen, const InjectedEffects& effects,
                          const core::DutyCycle& duty, int run_index) {
  core::CaseSpec s = truth_case(gen, InjectedEffect{}, duty, run_index);
  for (const auto& e : effects) s = truth_case(s, e, duty, run_index);
  return s;
}

core::TimeTable shop_day_air(double magnitude, std::uint64_t seed, int run_index, double end) {
  std::mt19937_64 rng = core::generator(seed, static_cast<std::uint64_t>(run_index));
  const double start_h = uniform(rng, 6, 12);
  const double hvac_period = uniform(rng, 1200, 2400), hvac_amp = uniform(rng, 0.05, 0.2),
               hvac_phase = uniform(rng, 0, 1);
  struct Door {
    double at, drop, tau;
  };
  std::vector<Door> doors;
  for (double t = 0; t < end;) {
    t += std::exponential_distribution<double>(1.0 / 7200)(rng);
    if (t < end) doors.push_back({t, uniform(rng, 0.2, 0.6), uniform(rng, 600, 1200)});
  }
  auto air = [&](double t) {
    const double h = start_h + t / 3600;
    // Coolest at 4, warmest at 15 o'clock: a day warms faster than it cools.
    const double phase = std::fmod(h - 4 + 24, 24);
    const double daily =
        phase < 11 ? -std::cos(3.14159265 * phase / 11) : std::cos(3.14159265 * (phase - 11) / 13);
    const double saw = std::fmod(t / hvac_period + hvac_phase, 1.0);
    double v = magnitude * daily + hvac_amp * (4 * std::abs(saw - 0.5) - 1);
    for (const auto& d : doors)
      if (t >= d.at) v -= d.drop * std::exp(-(t - d.at) / d.tau);
    return v;
  };
  core::TimeTable out;
  const double v0 = air(0);
  for (double t = 0; t <= end + 1e-9; t += 60) {
    out.time.push_back(t);
    out.value.push_back(air(t) - v0);
  }
  return out;
}

InjectedEffects random_effects_in_several_places(EffectKind kind, const core::CaseSpec& declared,
                                                 const mesh::TetMesh& m,
                                                 const std::vector<std::string>& sensors,
                                                 std::mt19937_64& rng) {
  InjectedEffects out;
  const int want =
      kind == EffectKind::sensor_offset || kind == EffectKind::speed_dependent_convection
          ? 2 + pick(rng, 2)
          : 2;
  // A part that acts where another already does is drawn again.
  auto overlaps = [](const InjectedEffect& a, const InjectedEffect& b) {
    if (a.kind == EffectKind::heat_input)
      return !((a.box_max.array() < b.box_min.array()).any() ||
               (b.box_max.array() < a.box_min.array()).any());
    return a.target == b.target;
  };
  switch (kind) {
    case EffectKind::ambient_temperature: {
      // One shop's day, felt by each unfixed group's air with its own amplitude.
      InjectedEffect e = random_effect(kind, declared, m, sensors, rng);
      e.air = InjectedEffect::Air::shop_day;
      e.magnitude = uniform(rng, 1, 3);
      const auto& fixed = declared.mechanical.fixed_groups;
      for (const auto& c : declared.thermal.convection) {
        if (std::find(fixed.begin(), fixed.end(), c.group) != fixed.end()) continue;
        InjectedEffect part = e;
        part.target = declared.groups[c.group].name;
        if (!out.empty()) part.magnitude *= uniform(rng, 0.5, 1.2);
        out.push_back(part);
      }
      return out;
    }
    case EffectKind::temperature_dependent_heat:
      for (const auto& src : declared.thermal.sources) {
        InjectedEffect e = random_effect(kind, declared, m, sensors, rng);
        e.target = src.name;
        out.push_back(e);
      }
      return out;
    default:
      break;
  }
  for (int tries = 0; static_cast<int>(out.size()) < want && tries < 50; ++tries) {
    InjectedEffect e = random_effect(kind, declared, m, sensors, rng);
    if (std::any_of(out.begin(), out.end(), [&](const auto& o) { return overlaps(o, e); }))
      continue;
    if (kind == EffectKind::speed_dependent_convection) e.speed_exponent = uniform(rng, 0.5, 0.9);
    if (kind == EffectKind::heat_input && !out.empty())
      e.follows_speed = !out.front().follows_speed;  // one of each law
    out.push_back(e);
  }
  return out;
}

io::MeasuredRun clean_run(const mesh::TetMesh& mesh_in, const core::CaseSpec& truth,
                          const InjectedEffect& e, const Instrumentation& inst,
                          const GeneratorOptions& o, const std::string& name) {
  return clean_run(mesh_in, truth, InjectedEffects{e}, inst, o, name);
}

namespace {

/// `x` (a sensor's true temperature on the truth's fine times `fine_t` [s]) as sensor `id` reads
/// it: with its injected lag and offset in `effects`.
Eigen::VectorXd sensed(Eigen::VectorXd x, const Eigen::VectorXd& fine_t,
                       const InjectedEffects& effects, const std::string& id) {
  const Eigen::Index nt = fine_t.size();
  for (const InjectedEffect& e : effects) {
    if (!e.present || e.target != id) continue;
    if (e.kind == EffectKind::sensor_lag) {
      // The sensor's own first-order lag, integrated on the truth's fine time grid.
      Eigen::VectorXd y(nt);
      y(0) = x(0);
      for (Eigen::Index k = 1; k < nt; ++k) {
        const double a = std::exp(-(fine_t(k) - fine_t(k - 1)) / e.magnitude);
        y(k) = a * y(k - 1) + (1 - a) * 0.5 * (x(k) + x(k - 1));
      }
      x = y;
    }
    if (e.kind == EffectKind::sensor_offset) x.array() += e.magnitude;
  }
  return x;
}

/// `run` with an ambient sensor "AIR" reading the sink of the truth's first unfixed convection
/// entry at its sample times.
void add_ambient_sensor(io::MeasuredRun& run, const core::CaseSpec& truth) {
  const Eigen::Index ns = run.time.size();
  const auto& fixed = truth.mechanical.fixed_groups;
  const auto air = std::find_if(
      truth.thermal.convection.begin(), truth.thermal.convection.end(),
      [&](const auto& c) { return std::find(fixed.begin(), fixed.end(), c.group) == fixed.end(); });
  if (air == truth.thermal.convection.end())
    throw core::DataError(
        "generator: an ambient sensor needs a convection entry on a group "
        "that is not fixed (the air); the case has none");
  const Eigen::Index k = run.temperature.cols();
  run.temperature.conservativeResize(ns, k + 1);
  for (Eigen::Index i = 0; i < ns; ++i)
    run.temperature(i, k) = solvers::table_value(air->sink, run.time(i)) + core::kCelsiusOffset;
  run.sensors.push_back({"AIR", std::nullopt});
  run.ambient_sensor = "AIR";
}

/// Whether `a` and `b` give the same elastic model and probes on one mesh: the same materials,
/// supports, fixed groups, reference temperature, TCP and axis points.
bool same_elastic_inputs(const core::CaseSpec& a, const core::CaseSpec& b) {
  const auto fields = [](const core::Material& m) {
    return std::tie(m.name, m.density, m.specific_heat, m.conductivity, m.youngs_modulus,
                    m.poisson_ratio, m.expansion);
  };
  const auto support = [](const core::PointSupport& p) { return std::tie(p.point, p.fixed); };
  const auto& ma = a.mechanical;
  const auto& mb = b.mechanical;
  return std::equal(a.materials.begin(), a.materials.end(), b.materials.begin(), b.materials.end(),
                    [&](const auto& x, const auto& y) { return fields(x) == fields(y); }) &&
         std::equal(ma.point_supports.begin(), ma.point_supports.end(), mb.point_supports.begin(),
                    mb.point_supports.end(),
                    [&](const auto& x, const auto& y) { return support(x) == support(y); }) &&
         std::tie(ma.enabled, ma.reference_temperature_c, ma.fixed_groups, ma.tcp_point,
                  ma.axis_points) == std::tie(mb.enabled, mb.reference_temperature_c,
                                              mb.fixed_groups, mb.tcp_point, mb.axis_points);
}

std::vector<std::string> group_names(const core::CaseSpec& spec) {
  std::vector<std::string> names;
  for (const auto& g : spec.groups) names.push_back(g.name);
  return names;
}

/// `run` with the machine's displacement probes (from the history's first column at the samples
/// `at`); none when it has none.
void add_probes(io::MeasuredRun& run, const TruthMachine& machine,
                const solvers::ThermalHistory& th, const std::vector<Eigen::Index>& at) {
  const Eigen::Index ns = static_cast<Eigen::Index>(at.size());
  run.displacement.resize(ns, static_cast<Eigen::Index>(machine.probe_influence.size()));
  run.displacements = machine.probes;
  for (size_t p = 0; p < machine.probe_influence.size(); ++p) {
    const Eigen::VectorXd& a = machine.probe_influence[p];
    const double u0 = a.dot(th.temperature.col(0));
    for (Eigen::Index i = 0; i < ns; ++i)
      run.displacement(i, static_cast<Eigen::Index>(p)) = a.dot(th.temperature.col(at[i])) - u0;
  }
}

}  // namespace

TruthMachine truth_machine(const mesh::TetMesh& mesh_in, const core::CaseSpec& truth,
                           const Instrumentation& inst) {
  TruthMachine machine;
  // A heat input adds boundary groups: the faces must carry the truth's own group labels, or its
  // flux and convection land on whatever group had that index before (same nodes: groups do not
  // change TetGen's input).
  machine.mesh = group_names(truth) != mesh_in.group_names ? mesh::mesh_case(truth) : mesh_in;
  machine.truth = truth;
  machine.instrumentation = inst;
  if (!inst.tcp_probes || !truth.mechanical.enabled || truth.mechanical.tcp_point.empty())
    return machine;
  // The TCP's, then (axis_probes) each axis point's: the point's displacement in x, y, z.
  std::vector<std::pair<std::string, std::string>> points{{truth.mechanical.tcp_point, ""}};
  if (inst.axis_probes)
    for (const auto& id : truth.mechanical.axis_points) points.emplace_back(id, id + "_");
  const char* directions[] = {"dx", "dy", "dz"};
  // A solve per probe, not one block solve: a block's rounding depends on its width, and the
  // TCP's readings must not change with the axis points asked beside them.
  const solvers::ElasticModel model(machine.mesh, truth);
  for (const auto& [id, prefix] : points) {
    const int node = point_node(machine.mesh, id);
    const Eigen::Vector3d position = machine.mesh.nodes.row(node).transpose();
    for (int d = 0; d < 3; ++d) {
      machine.probe_influence.push_back(model.influence(node, d));
      machine.probes.push_back({prefix + directions[d], position, Eigen::Vector3d::Unit(d)});
    }
  }
  return machine;
}

bool serves(const TruthMachine& machine, const core::CaseSpec& truth) {
  return group_names(truth) == machine.mesh.group_names &&
         same_elastic_inputs(truth, machine.truth);
}

const TruthMachine& machine_for(std::optional<TruthMachine>& kept, const mesh::TetMesh& mesh,
                                const core::CaseSpec& truth, const Instrumentation& inst) {
  if (!kept || !serves(*kept, truth)) kept = truth_machine(mesh, truth, inst);
  return *kept;
}

io::MeasuredRun clean_run(const mesh::TetMesh& mesh_in, const core::CaseSpec& truth,
                          const InjectedEffects& effects, const Instrumentation& inst,
                          const GeneratorOptions& o, const std::string& name) {
  return clean_run(truth_machine(mesh_in, truth, inst), truth, effects, o, name);
}

io::MeasuredRun clean_run(const TruthMachine& machine, const core::CaseSpec& truth,
                          const InjectedEffects& effects, const GeneratorOptions& o,
                          const std::string& name) {
  if (!serves(machine, truth))
    throw std::invalid_argument("generator: run '" + name +
                                "' has other boundary groups, materials or mechanical settings "
                                "than the truth its machine was built for");
  const mesh::TetMesh& m = machine.mesh;
  const Instrumentation& inst = machine.instrumentation;
  const solvers::FullThermalSystem ops = solvers::thermal_system(m, truth);
  const solvers::ThermalHistory th = solvers::thermal_history(
      m, truth, ops, {}, {}, {o.source_tolerance_K}, machine.factors.get());
  io::MeasuredRun run;
  run.machine = truth.machine;
  // The mesh's extent: readers check every position against it (meta.json machine_box_m).
  run.machine_box = Eigen::AlignedBox3d(m.nodes.colwise().minCoeff().transpose(),
                                        m.nodes.colwise().maxCoeff().transpose());
  run.run = name;
  run.inputs = {"speed_rpm"};
  run.initial_temperature_c = truth.thermal.initial_temperature_c;
  run.nominal_ambient_c =
      truth.thermal.convection.empty() ? 20.0 : truth.thermal.convection.front().sink.value.front();
  run.meta = {{"generator", "thermotwin calibration generator"}};
  const Eigen::Index nt = static_cast<Eigen::Index>(th.times.size());
  std::vector<Eigen::Index> at;  // history columns at the logger's samples
  for (Eigen::Index k = 0; k < nt; ++k) {
    const double q = th.times[k] / o.sample_interval_s;
    if (std::abs(q - std::round(q)) < 1e-6) at.push_back(k);
  }
  const Eigen::Index ns = static_cast<Eigen::Index>(at.size());
  run.time.resize(ns);
  run.input_values.resize(ns, 1);
  for (Eigen::Index i = 0; i < ns; ++i) {
    run.time(i) = th.times[at[i]];
    run.input_values(i, 0) = solvers::speed_at(truth.duty_cycle, run.time(i));
  }
  Eigen::VectorXd fine_t(nt);
  for (Eigen::Index k = 0; k < nt; ++k) fine_t(k) = th.times[k];
  run.temperature.resize(ns, static_cast<Eigen::Index>(inst.sensor_points.size()));
  for (size_t s = 0; s < inst.sensor_points.size(); ++s) {
    const int node = point_node(m, inst.sensor_points[s]);
    run.sensors.push_back({inst.sensor_points[s], m.points[0].position});
    for (const auto& p : m.points)
      if (p.id == inst.sensor_points[s]) run.sensors.back().position = p.position;
    const Eigen::VectorXd x =
        sensed(th.temperature.row(node).transpose(), fine_t, effects, inst.sensor_points[s]);
    for (Eigen::Index i = 0; i < ns; ++i)
      run.temperature(i, static_cast<Eigen::Index>(s)) = x(at[i]);
  }
  if (inst.ambient_sensor) add_ambient_sensor(run, truth);
  add_probes(run, machine, th, at);
  return run;
}

io::MeasuredRun with_noise(const io::MeasuredRun& clean, const GeneratorOptions& o,
                           std::mt19937_64& rng) {
  io::MeasuredRun run = clean;
  std::normal_distribution<double> normal(0.0, 1.0);
  auto quantise = [](double v, double q) { return q > 0 ? q * std::round(v / q) : v; };
  for (Eigen::Index s = 0; s < run.temperature.cols(); ++s) {
    double drift = 0;
    for (Eigen::Index i = 0; i < run.time.size(); ++i) {
      const double dt = i ? run.time(i) - run.time(i - 1) : 0.0;
      const double a = std::exp(-dt / 600.0);
      drift = a * drift + std::sqrt(1 - a * a) * o.drift_temperature_K * normal(rng);
      run.temperature(i, s) = quantise(run.temperature(i, s) - core::kCelsiusOffset +
                                           o.noise_temperature_K * normal(rng) + drift,
                                       o.quantum_temperature_K) +
                              core::kCelsiusOffset;
    }
  }
  for (Eigen::Index p = 0; p < run.displacement.cols(); ++p)
    for (Eigen::Index i = 0; i < run.time.size(); ++i)
      run.displacement(i, p) = quantise(
          run.displacement(i, p) + o.noise_displacement_m * normal(rng), o.quantum_displacement_m);
  return run;
}

io::MeasuredRun synthetic_run(const mesh::TetMesh& m, const core::CaseSpec& truth,
                              const InjectedEffect& e, const Instrumentation& inst,
                              const GeneratorOptions& o, const std::string& name,
                              std::mt19937_64& rng) {
  return with_noise(clean_run(m, truth, e, inst, o, name), o, rng);
}

}  // namespace tt::calibration
