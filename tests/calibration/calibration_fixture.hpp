// Shared set-up of the calibration tests: the declared coarse SB-1, the generator's finer mesh,
// three duty cycles (two for training, one for testing) and the training catalogue, built once.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "calibration/calibrate.hpp"
#include "calibration/generator.hpp"
#include "core/rng.hpp"
#include "core/timing.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"

namespace tt::calibration::testing {

struct Study {
  core::CaseSpec declared, gen;
  mesh::TetMesh mesh, gen_mesh;
  std::vector<core::DutyCycle> duties;  /// train, train, test
  Instrumentation inst;
  GeneratorOptions gopt;
  CalibrationOptions copt;
  std::unique_ptr<MarchModel> model;  /// the declared model marched (reduced unless Scale says)
  Catalogue train;         /// built on the first training data; measured channels replaced per case
  double catalogue_s = 0;  /// wall time of the catalogue's build [s]
};

/// Scale of the study: CI (coarse, short), the long variant, or cases/sb1.toml itself. By default
/// the declared model is the coarse SB-1 with its bodies' max_edge times `declared_edge_scale`,
/// stepped at `declared_step_s`; the generator meshes 0.8 times finer again (more circle segments)
/// and steps at 20 s. At 0.7 and 30 s the declared model's own error against the generator on a
/// clean test run is 0.0023 K over the sensors and 0.023 um at the TCP (0.0080 K and 0.043 um at
/// 1.0 and 60 s, which left the after RMS of small effects at 40-55 % of before):
/// docs/calibration.md, "Limits".
struct Scale {
  double hours = 2;
  std::vector<double> run_hours;  /// per run (train, train, test); empty: every run `hours`
  std::string declared_case = "cases/sb1_coarse.toml";  /// relative to the source tree
  double declared_step_s = 30;
  double patch_spacing = 0.14, patch_half = 0.08;
  double declared_edge_scale = 0.7;
  double gen_mesh_scale = 0.8;  /// the generator's bodies' max_edge times this (GeneratorOptions)
  double gen_step_s = 20;       /// the generator's step: finer than the calibration's, another grid
  bool reduced = true;  /// march the reduced model on the channels, as calibrate --case does
  bool seed_from_case = false;  /// CalibrationOptions::seed from the case, as calibrate --case
};

/// Cases/sb1.toml itself as the declared model, as `calibrate --case` takes it: its own mesh and
/// 12 s step, calibrate's default patch grid and seed, the reduced model; runs of 2, 6 and 8 hours
/// (train, train, test). Its own mesh (or a finer one) as the generator costs 20-50 min per draw,
/// so the generator meshes 2.0 times coarser at 20 s: another mesh and step than the calibrator's.
inline Scale sb1_scale() {
  Scale sc;
  sc.run_hours = {2, 6, 8};
  sc.declared_case = "cases/sb1.toml";
  sc.declared_step_s = 12;
  sc.patch_spacing = CalibrationOptions{}.patch_spacing;
  sc.patch_half = CalibrationOptions{}.patch_half_size;
  sc.declared_edge_scale = 1.0;
  sc.gen_mesh_scale = 2.0;
  sc.seed_from_case = true;
  return sc;
}

inline std::unique_ptr<Study> make_study(const Scale& sc) {
  auto s = std::make_unique<Study>();
  const auto t0 = std::chrono::steady_clock::now();
  auto since = [&] { return core::seconds_since(t0); };
  s->declared = io::read_case(std::string(TT_SOURCE_DIR) + "/" + sc.declared_case);
  s->declared.thermal.step = sc.declared_step_s;
  for (auto& b : s->declared.bodies) b.max_edge *= sc.declared_edge_scale;
  s->gopt.mesh_scale = sc.gen_mesh_scale;
  s->gopt.step_s = sc.gen_step_s;
  s->gen = generator_case(s->declared, s->gopt);
  s->mesh = mesh::mesh_case(s->declared);
  s->gen_mesh = mesh::mesh_case(s->gen);
  std::printf("[calibration] meshes: %ld and %ld nodes (%.1f s)\n",
              static_cast<long>(s->mesh.nodes.rows()), static_cast<long>(s->gen_mesh.nodes.rows()),
              since());
  std::mt19937_64 rng = core::generator(20260107, 1);
  for (int k = 0; k < 3; ++k)
    s->duties.push_back(
        random_duty_cycle(sc.run_hours.empty() ? sc.hours : sc.run_hours.at(k), rng));
  s->inst.sensor_points = {"T02", "T05", "T08", "T11", "T14", "T17", "T19", "T23",
                           "T27", "T31", "T35", "T40", "T44", "T48", "T52", "T54"};
  s->copt.patch_spacing = sc.patch_spacing;
  s->copt.patch_half_size = sc.patch_half;
  if (sc.seed_from_case) s->copt.seed = s->declared.seed;
  // The catalogue depends on the runs' inputs only: build it on clean declared runs.
  std::vector<io::MeasuredRun> runs;
  const TruthMachine machine =
      truth_machine(s->gen_mesh, truth_case(s->gen, InjectedEffect{}, s->duties[0], 0), s->inst);
  for (int k = 0; k < 2; ++k) {
    const core::CaseSpec t = truth_case(s->gen, InjectedEffect{}, s->duties[k], k);
    runs.push_back(clean_run(machine, t, {}, s->gopt, "train " + std::to_string(k)));
  }
  std::printf("[calibration] clean generator runs (%.1f s)\n", since());
  const Readout r = readout(s->mesh, s->declared, runs.front());
  s->model = sc.reduced ? std::make_unique<MarchModel>(s->mesh, s->declared, r,
                                                       solvers::ReductionOptions{})
                        : std::make_unique<MarchModel>(s->mesh, s->declared);
  std::printf("[calibration] model: order %d of %ld nodes (%.1f s)\n", s->model->order(),
              static_cast<long>(s->mesh.nodes.rows()), since());
  const auto t_catalogue = std::chrono::steady_clock::now();
  s->train = catalogue(*s->model, s->declared, r, runs, s->copt);
  s->catalogue_s = core::seconds_since(t_catalogue);
  std::printf("[calibration] catalogue: %zu candidates (%.1f s; %.1f s for the catalogue)\n",
              s->train.candidates.size(), since(), s->catalogue_s);
  return s;
}

/// Runs (train, train, test) of the truth with `effect`, noise from `rng`; `clean` gets the same
/// runs without noise (the test run's is the truth the RMS figures are measured against).
inline std::vector<io::MeasuredRun> effect_runs(const Study& s, const InjectedEffects& effect,
                                                std::mt19937_64& rng,
                                                std::vector<io::MeasuredRun>* clean = nullptr) {
  std::vector<io::MeasuredRun> out;
  // One machine for the three runs: they differ in duty cycle and air only.
  const TruthMachine machine =
      truth_machine(s.gen_mesh, truth_case(s.gen, effect, s.duties[0], 0), s.inst);
  for (int k = 0; k < 3; ++k) {
    const core::CaseSpec t = truth_case(s.gen, effect, s.duties[k], k);
    io::MeasuredRun c =
        clean_run(machine, t, effect, s.gopt, (k < 2 ? "train " : "test ") + std::to_string(k));
    out.push_back(with_noise(c, s.gopt, rng));
    if (clean) clean->push_back(std::move(c));
  }
  return out;
}

/// The training catalogue with these runs' measured channels.
inline Catalogue with_measured(const Catalogue& cat, const std::vector<io::MeasuredRun>& runs) {
  Catalogue c = cat;
  for (size_t k = 0; k < c.runs.size(); ++k)
    c.runs[k].measured = measured_channels(runs[k], c.readout);
  return c;
}

}  // namespace tt::calibration::testing
