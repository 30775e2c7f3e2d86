// Placeholder for `thermotwin calibrate --case CASE`: the model-based path lives in calibration/
// and its driver replaces this file when it is wired.
#include "app/commands.hpp"
#include "core/errors.hpp"

namespace tt::app {

int calibrate_command_with_case(const CalibrateArgs& /*args*/) {
  throw core::CaseError("calibrate --case is not available yet");
}

}  // namespace tt::app
