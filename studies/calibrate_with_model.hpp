// Calibration with a machine model (`thermotwin calibrate --case`): the declared case marched
// under each measured run's inputs, the residual of every channel traced to the undeclared effect
// that explains it (held-out training runs, noise threshold; calibration/), the augmented case
// evaluated on the test runs. SI units ([K], [m], [s]) except where calibration's own result says
// otherwise; io/calibration_model_out writes calibration.json, report.md, the augmented cases,
// residuals.csv and the figures.
#pragma once

#include <string>
#include <vector>

#include "calibration/calibrate.hpp"
#include "core/case_spec.hpp"
#include "io/measured_data.hpp"  // io::MeasuredRun: the run type calibration/'s functions take
#include "solvers/twin.hpp"
#include "studies/model_choice.hpp"
#include "studies/progress.hpp"
#include "studies/test_figures.hpp"

namespace tt::studies {

struct ModelCalibrationInput {
  core::CaseSpec declared;
  std::vector<io::MeasuredRun> train, test;  /// at least one training run
  bool full = false;  /// march the full model, not a reduced one built on the channels
  bool refit = true;  /// refit the claims' sizes about the updated model (Gauss-Newton)
};

struct ModelCalibrationReport {
  std::string case_name;
  std::vector<std::string> training_runs;
  /// the model marched: full order, or reduced on the channels (indicator on the first
  /// training run, backward Euler only)
  ModelUsed model;
  /// the choice, the claims and the test runs (before, after, augmented cases)
  calibration::CalibrationResult result;
  /// per channel in the readout's order (sensors, then probes), on the test runs
  std::vector<ChannelTestFigures> channels;
  double runtime_s = 0;  /// wall time of the study [s]
};

/// The study. Throws DataError when no channel of the first training run can be located on the
/// mesh, and what meshing, reading and marching throw.
ModelCalibrationReport calibrate_with_model(const ModelCalibrationInput& input,
                                            const Progress& say = {},
                                            const solvers::Progress& stepping = {});

}  // namespace tt::studies
