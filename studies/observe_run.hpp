// The physics observer (docs/observer.md) on a measured run, as `thermotwin observe` runs it: a
// Kalman filter on a reduced model's states, fed with the run's spindle speed (its speed_rpm
// column) as the duty cycle and its sensors' readings, that predicts the drift at the tool (and the
// axis points) with its standard deviation and says when the innovations stop fitting the noise
// model. SI units.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "io/measured_data.hpp"
#include "solvers/observer.hpp"
#include "solvers/twin.hpp"

namespace tt::studies {

/// The ids of `ids` that are named points of the twin (its temperature outputs), in their order.
std::vector<std::string> named_by_twin(const solvers::TwinOutputs& outputs,
                                       const std::vector<std::string>& ids);

struct ObserveInput {
  const core::CaseSpec* declared = nullptr;
  const io::MeasuredRun* run = nullptr;
  /// the reduced model, checked by the caller against the declared case and its mesh
  const solvers::Twin* twin = nullptr;
  /// the run's columns to observe; empty: every sensor of the run that the twin names
  std::vector<std::string> sensors;
  /// the observer's noise and consistency test on the case under the run and the chosen sensors
  std::function<solvers::ObserverSetup(const core::CaseSpec&, const std::vector<std::string>&)>
      setup;
};

struct ObserveReport {
  core::CaseSpec spec;               /// the declared case under the run's inputs
  std::vector<std::string> sensors;  /// the observed columns, in the readings' order
  solvers::ObserverSetup setup;
  solvers::ObserverRun result;
};

/// Throws DataError when the run has no speed column, when none of its sensors is a named point of
/// the twin (and none was chosen) or a chosen sensor is not a column of the run; what the observer
/// throws.
ObserveReport observe_run(const ObserveInput& input);

}  // namespace tt::studies
