#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/errors.hpp"
#include "probe_fixtures.hpp"
#include "probes/virtual_signal.hpp"

using namespace tt::probes;
using std::numbers::pi;

TEST(VirtualSignal, ProbesSeeDriftPlusProfileAtTheirDirection) {
  VirtualProbeSetup s = fixtures::runout_setup(3);
  s.noise_std_m = 0.0;
  s.axial_probe = true;
  const DriftHistory h = {{0.0, {1e-6, 2e-6, 3e-6, 4e-6, 5e-6}}};
  const VirtualRecord v = virtual_record(s, h);
  const Reading& r = v.record.readings.at(0);
  const double per_rev = v.record.samples_per_revolution();
  ASSERT_DOUBLE_EQ(per_rev, 200.0);
  ASSERT_EQ(r.samples_m.rows(), 500);  // 2.5 revolutions
  ASSERT_EQ(r.samples_m.cols(), 5);
  for (Eigen::Index j : {0, 37, 199, 451}) {
    const double theta = v.start_angle_rad[0] + 2 * pi * j / per_rev;
    EXPECT_NEAR(r.samples_m(j, s3_x1), 1e-6 + profile_value(s.runout_plane1, theta), 1e-15);
    EXPECT_NEAR(r.samples_m(j, s1_y1), 2e-6 + profile_value(s.runout_plane1, theta - pi / 2),
                1e-15);
    EXPECT_NEAR(r.samples_m(j, s4_x2), 3e-6 + profile_value(s.runout_plane2, theta), 1e-15);
    EXPECT_NEAR(r.samples_m(j, s2_y2), 4e-6 + profile_value(s.runout_plane2, theta - pi / 2),
                1e-15);
    EXPECT_NEAR(r.samples_m(j, s5_z), 5e-6 + profile_value(s.runout_axial, theta), 1e-15);
  }
  // The signal repeats after one revolution.
  EXPECT_NEAR(r.samples_m(10, s3_x1), r.samples_m(210, s3_x1), 1e-15);
}

TEST(VirtualSignal, SeededAndStartingAtContinuousRandomAngles) {
  const DriftHistory h = fixtures::warm_up_history(8);
  const VirtualRecord a = virtual_record(fixtures::runout_setup(7), h);
  const VirtualRecord b = virtual_record(fixtures::runout_setup(7), h);
  const VirtualRecord c = virtual_record(fixtures::runout_setup(8), h);
  EXPECT_EQ(a.record.readings[3].samples_m, b.record.readings[3].samples_m);
  EXPECT_NE(a.start_angle_rad[3], c.start_angle_rad[3]);
  const double step = 2 * pi / a.record.samples_per_revolution();
  double largest_fraction = 0.0;
  for (double angle : a.start_angle_rad) {
    EXPECT_GE(angle, 0.0);
    EXPECT_LT(angle, 2 * pi);
    const double fraction = angle / step - std::floor(angle / step);
    largest_fraction = std::max(largest_fraction, std::min(fraction, 1.0 - fraction));
  }
  // Not all on the sample grid: some start falls well between two sample angles.
  EXPECT_GT(largest_fraction, 0.1);
}

TEST(VirtualSignal, NoiseHasTheRequestedSpread) {
  VirtualProbeSetup s = fixtures::runout_setup(5);
  s.runout_plane1.clear();
  s.runout_plane2.clear();
  const VirtualRecord v = virtual_record(s, {{0.0, {}}});
  const Eigen::VectorXd col = v.record.readings[0].samples_m.col(s1_y1);
  const double sd = std::sqrt((col.array() - col.mean()).square().mean());
  EXPECT_NEAR(sd, 0.1e-6, 0.015e-6);
}

TEST(VirtualSignal, RejectsReadingsOfOneRevolutionOrLess) {
  VirtualProbeSetup s = fixtures::runout_setup(1);
  s.revolutions_per_reading = 1.0;
  try {
    virtual_record(s, fixtures::warm_up_history(2));
    FAIL() << "a one-revolution reading was accepted";
  } catch (const tt::core::DataError& e) {
    EXPECT_NE(std::string(e.what()).find("revolutions_per_reading"), std::string::npos) << e.what();
  }
}

TEST(VirtualSignal, TrueDriftIsRelativeToTheFirstReading) {
  const DriftHistory h = {{0.0, {1e-6, 1e-6, 1e-6, 1e-6, 0}}, {60.0, {1e-6, 2e-6, 4e-6, 1e-6, 0}}};
  const DriftSeries d = drift_relative_to_first(h, 0.1, false);
  ASSERT_EQ(d.points.size(), 2u);
  EXPECT_DOUBLE_EQ(d.points[0].drift.x2_m, 0.0);
  EXPECT_DOUBLE_EQ(d.points[1].drift.x2_m, 3e-6);
  EXPECT_DOUBLE_EQ(d.points[1].tilt_x_rad, std::atan(3e-6 / 0.1));
  EXPECT_DOUBLE_EQ(d.points[1].tilt_y_rad, std::atan(-1e-6 / 0.1));
}
