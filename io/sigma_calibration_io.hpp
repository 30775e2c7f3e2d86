// The observer's sigma calibration at the edge (docs/observer.md, "Calibrating the sigma"):
// sigma_calibration.json, written by `observe --train` and read back by `--sigma-calibration` in
// `observe` and `compensate --rom`.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "studies/observer_sigma.hpp"

namespace tt::io {

/// What the calibration came from, for sigma_calibration.json.
struct SigmaCalibrationSource {
  std::string case_name;      /// the declared case's
  int order = 0;              /// the reduced model's states
  std::filesystem::path rom;  /// its folder
  nlohmann::json noise;       /// the set-up's noise model and consistency test
};

/// sigma_calibration.json's content.
nlohmann::json sigma_calibration_json(const studies::SigmaCalibration& calibration,
                                      const SigmaCalibrationSource& source);

/// The factors a sigma_calibration.json gives, and what they hold for.
struct SigmaCalibrationFile {
  std::vector<std::string> sensors, targets;
  Eigen::VectorXd drift_sigma_scale;  /// per target
  /// with a probe cycle: its period [s] and the factor of the filter that reads it
  std::optional<double> probe_every_s;
  Eigen::VectorXd probed_drift_sigma_scale;
  /// with changed runs (changed_machine): the correction's relative sigma, and the expansion
  /// relative sigma of every material
  std::optional<double> correction_relative_sigma, expansion_relative_sigma;
  /// and when they act (changed_machine.gate)
  solvers::ChangedTermsGate changed_terms = solvers::ChangedTermsGate::always;
  /// the alarm's and the evidence's settings the gated terms were chosen with (absent in files
  /// of session 18)
  std::optional<solvers::ConsistencyOptions> consistency;
};

/// The gate's name in sigma_calibration.json and observer.json: "always", "on_evidence" or
/// "after_alarm".
std::string changed_terms_gate_name(solvers::ChangedTermsGate gate);

/// The flag that asks for a gate other than always: --changed-terms-on-evidence or
/// --changed-terms-after-alarm.
std::string changed_terms_gate_flag(solvers::ChangedTermsGate gate);

/// Reads a sigma_calibration.json. IoError when it cannot be read; DataError naming the file and
/// the key for one that is missing or malformed, a factor that is not above 0, factors that are
/// not one per target, or a relative sigma below 0.
SigmaCalibrationFile read_sigma_calibration(const std::filesystem::path& path);

}  // namespace tt::io
