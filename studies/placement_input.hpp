// Placement on fitting groups: the groups laid end to end as one placement input.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "fitting/group.hpp"
#include "placement/place.hpp"

namespace tt::studies {

/// The groups `which` (indices into `groups`, all with the same sensors) laid end to end as one
/// placement input: each group's times shifted to start 1 s after the previous group's end, its
/// temperatures and its first `targets` error columns (named as the groups name them). The
/// candidates are numbered 1.. in the groups' sensor order, at `positions` (#sensors x 3 [m]).
/// Throws core::DataError when `which` is empty or names a group out of range, or the groups
/// differ in their sensors.
placement::PlacementInput groups_end_to_end(const std::vector<fitting::Group>& groups,
                                            const std::vector<int>& which,
                                            const Eigen::MatrixX3d& positions,
                                            Eigen::Index targets);

}  // namespace tt::studies
