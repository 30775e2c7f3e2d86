#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.hpp"
#include "placement/ksg.hpp"
#include "synthetic.hpp"

using namespace tt::placement;

namespace {

Eigen::MatrixXd correlated_pair(int samples, double rho, std::uint64_t seed) {
  synthetic::Normal normal(seed);
  Eigen::MatrixXd xy(samples, 2);
  xy.col(0) = normal.vector(samples);
  xy.col(1) = rho * xy.col(0) + std::sqrt(1.0 - rho * rho) * normal.vector(samples);
  return xy;
}

}  // namespace

TEST(Ksg, BivariateGaussianWithinTenPercentAtTwoThousandSamples) {
  const double truth = -0.5 * std::log2(1.0 - 0.81);  // 1.198 bits
  const Eigen::MatrixXd xy = correlated_pair(2000, 0.9, 21);
  for (int k : {3, 4, 5}) {
    const double est = ksg_mi_bits(xy.col(0), xy.col(1), k);
    RecordProperty("ksg_relative_error_k" + std::to_string(k),
                   std::to_string((est - truth) / truth));
    EXPECT_NEAR(est, truth, 0.1 * truth) << "k = " << k;
  }
}

TEST(Ksg, IndependentVariablesGiveAboutZero) {
  const Eigen::MatrixXd xy = correlated_pair(1000, 0.0, 22);
  EXPECT_NEAR(ksg_mi_bits(xy.col(0), xy.col(1), 4), 0.0, 0.05);
}

TEST(Ksg, MultivariateSetSeesInformationSplitOverTwoSensors) {
  // y = a + b + 0.1·e: each alone carries ½·log2(2.01/1.01) ≈ 0.5 bit, both ½·log2(201).
  synthetic::Normal normal(23);
  const int s = 800;
  Eigen::MatrixXd x(s, 2);
  x.col(0) = normal.vector(s);
  x.col(1) = normal.vector(s);
  const Eigen::VectorXd y = x.col(0) + x.col(1) + 0.1 * normal.vector(s);
  const double one = ksg_mi_bits(x.col(0), y, 4);
  const double both = ksg_mi_bits(x, y, 4);
  EXPECT_NEAR(one, 0.5 * std::log2(2.01 / 1.01), 0.1);
  EXPECT_GT(both, one + 1.5);
  EXPECT_THROW(ksg_mi_bits(x, y, s), tt::core::DataError);
}
