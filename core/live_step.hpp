// One sample of a live stream as a model beside the machine answers it (thermotwin compensate):
// the status of the sample, the predicted drift of every target and its standard deviation. The
// fitted regressions (fitting::Compensator) and the physics observer (solvers::LiveObserver) both
// answer in it, so that one loop streams either.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/enum_names.hpp"

namespace tt::core {

/// What became of one sample.
enum class SampleStatus {
  /// every reading the model uses was there
  ok,
  /// some readings were missing or not finite: a fitted model used their last good values; the
  /// observer left the sensors out of its update and held the last speed (`held`)
  held,
  /// its time was not after the last sample used (or not finite): skipped, the last prediction
  /// repeated
  late,
  /// no sample with every reading the model needs to start yet: nothing is predicted
  waiting,
};

/// The statuses' names in compensate's output.
inline constexpr std::array<Named<SampleStatus>, 4> kSampleStatusNames{{
    {SampleStatus::ok, "ok"},
    {SampleStatus::held, "held"},
    {SampleStatus::late, "late"},
    {SampleStatus::waiting, "waiting"},
}};
static_assert(one_to_one(kSampleStatusNames));

/// The status's name in kSampleStatusNames.
inline std::string status_name(SampleStatus status) {
  return std::string(name_in(kSampleStatusNames, status));
}

/// The model's answer to one sample.
struct LiveStep {
  SampleStatus status = SampleStatus::waiting;
  /// #targets predicted errors [m]; NaN while waiting
  Eigen::VectorXd predicted;
  /// #targets standard deviation of the predicted errors [m]
  Eigen::VectorXd sigma;
  /// columns (indices into the stream's columns) held at their last good reading or left out,
  /// or still missing while waiting
  std::vector<int> held;
  /// the model no longer describes the machine (the observer's innovation test, a reading held
  /// away from the declared model's run, a sensor offset that appeared late): recalibrate
  bool recalibrate = false;
  /// columns (indices into the stream's columns) of sensors the observer found off by an offset
  /// it is sure of (solvers::HeldSensor), in the order they were raised: check these sensors
  std::vector<int> faulty;
};

}  // namespace tt::core
