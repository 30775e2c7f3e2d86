#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.hpp"
#include "placement/histogram_mi.hpp"
#include "synthetic.hpp"

using namespace tt::placement;

TEST(HistogramMi, EqualWidthBinsPutTheMaximumInTheLastBin) {
  Eigen::VectorXd v(5);
  v << 0.0, 0.49, 0.5, 0.99, 1.0;
  const auto b = equal_width_bins(v, 2);
  EXPECT_EQ(b, (std::vector<std::uint8_t>{0, 0, 1, 1, 1}));
  EXPECT_EQ(equal_width_bins(Eigen::VectorXd::Constant(3, 7.0), 20),
            (std::vector<std::uint8_t>{0, 0, 0}));
  EXPECT_THROW(equal_width_bins(v, 1), tt::core::DataError);
}

TEST(HistogramMi, Formula1OnAHandComputedExample) {
  // Y = (0, 0.1, 0.9, 1.0) in M = 2 bins -> (0, 0, 1, 1); T = (5, 5.2, 5.4, 7) in N = 2 bins
  // -> (0, 0, 0, 1). p(y0,t0) = 1/2, p(y1,t0) = 1/4, p(y1,t1) = 1/4; p(t0) = 3/4, p(y) = 1/2:
  // I = ½·log2(4/3) + ¼·log2(2/3) + ¼·log2(2) = 0.311278 bits.
  Eigen::MatrixXd t(4, 1);
  t << 5.0, 5.2, 5.4, 7.0;
  Eigen::VectorXd y(4);
  y << 0.0, 0.1, 0.9, 1.0;
  const double expected = 0.5 * std::log2(4.0 / 3.0) + 0.25 * std::log2(2.0 / 3.0) + 0.25;
  EXPECT_NEAR(expected, 0.311278, 1e-6);
  const auto p = binned_problem(t, y, 2, 2);
  EXPECT_NEAR(single_mi_bits(p)(0), expected, 1e-12);
  const int set[1] = {0};
  EXPECT_NEAR(joint_mi_bits(p, set), expected, 1e-12);  // formula 2 with m = 1 is formula 1
  EXPECT_NEAR(binned_entropy_bits(p.y_bins, 2), 1.0, 1e-12);
}

TEST(HistogramMi, JointEstimateOfACopyIsTheTargetEntropyAndIsSymmetricInTheSet) {
  synthetic::Normal normal(3);
  Eigen::MatrixXd t(200, 3);
  const Eigen::VectorXd y = normal.vector(200);
  t.col(0) = y;
  t.col(1) = normal.vector(200);
  t.col(2) = normal.vector(200);
  const auto p = binned_problem(t, y, 20, 20);
  const int copy[1] = {0};
  EXPECT_NEAR(joint_mi_bits(p, copy), binned_entropy_bits(p.y_bins, 20), 1e-12);
  const int ab[2] = {1, 2}, ba[2] = {2, 1};
  EXPECT_NEAR(joint_mi_bits(p, ab), joint_mi_bits(p, ba), 1e-12);
  const int too_many[8] = {0, 1, 2, 0, 1, 2, 0, 1};
  EXPECT_THROW(joint_mi_bits(p, too_many), tt::core::DataError);
}

TEST(HistogramMi, EstimateConvergesTowardsTheGaussianTruthAsSamplesGrow) {
  // Bivariate Gaussian, ρ = 0.9: I = −½·log2(1 − 0.81) = 1.198 bits. At the patent's S = 100 and
  // 20 bins the plug-in estimate is biased upwards by about half a bit; with the bins growing as
  // 20·(S/100)^(1/4) the bias and the discretisation loss both shrink and the error falls
  // monotonically. (With 20 bins held fixed it levels off near −0.1 bit: the discretised MI.)
  const double truth = -0.5 * std::log2(1.0 - 0.81);
  double previous_error = INFINITY;
  for (int samples : {100, 1000, 10000, 100000}) {
    synthetic::Normal normal(11);
    const Eigen::VectorXd x = normal.vector(samples);
    const Eigen::VectorXd e = normal.vector(samples);
    Eigen::MatrixXd t(samples, 1);
    t.col(0) = 0.9 * x + std::sqrt(1.0 - 0.81) * e;
    const int bins = static_cast<int>(std::lround(20.0 * std::pow(samples / 100.0, 0.25)));
    const auto p = binned_problem(t, x, bins, bins);
    const double error = std::abs(single_mi_bits(p)(0) - truth);
    if (samples == 100) {
      EXPECT_GT(error, 0.3) << "the small-sample bias the patent lives with";
    }
    EXPECT_LT(error, previous_error) << "S = " << samples;
    previous_error = error;
  }
  EXPECT_LT(previous_error, 0.05 * truth);
}
