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
  Catalogue train;  /// built on the first training data; measured channels replaced per case
};

/// Scale of the study: CI (coarse, short) or the long variant. The declared model is the coarse
/// SB-1 with its bodies' max_edge times `declared_edge_scale`, stepped at `declared_step_s`; the
/// generator meshes 0.8 times finer again (more circle segments) and steps at 20 s. At 0.7 and 30 s
/// the declared model's own error against the generator on a clean test run is 0.0023 K over the
/// sensors and 0.023 um at the TCP (0.0080 K and 0.043 um at 1.0 and 60 s, which left the after
/// RMS of small effects at 40-55 % of before): docs/calibration.md, "Limits".
struct Scale {
  double hours = 2;
  double declared_step_s = 30;
  double patch_spacing = 0.14, patch_half = 0.08;
  double declared_edge_scale = 0.7;
  bool reduced = true;  /// march the reduced model on the channels, as calibrate --case does
};

inline std::unique_ptr<Study> make_study(const Scale& sc) {
  auto s = std::make_unique<Study>();
  const auto t0 = std::chrono::steady_clock::now();
  auto since = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  s->declared = io::read_case(std::string(TT_SOURCE_DIR) + "/cases/sb1_coarse.toml");
  s->declared.thermal.step = sc.declared_step_s;
  for (auto& b : s->declared.bodies) b.max_edge *= sc.declared_edge_scale;
  s->gen = generator_case(s->declared, s->gopt);
  s->gen.thermal.step = 20;  // finer than the calibration's, and not the same grid
  s->gen.thermal.output_interval = 20;
  s->mesh = mesh::mesh_case(s->declared);
  s->gen_mesh = mesh::mesh_case(s->gen);
  std::printf("[calibration] meshes: %ld and %ld nodes (%.1f s)\n",
              static_cast<long>(s->mesh.nodes.rows()), static_cast<long>(s->gen_mesh.nodes.rows()),
              since());
  std::mt19937_64 rng = core::generator(20260107, 1);
  for (int k = 0; k < 3; ++k) s->duties.push_back(random_duty_cycle(sc.hours, rng));
  s->inst.sensor_points = {"T02", "T05", "T08", "T11", "T14", "T17", "T19", "T23",
                           "T27", "T31", "T35", "T40", "T44", "T48", "T52", "T54"};
  s->copt.patch_spacing = sc.patch_spacing;
  s->copt.patch_half_size = sc.patch_half;
  // The catalogue depends on the runs' inputs only: build it on clean declared runs.
  std::vector<io::MeasuredRun> runs;
  for (int k = 0; k < 2; ++k) {
    const core::CaseSpec t = truth_case(s->gen, InjectedEffect{}, s->duties[k], k);
    runs.push_back(clean_run(s->gen_mesh, t, InjectedEffect{}, s->inst, s->gopt,
                             "train " + std::to_string(k)));
  }
  std::printf("[calibration] clean generator runs (%.1f s)\n", since());
  const Readout r = readout(s->mesh, s->declared, runs.front());
  s->model = sc.reduced ? std::make_unique<MarchModel>(s->mesh, s->declared, r,
                                                       solvers::ReductionOptions{})
                        : std::make_unique<MarchModel>(s->mesh, s->declared);
  std::printf("[calibration] model: order %d of %ld nodes (%.1f s)\n", s->model->order(),
              static_cast<long>(s->mesh.nodes.rows()), since());
  s->train = catalogue(*s->model, s->declared, r, runs, s->copt);
  std::printf("[calibration] catalogue: %zu candidates (%.1f s)\n", s->train.candidates.size(),
              since());
  return s;
}

/// Runs (train, train, test) of the truth with `effect`, noise from `rng`; `clean` gets the same
/// runs without noise (the test run's is the truth the RMS figures are measured against).
inline std::vector<io::MeasuredRun> effect_runs(const Study& s, const InjectedEffects& effect,
                                                std::mt19937_64& rng,
                                                std::vector<io::MeasuredRun>* clean = nullptr) {
  std::vector<io::MeasuredRun> out;
  for (int k = 0; k < 3; ++k) {
    const core::CaseSpec t = truth_case(s.gen, effect, s.duties[k], k);
    io::MeasuredRun c = clean_run(s.gen_mesh, t, effect, s.inst, s.gopt,
                                  (k < 2 ? "train " : "test ") + std::to_string(k));
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
