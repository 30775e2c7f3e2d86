#include <gtest/gtest.h>

#include <numeric>

#include "core/errors.hpp"
#include "placement/histogram_mi.hpp"
#include "placement/saturation.hpp"
#include "synthetic.hpp"

using namespace tt::placement;

namespace {

/// S = 100 samples: columns 0-2 are the error plus 30 % noise (good sensors), columns 3-29 are
/// independent noise.
BinnedProblem good_and_noise(std::uint64_t seed) {
  synthetic::Normal normal(seed);
  const int samples = 100;
  const Eigen::VectorXd y = normal.vector(samples);
  Eigen::MatrixXd t(samples, 30);
  for (int c = 0; c < 3; ++c) t.col(c) = y + 0.3 * normal.vector(samples);
  for (int c = 3; c < 30; ++c) t.col(c) = normal.vector(samples);
  return binned_problem(t, y, 20, 20);
}

}  // namespace

TEST(Saturation, ShuffleTestSeparatesAGoodSensorFromNoiseWhileTheThreeSensorEstimateDoesNot) {
  const auto p = good_and_noise(5);
  std::vector<int> pool(30);
  std::iota(pool.begin(), pool.end(), 0);
  const SaturationOptions options;

  // One sensor: the shuffle test tells the good one from noise.
  const int good[1] = {0}, noise[1] = {3};
  const auto dg = saturation_diagnosis(p, good, pool, options, 1);
  const auto dn = saturation_diagnosis(p, noise, pool, options, 2);
  EXPECT_LT(dg.p_value, 0.01);
  EXPECT_GT(dg.excess_bits, 0.5);
  EXPECT_GT(dn.p_value, 0.05);
  EXPECT_LT(std::abs(dn.excess_bits), 3.0 * dn.shuffle_sd_bits + 1e-12);
  EXPECT_FALSE(dg.saturated) << dg.reason;
  EXPECT_TRUE(dn.saturated);

  // Three sensors: the raw estimate scores noise like signal, both at the ceiling.
  const int good3[3] = {0, 1, 2}, noise3[3] = {3, 4, 5};
  const double ceiling = binned_entropy_bits(p.y_bins, 20);
  const double ig = joint_mi_bits(p, good3);
  const double in = joint_mi_bits(p, noise3);
  EXPECT_LT(std::abs(ig - in), 0.1 * ceiling);
  EXPECT_GT(in, ceiling - 0.5);
  const auto d3 = saturation_diagnosis(p, noise3, pool, options, 3);
  EXPECT_TRUE(d3.saturated);
  EXPECT_GE(d3.share_near_ceiling, options.share_threshold) << d3.reason;
  EXPECT_GT(d3.singleton_share, 0.8);
  EXPECT_LE(d3.ceiling_bits, std::log2(20.0) + 1e-12);
  // Even the good triple is flagged: its score no longer stands out.
  EXPECT_TRUE(saturation_diagnosis(p, good3, pool, options, 4).saturated);
}

TEST(Saturation, DiagnosisIsReproducibleFromItsSeed) {
  const auto p = good_and_noise(8);
  std::vector<int> pool(30);
  std::iota(pool.begin(), pool.end(), 0);
  const int set[2] = {0, 7};
  const auto a = saturation_diagnosis(p, set, pool, {}, 42);
  const auto b = saturation_diagnosis(p, set, pool, {}, 42);
  EXPECT_EQ(a.p_value, b.p_value);
  EXPECT_EQ(a.shuffle_mean_bits, b.shuffle_mean_bits);
  EXPECT_EQ(a.share_near_ceiling, b.share_near_ceiling);
  SaturationOptions too_few;
  too_few.shuffles = 50;  // p can never fall below 1/51 > alpha = 0.01
  EXPECT_THROW(saturation_diagnosis(p, set, pool, too_few, 42), tt::core::DataError);
}
