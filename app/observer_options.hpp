// The physics observer's command-line options, shared by `observe` and `compensate --rom`: the
// flags, and the solvers::ObserverSetup they give on a reduced model (docs/observer.md).
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "core/case_spec.hpp"
#include "io/sigma_calibration_io.hpp"
#include "solvers/observer.hpp"
#include "solvers/twin.hpp"

namespace tt::app {

/// --sensors, --sensor-sigma-k, --heat-walk-w, --heat-initial-w, --air-walk-k, --air-initial-k,
/// --state-walk-k, --sensor-offset-k, --sensor-offset-walk-k, --drift-relative-sigma,
/// --correction-relative-sigma, --drift-sigma-scale, --widen-on-inconsistency, --window-s,
/// --sustain-s, --probability, --sensor-fault-sigmas on `command`.
void add_observer_options(CLI::App& command, ObserverOptions& options);

/// The consistency test's and the sensor-fault test's options (--window-s, --sustain-s,
/// --probability, --sensor-fault-sigmas) and --widen-on-inconsistency, which widens by that
/// test's window; a part of add_observer_options.
void add_consistency_options(CLI::App& command, ObserverOptions& options);

/// The set-up on `twin` for `sensors` (ids; read through `sensor_rows` when given, else at their
/// named points): the noise and the consistency test of `options`, with --sigma-calibration's
/// file (`calibration` when it was read already, else read here). Throws DataError when
/// --sensor-sigma-k or --drift-sigma-scale has neither one value nor one per sensor (target),
/// naming them.
solvers::ObserverSetup observer_setup(const ObserverOptions& options, const solvers::Twin& twin,
                                      const core::CaseSpec& spec,
                                      const std::vector<std::string>& sensors,
                                      const Eigen::MatrixXd& sensor_rows = Eigen::MatrixXd(),
                                      const io::SigmaCalibrationFile* calibration = nullptr);

/// The noise model and consistency test of a set-up, for a result file.
nlohmann::json observer_noise_json(const solvers::ObserverSetup& setup);

/// Whether --correction-relative-sigma or --expansion-relative-sigma gives a term (a value above
/// 0): what `observe --changed` and a --sigma-calibration file that chose them refuse beside them.
bool gives_changed_terms(const ObserverOptions& options);

/// When the options let the correction's and the expansion's terms act
/// (--changed-terms-after-alarm, --changed-terms-on-evidence; neither: always).
solvers::ChangedTermsGate changed_terms_gate(const ObserverOptions& options);

}  // namespace tt::app
