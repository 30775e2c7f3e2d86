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

/// Where the held-out part of one run starts when none is given [s]: the start of the last speed
/// cycle that begins after the run's start and by `limit` of its duration, so that the held-out
/// data start at rest as every training piece does; `fallback` of the duration when no cycle begins
/// there (no speed, or a single cycle). time: #samples [s]; speed: #samples [rpm], or empty.
double held_out_start(const Eigen::VectorXd& time, const Eigen::VectorXd& speed, double limit,
                      double fallback);

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

/// Blocks for blocked cross-validation, and how they were made.
struct Blocks {
  std::vector<Segment> segments;
  /// true when the pieces were too few and were cut into time blocks
  bool cut_in_time = false;
  /// how the blocks were made, in words for the reports
  std::string origin;
};

/// The training pieces (speed cycles or whole runs) as cross-validation blocks: as given when
/// there are at least min_blocks; else each piece is cut into equal-duration time blocks,
/// re-zeroed at each block start, so that there are at least min_blocks. Throws DataError naming
/// the piece, its length and what would work when a piece is too short for blocks of min_rows.
Blocks cross_validation_blocks(const std::vector<Segment>& pieces, int min_blocks = 4,
                               Eigen::Index min_rows = 10);

/// One candidate of a blocked choice.
struct Candidate {
  SensorSet sensor_set;
  ModelSpec spec;
};

/// Blocked cross-validation. Each group of `pool` (whole runs, speed cycles or time blocks)
/// validates in turn while the other pool groups fit; a candidate's validation Accuracy holds its S
/// per fold. The candidate of the lowest mean S² over the folds is chosen (ties: fewer
/// coefficients, then the stronger ridge), unless it fails the one-standard-error guard against
/// no compensation: its mean per-fold gain in S² over a listed no_compensation candidate must
/// exceed that gain's standard error, else no compensation is chosen. So a model worse than no
/// compensation on validation, or better only by the fold-to-fold scatter, is never chosen. The
/// choice is refitted on all of `pool` and measured on `test`. The Evaluation's sensor_sets and
/// specs hold one entry per candidate. Throws DataError on fewer than 2 pool groups or when every
/// candidate fails.
Evaluation blocked_evaluation(const std::vector<Group>& groups, const std::vector<int>& pool,
                              const std::vector<int>& test, int target,
                              const std::vector<Candidate>& candidates);

/// The candidates fit --data and calibrate (without --case) choose among for a channel of measured
/// runs: no compensation; least squares on all temperature rises, as the standard fits it (3σ
/// criterion) and plain; ridge on them and on them with their first-order lags at 600 s and 3600 s
/// (and the inputs with their lags, has_inputs) over a grid of ridge strengths λ in 1e-6..10
/// (quick: 1e-4, 1e-2, 1), so that the strength is chosen by blocked_evaluation, never fixed.
/// Sensor subsets are left out: on data/fl-thermal-measured the best of 72 subset candidates on
/// validation was 1.5 to 3 times worse on the test window than the lagged ridge
/// (docs/real-data.md): choosing among many subsets on a few validation blocks selects on noise.
std::vector<Candidate> measured_data_candidates(int sensor_count, bool has_inputs, bool quick);

/// A temperature or input increment the test groups take outside the training groups' range.
struct OutOfRange {
  /// e.g. "dT[t3]", "d[speed_rpm]"
  std::string column;
  /// [K] or the input's unit
  double training_min = 0.0, training_max = 0.0, test_min = 0.0, test_max = 0.0;
  /// share of the test samples beyond the training range by more than 5 % of its width
  double share_outside = 0.0;
};

/// The columns (every sensor's and input's increment) whose test values leave the training range
/// by more than 5 % of its width: a model is extrapolating there.
std::vector<OutOfRange> out_of_training_range(const std::vector<Group>& training,
                                              const std::vector<Group>& test);

}  // namespace tt::fitting
