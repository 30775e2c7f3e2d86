// The virtual campaign's sensor noise: right size, quantised, reproducible.
#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.hpp"
#include "fitting/noise.hpp"
#include "tests/fitting/synthetic.hpp"

using namespace tt::fitting;

TEST(Noise, HasTheRequestedSizeResolutionAndSeed) {
  Group clean = test::thermal_run(0, 1, 4, 5 * 3600.0, 5.0);
  clean.error = Eigen::MatrixXd::Zero(clean.time.size(), 2);
  clean.target_names = {"x", "z"};
  const SensorNoise noise;  // 0.05 K, 0.01 K steps, 0.3 µm
  const Group a = noisy_group(clean, noise, 7, 0);
  const Group b = noisy_group(clean, noise, 7, 0);
  const Group c = noisy_group(clean, noise, 7, 1);
  EXPECT_EQ(a.temperature, b.temperature);
  EXPECT_EQ(a.error, b.error);
  EXPECT_NE(a.temperature, c.temperature);

  const Eigen::ArrayXXd dt = (a.temperature - clean.temperature).array();
  const double t_std = std::sqrt(dt.square().mean());
  // Gaussian noise plus uniform rounding error of one resolution step.
  const double expected = std::sqrt(0.05 * 0.05 + 0.01 * 0.01 / 12.0);
  EXPECT_NEAR(t_std / expected, 1.0, 0.05);
  for (Eigen::Index i = 0; i < a.temperature.size(); ++i) {
    const double steps = a.temperature(i) / 0.01;
    ASSERT_NEAR(steps, std::round(steps), 1e-6) << i;
  }
  const double e_std = std::sqrt(a.error.array().square().mean());
  EXPECT_NEAR(e_std / 0.3e-6, 1.0, 0.05);

  SensorNoise bad;
  bad.temperature_sigma = -1.0;
  EXPECT_THROW(noisy_group(clean, bad, 7, 0), tt::core::DataError);
}
