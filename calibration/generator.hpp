// Test data with an undeclared effect: the virtual machine with an extra effect switched on,
// simulated on its own (finer) mesh and time step, read by noisy sensors, written in the
// measured-data format. It shares none of the calibrator's choices: heat enters through a box of
// random size and position (not a calibrator patch), the air temperature is a random smooth
// signal or a shop's day (not hat functions), the convection gain follows speed with exponent
// 0.8 (0.5-0.9 in several places), magnitudes are drawn from ranges that reach down to the
// detection limit, and a mechanism may act in several places at once with its own size and law
// in each, or two mechanisms at once. Heat that grows with temperature is simulated as such:
// each step is solved again with the sources' powers at the step's end until their mean
// temperatures settle (GeneratorOptions::source_tolerance_K), not lagged by a step.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "calibration/effects.hpp"
#include "core/case_spec.hpp"
#include "io/measured_data.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/thermal_stepper.hpp"

namespace tt::calibration {

/// The effect switched on in the truth, with its drawn magnitude and place.
struct InjectedEffect {
  bool present = false;
  EffectKind kind = EffectKind::heat_input;
  double magnitude =
      0;  /// kind's own unit: W (heat), K (air, offset), factor-1, 1/K, W/(m2K), s (lag)
  std::string target;  /// group, material.field, source or sensor id
  Eigen::Vector3d centre =
      Eigen::Vector3d::Zero();  /// heat input: area-weighted centre of its faces [m]
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero(), box_max = Eigen::Vector3d::Zero();
  std::vector<std::string> groups{};  /// heat input: the boundary groups its box covers
  double area = 0;  /// heat input: area of the faces in the box on the generator's mesh [m^2]
  bool follows_speed = false;
  std::uint64_t seed = 0;  /// for the run-specific parts (the air signal)
  /// speed_dependent_convection: the gain grows with (speed / 3000 rpm)^speed_exponent.
  double speed_exponent = 0.8;
  /// ambient_temperature: a drift plus two slow waves, or a shop's day (shop_day_air); on every
  /// unfixed sink, or on `target`'s only when it names a group.
  enum class Air { waves, shop_day } air = Air::waves;
};

/// Every effect a truth has switched on (several places of one kind, or two kinds at once).
using InjectedEffects = std::vector<InjectedEffect>;

struct GeneratorOptions {
  double mesh_scale = 0.8;                /// bodies' max_edge times this (finer than the case)
  double step_s = 6;                      /// thermal step of the truth [s]
  double sample_interval_s = 60;          /// the data logger's interval [s]
  double noise_temperature_K = 0.03;      /// white noise per reading
  double drift_temperature_K = 0.01;      /// slow correlated part (first-order, 600 s)
  double noise_displacement_m = 0.08e-6;  /// white noise per reading
  double quantum_temperature_K = 0.01, quantum_displacement_m = 0.01e-6;
  /// Heat that grows with temperature, iterated within each step until no source's mean
  /// temperature moves by more than this between two solves [K] (solvers::SourceIteration; 0:
  /// lagged by one step, as `run` steps it).
  double source_tolerance_K = 1e-6;
};

/// A random effect of `kind` on `declared` (sizes drawn by `rng` from the ranges of
/// docs/calibration.md). `mesh` is the generator's mesh (for the heat input's faces).
InjectedEffect random_effect(EffectKind kind, const core::CaseSpec& declared,
                             const mesh::TetMesh& mesh, const std::vector<std::string>& sensor_ids,
                             std::mt19937_64& rng);

/// One random_effect of each kind of the catalogue, in the kinds' order (ambient_temperature to
/// sensor_lag), drawn in that order from `rng`.
InjectedEffects random_effect_of_each_kind(const core::CaseSpec& declared,
                                           const mesh::TetMesh& mesh,
                                           const std::vector<std::string>& sensor_ids,
                                           std::mt19937_64& rng);

/// One mechanism in several places at once, each with its own size and law, in forms the
/// calibrator's candidates (one place, or every place by one share of its h) cannot match one to
/// one: heat inputs on two patches of the housing, one constant and one following speed; two or
/// three unfixed films growing with speed with their own gains and exponents (0.5-0.9); every
/// heat source's heat growing with temperature by its own coefficient; two films' conductances
/// changed by their own factors; two material values; offsets or lags of two or three sensors;
/// a shop's day (shop_day_air) on each unfixed sink with its own amplitude. The first element
/// is the largest or the one random_effect would draw.
InjectedEffects random_effects_in_several_places(EffectKind kind, const core::CaseSpec& declared,
                                                 const mesh::TetMesh& mesh,
                                                 const std::vector<std::string>& sensor_ids,
                                                 std::mt19937_64& rng);

/// An air that follows a shop's day [K, change from the run's start], sampled every 60 s up to
/// `end_s`: the run starts between 6 and 12 o'clock (seeded by seed + run_index); a daily swing
/// of `magnitude` K either side (coolest at 4, warmest at 15 o'clock), the air conditioning's
/// cycle (20-40 min, 0.05-0.2 K) and doors opened now and then (about once in two hours: 0.2-0.6 K
/// cooler, recovering in 10-20 min).
core::TimeTable shop_day_air(double magnitude, std::uint64_t seed, int run_index, double end_s);

/// The generator's own case: the declared case meshed finer, with its own time step.
core::CaseSpec generator_case(const core::CaseSpec& declared, const GeneratorOptions& options);

/// `gen_case` (from generator_case) with `effect` switched on, under `duty` (run-specific air
/// signal seeded by effect.seed + run_index).
core::CaseSpec truth_case(const core::CaseSpec& gen_case, const InjectedEffect& effect,
                          const core::DutyCycle& duty, int run_index);
/// The same with every effect of `effects` switched on, in order.
core::CaseSpec truth_case(const core::CaseSpec& gen_case, const InjectedEffects& effects,
                          const core::DutyCycle& duty, int run_index);

/// Sensors at named points of the case (by id) and displacement probes at the TCP in x, y, z.
struct Instrumentation {
  std::vector<std::string> sensor_points;  /// ids of named points
  bool tcp_probes = true;
  /// Probes at each of the case's feed-axis points in x, y, z ("<point>_dx", ...), after the
  /// TCP's: the truth of the error along the axis (mechanical.axis_points).
  bool axis_probes = false;
  /// An air sensor `AIR` (no position; meta.json `ambient_sensor`) reading the truth's air: the
  /// sink of its first convection entry that is not mechanically fixed, with the sensors' noise.
  bool ambient_sensor = false;
};

/// What every run of one truth shares, whatever its duty cycle and air: the mesh carrying the
/// truth's boundary groups (`mesh` re-meshed when a heat input adds groups) and the displacement
/// probes' influences (u = a . T; the elastic factor is the costly part of a run: built once
/// for a draw's runs instead of once per run), and the thermal step factors its runs share. Valid
/// for truth cases that differ from the one it was built for in their duty cycle and convection
/// sinks only, as truth_case's runs of one draw do; clean_run refuses another
/// (std::invalid_argument).
struct TruthMachine {
  mesh::TetMesh mesh;
  core::CaseSpec truth;                          /// the truth it was built for, for the check
  Instrumentation instrumentation;               /// the sensors and probes it reads
  std::vector<io::MeasuredProbe> probes;         /// per probe: name, position, direction
  std::vector<Eigen::VectorXd> probe_influence;  /// per probe: a with u = a . T [m/K]
  /// The thermal step factors made so far, for the next run (forgotten when a run's system has
  /// other matrices; one run at a time).
  std::shared_ptr<solvers::KeptStepFactors<Eigen::SparseMatrix<double>>> factors =
      std::make_shared<solvers::KeptStepFactors<Eigen::SparseMatrix<double>>>();
};
TruthMachine truth_machine(const mesh::TetMesh& mesh, const core::CaseSpec& truth,
                           const Instrumentation& inst);
/// Whether `machine` can run `truth`: the same boundary groups, materials and mechanical
/// settings as the truth it was built for (clean_run's check).
bool serves(const TruthMachine& machine, const core::CaseSpec& truth);
/// The machine for `truth`: `kept` when it serves it, or else one built for it on `mesh` (kept in
/// its place for the next run; runs of one truth then share it).
const TruthMachine& machine_for(std::optional<TruthMachine>& kept, const mesh::TetMesh& mesh,
                                const core::CaseSpec& truth, const Instrumentation& inst);

/// Simulates `truth` on `mesh` (re-meshed when `truth` has other boundary groups, as a heat input
/// adds), samples it every options.sample_interval_s, applies sensor
/// effects (offset, lag) and noise from `rng`, and returns the run (nominal conditions in meta).
io::MeasuredRun synthetic_run(const mesh::TetMesh& mesh, const core::CaseSpec& truth,
                              const InjectedEffect& effect, const Instrumentation& inst,
                              const GeneratorOptions& options, const std::string& name,
                              std::mt19937_64& rng);

/// The noiseless readings of synthetic_run (noise added separately so that many noise draws can
/// share one simulation).
io::MeasuredRun clean_run(const mesh::TetMesh& mesh, const core::CaseSpec& truth,
                          const InjectedEffect& effect, const Instrumentation& inst,
                          const GeneratorOptions& options, const std::string& name);
/// The same with the sensor effects of every element of `effects`.
io::MeasuredRun clean_run(const mesh::TetMesh& mesh, const core::CaseSpec& truth,
                          const InjectedEffects& effects, const Instrumentation& inst,
                          const GeneratorOptions& options, const std::string& name);
/// The same on a machine built for `truth`'s draw (truth_machine), `machine.instrumentation` read.
io::MeasuredRun clean_run(const TruthMachine& machine, const core::CaseSpec& truth,
                          const InjectedEffects& effects, const GeneratorOptions& options,
                          const std::string& name);
io::MeasuredRun with_noise(const io::MeasuredRun& clean, const GeneratorOptions& options,
                           std::mt19937_64& rng);

/// Random duty cycles of `hours`: segments of 5-30 min at 0, 1500, 2000, 3000 or 4000 rpm.
core::DutyCycle random_duty_cycle(double hours, std::mt19937_64& rng);

}  // namespace tt::calibration
