// Placement for detection (placement/detection): the held change an unknown input makes at a
// candidate against the closed form of a one-state filter, and the greedy's coverage choice (the
// effects it makes seen first, then the progress towards the rest, ties to the lower column).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "core/errors.hpp"
#include "placement/detection.hpp"

namespace tt::placement {
namespace {

/// One reduced state z and one unknown input b: z_k = a z_(k-1) + g b at each of `readings`
/// readings; candidates read z (sigma 0.1 K) and z / 2 (sigma 0.05 K).
EstimationProblem one_state(double a, double g, int readings) {
  EstimationProblem p;
  CovarianceTrack t;
  t.initial = Eigen::Matrix2d::Identity();
  Eigen::Matrix2d f;
  f << a, g, 0, 1;
  for (int k = 0; k < readings; ++k) {
    t.transitions.push_back(f);
    t.process.push_back(Eigen::Matrix2d::Zero());
  }
  p.tracks = {t};
  p.candidate_rows = Eigen::MatrixXd(2, 2);
  p.candidate_rows << 1, 0, 0.5, 0;
  p.candidate_sigma = Eigen::Vector2d(0.1, 0.05);
  p.target_rows = Eigen::MatrixXd::Zero(1, 2);
  return p;
}

TEST(Detection, HeldChangeIsTheFiltersResponseToTheHeldInput) {
  // z_k = g b (1 - a^k) / (1 - a) grows: its smallest |z| over the last 4 readings is z at the
  // fourth reading from the end, the largest such over the run.
  const double a = 0.9, g = 0.02, b = 5;
  const int k = 12, w = 4;
  const std::vector<Eigen::Index> states{1};
  const DetectionProblem d = detection_problem(one_state(a, g, k), {"heat:spindle"}, states,
                                               Eigen::VectorXd::Constant(1, b), w);
  ASSERT_EQ(d.held_sigmas.rows(), 1);
  ASSERT_EQ(d.held_sigmas.cols(), 2);
  const double z = g * b * (1 - std::pow(a, k - w + 1)) / (1 - a);
  EXPECT_NEAR(d.held_sigmas(0, 0), z / 0.1, 1e-12);
  EXPECT_NEAR(d.held_sigmas(0, 1), 0.5 * z / 0.05, 1e-12);
  // Held over one reading: the last, largest value.
  const DetectionProblem last = detection_problem(one_state(a, g, k), {"heat:spindle"}, states,
                                                  Eigen::VectorXd::Constant(1, b), 1);
  EXPECT_NEAR(last.held_sigmas(0, 0), g * b * (1 - std::pow(a, k)) / (1 - a) / 0.1, 1e-12);
  // Held longer than the run: never held, 0.
  EXPECT_EQ(detection_problem(one_state(a, g, k), {"heat:spindle"}, states,
                              Eigen::VectorXd::Constant(1, b), k + 1)
                .held_sigmas.maxCoeff(),
            0.0);
  // Refused: the reduced state itself as an effect is allowed, a state out of range is not; a
  // size that is not > 0; no readings to hold over.
  const std::vector<Eigen::Index> outside{2};
  EXPECT_THROW(detection_problem(one_state(a, g, k), {"x"}, outside, Eigen::VectorXd::Ones(1), w),
               core::DataError);
  EXPECT_THROW(detection_problem(one_state(a, g, k), {"x"}, states, Eigen::VectorXd::Zero(1), w),
               core::DataError);
  EXPECT_THROW(detection_problem(one_state(a, g, k), {"x"}, states, Eigen::VectorXd::Ones(1), 0),
               core::DataError);
  EXPECT_THROW(
      detection_problem(one_state(a, g, k), {"x", "y"}, states, Eigen::VectorXd::Ones(1), w),
      core::DataError);
}

TEST(Detection, GreedyMakesTheMostEffectsSeenThenTheMostProgress) {
  // Three effects, four candidates; candidate 0 is installed and sees effect 0. Candidates 1 and
  // 2 each make one more effect seen with the same progress (3): the lower column, 1, first, then
  // 2. Candidate 3 sees none on its own (2.9 sigma twice) and is never taken: with 1 and 2
  // installed nothing is left to see.
  DetectionProblem d;
  d.effects = {"heat:a", "heat:b", "air"};
  d.held_sigmas = Eigen::MatrixXd(3, 4);
  d.held_sigmas << 5, 0, 0, 1,  //
      0, 4, 0, 2.9,             //
      0, 0, 3.5, 2.9;
  const std::vector<int> installed{0}, pool{3, 2, 1, 0};
  const GreedyPath path = detection_greedy(d, installed, pool, 5, 3.0);
  EXPECT_EQ(path.order, (std::vector<int>{1, 2}));
  EXPECT_EQ(path.scores, (std::vector<double>{2, 3}));
  EXPECT_EQ(unseen_effects(d, installed, 3.0), (std::vector<int>{1, 2}));
  // One sensor only, and no effect reaches the bound at any candidate: the most progress,
  // candidate 3 (2.9 + 2.9).
  d.held_sigmas.row(1) << 0, 1, 0, 2.9;
  d.held_sigmas.row(2) << 0, 0, 1.5, 2.9;
  const GreedyPath progress = detection_greedy(d, installed, pool, 1, 3.0);
  EXPECT_EQ(progress.order, (std::vector<int>{3}));
  EXPECT_EQ(progress.scores, (std::vector<double>{1}));
  // Nothing to add: every effect seen already.
  EXPECT_TRUE(detection_greedy(d, std::vector<int>{0, 3}, pool, 3, 2.0).order.empty());
  EXPECT_THROW(detection_greedy(d, installed, pool, 1, 0.0), core::DataError);
  EXPECT_THROW(detection_greedy(d, installed, std::vector<int>{4}, 1, 3.0), core::DataError);
}

TEST(Detection, WeightsPerKindCountEachKindOnce) {
  // Three patches of one kind and one film: with weights per kind, the candidate that sees the
  // film (one kind) is worth more than the one that sees two of the three patches (2/3 of a
  // kind); unweighted, the two patches win. The scores are the kinds seen.
  DetectionProblem d;
  d.effects = {"patch a", "patch b", "patch c", "film"};
  d.kinds = {"heat_input", "heat_input", "heat_input", "boundary_conductance"};
  d.held_sigmas = Eigen::MatrixXd(4, 2);
  d.held_sigmas << 4, 0,  //
      4, 0,               //
      0, 0,               //
      0, 4;
  const std::vector<int> none, pool{0, 1};
  EXPECT_EQ(detection_greedy(d, none, pool, 1, 3.0).order, (std::vector<int>{0}));
  d.weights = weights_per_kind(d.kinds);
  ASSERT_EQ(d.weights.size(), 4);
  EXPECT_DOUBLE_EQ(d.weights(0), 1.0 / 3);
  EXPECT_DOUBLE_EQ(d.weights(3), 1.0);
  const GreedyPath path = detection_greedy(d, none, pool, 2, 3.0);
  EXPECT_EQ(path.order, (std::vector<int>{1, 0}));
  ASSERT_EQ(path.scores.size(), 2u);
  EXPECT_DOUBLE_EQ(path.scores[0], 1.0);
  EXPECT_DOUBLE_EQ(path.scores[1], 1.0 + 2.0 / 3);
  d.weights = Eigen::VectorXd::Ones(3);
  EXPECT_THROW(detection_greedy(d, none, pool, 1, 3.0), core::DataError);
  d.weights = -Eigen::VectorXd::Ones(4);
  EXPECT_THROW(detection_greedy(d, none, pool, 1, 3.0), core::DataError);
}

TEST(Detection, ProblemFromResponsesHoldsEachRunsChange) {
  // One effect on two runs, two candidates of sigma 0.1 and 0.5 K: the held change is the largest
  // over both runs and times of the smallest |change| over 2 consecutive readings, in sigmas.
  Eigen::MatrixXd run1(4, 2), run2(3, 2);
  run1 << 0.1, 1.0,  //
      0.3, -2.0,     //
      0.2, 0.5,      //
      0.0, 0.0;
  run2 << -0.4, 0.1,  //
      -0.35, 0.2,     //
      0.0, 0.3;
  const Eigen::Vector2d sigma(0.1, 0.5);
  const DetectionProblem d = detection_problem({"heat"}, {{run1, run2}}, sigma, 2);
  ASSERT_EQ(d.held_sigmas.rows(), 1);
  EXPECT_NEAR(d.held_sigmas(0, 0), 0.35 / 0.1, 1e-12);  // run 2's first two readings
  EXPECT_NEAR(d.held_sigmas(0, 1), 1.0 / 0.5, 1e-12);   // run 1's first two readings
  EXPECT_NEAR(detection_problem({"heat"}, {{run1}}, sigma, 1).held_sigmas(0, 1), 4.0, 1e-12);
  EXPECT_THROW(detection_problem({"heat", "air"}, {{run1}}, sigma, 2), core::DataError);
  EXPECT_THROW(detection_problem({"heat"}, {{}}, sigma, 2), core::DataError);
  EXPECT_THROW(detection_problem({"heat"}, {{run1}}, Eigen::Vector3d::Ones(), 2), core::DataError);
  EXPECT_THROW(detection_problem({"heat"}, {{run1}}, Eigen::Vector2d(0.1, 0), 2), core::DataError);
  EXPECT_THROW(detection_problem({"heat"}, {{run1}}, sigma, 0), core::DataError);
}

}  // namespace
}  // namespace tt::placement
