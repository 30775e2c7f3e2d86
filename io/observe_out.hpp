// observe's report at the edge (docs/observer.md): observer.csv, per sample the drift of every
// target and its sigma [um], the innovations' test and the status; observer.json, what was
// observed, how, and the status with when it was raised.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

#include "studies/observe_run.hpp"

namespace tt::io {

/// What the report came from, for observer.json.
struct ObserveSource {
  std::string run;            /// the measured run's name
  std::string case_name;      /// the declared case's
  int order = 0;              /// the reduced model's states
  std::filesystem::path rom;  /// its folder
  nlohmann::json noise;       /// the set-up's noise model and consistency test
};

/// The consistency test's and the departure test's settings, as observer.json and
/// sigma_calibration.json write them.
nlohmann::json consistency_json(const solvers::ConsistencyOptions& c);

/// Writes observer.csv and observer.json into `dir` (a folder the caller publishes).
void write_observe(const std::filesystem::path& dir, const studies::ObserveReport& report,
                   const ObserveSource& source);

}  // namespace tt::io
