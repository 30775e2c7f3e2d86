#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "placement/series.hpp"

using namespace tt::placement;

TEST(Resample, GivesSEquispacedSamplesWithoutTheInitialState) {
  // An irregular grid on SB-1's 2 h; S = 100 must land on the spec's t = 72·k s.
  Eigen::VectorXd t(6);
  t << 0.0, 10.0, 700.0, 3000.0, 7000.0, 7200.0;
  const Eigen::VectorXd ts = sample_times(t, 100);
  ASSERT_EQ(ts.size(), 100);
  for (int k = 1; k <= 100; ++k) EXPECT_NEAR(ts(k - 1), 72.0 * k, 1e-9);
  EXPECT_EQ(ts(99), 7200.0);
}

TEST(Resample, InterpolatesEachColumnLinearly) {
  Eigen::VectorXd t(5);
  t << 0.0, 1.0, 3.0, 4.0, 10.0;
  Eigen::MatrixXd v(5, 2);
  for (int i = 0; i < 5; ++i) v.row(i) << 2.0 * t(i) + 1.0, t(i) * t(i);
  const Eigen::VectorXd ts = sample_times(t, 7);
  const Eigen::MatrixXd r = resampled(t, v, ts);
  ASSERT_EQ(r.rows(), 7);
  ASSERT_EQ(r.cols(), 2);
  for (int k = 0; k < 7; ++k) EXPECT_NEAR(r(k, 0), 2.0 * ts(k) + 1.0, 1e-12);  // exact for lines
  // t = 10/7·2 = 2.857 lies between 1 and 3: chord of t² there.
  const double tk = ts(1);
  EXPECT_NEAR(r(1, 1), 1.0 + (tk - 1.0) / 2.0 * 8.0, 1e-12);
  EXPECT_NEAR(r(6, 1), 100.0, 1e-12);
}

TEST(Resample, RejectsBadGridsWithTypedErrors) {
  Eigen::VectorXd t(3);
  t << 0.0, 2.0, 2.0;
  EXPECT_THROW(sample_times(t, 10), tt::core::DataError);
  Eigen::VectorXd ok(3);
  ok << 0.0, 1.0, 2.0;
  EXPECT_THROW(sample_times(ok, 1), tt::core::DataError);
  EXPECT_THROW(resampled(ok, Eigen::MatrixXd::Zero(4, 1), ok), tt::core::DataError);
  Eigen::VectorXd outside(1);
  outside << 3.0;
  EXPECT_THROW(resampled(ok, Eigen::MatrixXd::Zero(3, 1), outside), tt::core::DataError);
}

TEST(Resample, UnitColumnsGiveCorrelationsAndZeroForConstants) {
  Eigen::MatrixXd v(4, 3);
  v << 1, 5, 2, 2, 5, 4, 3, 5, 6, 4, 5, 8.5;
  const Eigen::MatrixXd z = unit_columns(v);
  EXPECT_NEAR(z.col(0).norm(), 1.0, 1e-14);
  EXPECT_NEAR(z.col(0).sum(), 0.0, 1e-14);
  EXPECT_EQ(z.col(1).norm(), 0.0);
  EXPECT_GT(z.col(0).dot(z.col(2)), 0.99);
  EXPECT_LT(z.col(0).dot(z.col(2)), 1.0);
}
