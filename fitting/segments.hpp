// A continuous measured run cut into groups at its speed cycles, and a model choice made on
// several validation groups in turn. Cutting one run does not give independent cold starts: each
// segment's drift is re-zeroed at its first reading, as the standard's intercept assumes of a
// group, and the choice is averaged over validation folds instead of resting on one segment.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "fitting/group.hpp"
#include "fitting/models.hpp"
#include "fitting/selection.hpp"

namespace tt::fitting {

/// Rows [begin, end) of a run.
struct RowRange {
  Eigen::Index begin = 0;
  Eigen::Index end = 0;
};

/// One range per heating cycle: a cycle starts at the last stopped sample before the speed rises
/// from zero again (a rest before the first start joins the first cycle); a run that never stops
/// is one range.
/// Cycles shorter than min_rows join the one before. speed: #samples [rpm].
std::vector<RowRange> speed_cycles(const Eigen::VectorXd& speed, Eigen::Index min_rows = 10);

/// Ranges cut at the given times: rows with time < cuts[0], then [cuts[0], cuts[1]), ...; empty
/// pieces are left out. time: #samples [s]; cuts ascending [s].
std::vector<RowRange> ranges_at(const Eigen::VectorXd& time, const std::vector<double>& cuts);

/// A piece of a run as a group, with the operating input the group does not hold.
struct Segment {
  /// errors re-zeroed at the first kept row
  Group group;
  /// #samples spindle speed [rpm]; zeros when the run records none
  Eigen::VectorXd speed;
  /// rows of the run it came from (before dropping incomplete rows)
  RowRange rows;
  /// rows dropped because a reading was missing
  int dropped_rows = 0;
};

/// The rows `range` of a run as a segment: rows with a missing (non-finite) temperature, error or
/// speed are dropped and counted, and each error column is re-zeroed at the first kept row.
/// time: #samples [s]; speed: #samples [rpm] (or empty); temperature: #samples x #sensors [K];
/// error: #samples x #targets [m]. Throws DataError when fewer than 2 complete rows remain.
Segment segment_of(const std::string& name, const Eigen::VectorXd& time,
                   const Eigen::VectorXd& speed, const Eigen::MatrixXd& temperature,
                   const Eigen::MatrixXd& error, const std::vector<std::string>& sensor_names,
                   const std::vector<std::string>& target_names, RowRange range);

/// The groups of segments, in order.
std::vector<Group> segment_groups(const std::vector<Segment>& segments);

/// Chooses the (sensor set, model spec) pair with the smallest mean validation S over folds in
/// which each group of `pool` in turn validates and the other pool groups fit; refits it on all of
/// `pool` and measures it on `test`. The Evaluation's candidates hold, per pair, the S of every
/// fold's validation group and the model of the first fold; validation_groups lists the pool.
/// Needs at least 2 pool groups. Throws DataError when every pair fails.
Evaluation cross_validated_evaluation(const std::vector<Group>& groups,
                                      const std::vector<int>& pool, const std::vector<int>& test,
                                      int target, const std::vector<SensorSet>& sensor_sets,
                                      const std::vector<ModelSpec>& specs);

}  // namespace tt::fitting
