// A measured run as the fitting library takes it: segments cut at the run's speed cycles, each a
// group of temperatures [K] and re-zeroed displacements [m] with the speed beside it.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "fitting/segments.hpp"
#include "io/measured_data.hpp"

namespace tt::io {

/// #samples spindle speed [rpm]: the input "speed_rpm", else the first input with the unit rpm;
/// empty when the run has no input (then there are no speed cycles and no speed term).
Eigen::VectorXd measured_speed(const MeasuredRun& run);

/// The run's rows with from_s <= time < to_s cut at its speed cycles (fitting::speed_cycles),
/// named "<name>.c<k>_<speed>rpm" after the first nonzero speed of each cycle; targets are the
/// displacement ids, sensors the sensor ids. Rows with a missing reading are dropped per segment.
/// A run with no speed gives one segment, "<name>.whole".
std::vector<fitting::Segment> measured_segments(
    const MeasuredRun& run, const std::string& name,
    double from_s = -std::numeric_limits<double>::infinity(),
    double to_s = std::numeric_limits<double>::infinity());

}  // namespace tt::io
