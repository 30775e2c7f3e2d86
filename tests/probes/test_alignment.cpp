#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/errors.hpp"
#include "probe_fixtures.hpp"
#include "probes/alignment.hpp"
#include "probes/virtual_signal.hpp"

using namespace tt::probes;
using std::numbers::pi;

namespace {

Eigen::VectorXd shaped_window(int n, double phase) {
  Eigen::VectorXd v(n);
  for (int j = 0; j < n; ++j) {
    const double t = 2 * pi * j / n + phase;
    v(j) = 5e-6 * std::cos(t) + 1e-6 * std::cos(2 * t + 0.7) + 0.6e-6 * std::cos(3 * t + 2.1);
  }
  return v;
}

/// Offset in samples, within [0, P), at which a reading starting at `theta` reaches `theta_ref`.
double true_offset(double theta_ref, double theta, double per_rev) {
  const double turns = (theta_ref - theta) / (2 * pi);
  return (turns - std::floor(turns)) * per_rev;
}

double circular_distance(double a, double b, double period) {
  const double d = std::fmod(std::abs(a - b), period);
  return std::min(d, period - d);
}

}  // namespace

TEST(InformationDistance, ALevelShiftChangesNothing) {
  const Eigen::VectorXd a = shaped_window(200, 0.0);
  const double self = information_distance(a, a, 12);
  // Linear binning leaves a floor above 0, well below any misaligned window.
  EXPECT_GT(self, 0.0);
  EXPECT_LT(self, 0.5 * information_distance(a, shaped_window(200, 1.0), 12));
  // Drift moves the level only: the distance must not see it.
  const Eigen::VectorXd shifted = (a.array() + 7e-6).matrix();
  EXPECT_NEAR(information_distance(a, shifted, 12), self, 1e-9);
}

TEST(InformationDistance, GrowsWithMisalignmentAndIsSymmetric) {
  const Eigen::VectorXd a = shaped_window(200, 0.0);
  const double self = information_distance(a, a, 12);
  const double near = information_distance(a, shaped_window(200, 2 * pi * 3 / 200), 12);
  const double far = information_distance(a, shaped_window(200, 2 * pi * 40 / 200), 12);
  EXPECT_GT(near, self);
  EXPECT_GT(far - self, 2.0 * (near - self));
  const Eigen::VectorXd b = shaped_window(200, 1.0);
  EXPECT_NEAR(information_distance(a, b, 12), information_distance(b, a, 12), 1e-12);
}

TEST(InformationDistance, IsBlindToTheDirectionOfARelation) {
  // Why alignment requires a positive correlation: a mirrored window looks almost identical.
  const Eigen::VectorXd a = shaped_window(200, 0.0);
  const double self = information_distance(a, a, 12);
  const double mirrored = information_distance(a, -a, 12);
  const double misaligned = information_distance(a, shaped_window(200, 2 * pi * 40 / 200), 12);
  EXPECT_LT(mirrored - self, 0.2 * (misaligned - self))
      << self << " " << mirrored << " " << misaligned;
  EXPECT_THROW(information_distance(a, a, 1), tt::core::DataError);
  EXPECT_THROW(information_distance(a, a.head(10), 8), tt::core::DataError);
}

TEST(Alignment, PeriodicExtensionContinuesTheRevolution) {
  VirtualProbeSetup s = fixtures::runout_setup(2);
  s.noise_std_m = 0.0;
  s.speed_rpm = 2950.0;  // 203.39 samples per revolution: not a whole number
  s.revolutions_per_reading = 1.2;
  const VirtualRecord v = virtual_record(s, {{0.0, {}}});
  const double per_rev = v.record.samples_per_revolution();
  const Eigen::MatrixXd ext = periodic_extension(v.record.readings[0].samples_m, per_rev, 600);
  for (Eigen::Index q : {300, 420, 599}) {
    const double theta = v.start_angle_rad[0] + 2 * pi * q / per_rev;
    // Linear interpolation of a 5 µm profile at 203 samples per turn: error below 5 nm.
    EXPECT_NEAR(ext(q, s3_x1), profile_value(s.runout_plane1, theta), 5e-9);
  }
}

TEST(Alignment, FindsTheReferenceAngleToASmallFractionOfASample) {
  VirtualProbeSetup s = fixtures::runout_setup(11);
  s.speed_rpm = 2950.0;
  const DriftHistory h = fixtures::warm_up_history(10);
  const VirtualRecord v = virtual_record(s, h);
  const AlignmentPlan plan = alignment_plan(v.record, {});
  EXPECT_EQ(plan.window_samples, 203);
  for (AlignmentMethod m :
       {AlignmentMethod::information_distance, AlignmentMethod::cross_correlation}) {
    const std::vector<ReadingAlignment> a = record_alignment(v.record, plan, m);
    for (std::size_t i = 1; i < h.size(); ++i) {
      const double want =
          true_offset(v.start_angle_rad[0], v.start_angle_rad[i], plan.samples_per_revolution);
      EXPECT_LT(circular_distance(a[i].offset_samples, want, plan.samples_per_revolution), 0.3)
          << method_name(m) << " reading " << i + 1 << " found " << a[i].offset_samples << ", true "
          << want;
      EXPECT_GT(a[i].runner_up_score, a[i].best_score);
    }
  }
}

TEST(Alignment, PositiveCorrelationResolvesThePureEccentricityMirror) {
  VirtualProbeSetup s = fixtures::runout_setup(4);
  s.runout_plane1 = {{1, 5e-6, 0.3}};
  s.runout_plane2 = {{1, 5e-6, 1.4}};
  const DriftHistory h = fixtures::warm_up_history(8);
  const VirtualRecord v = virtual_record(s, h);
  AlignmentOptions blind;
  blind.require_positive_correlation = false;
  const AlignmentPlan with_sign = alignment_plan(v.record, {});
  const AlignmentPlan without_sign = alignment_plan(v.record, blind);
  const auto good = record_alignment(v.record, with_sign, AlignmentMethod::information_distance);
  const auto bad = record_alignment(v.record, without_sign, AlignmentMethod::information_distance);
  double worst_good = 0.0, worst_bad = 0.0;
  for (std::size_t i = 1; i < h.size(); ++i) {
    const double want =
        true_offset(v.start_angle_rad[0], v.start_angle_rad[i], with_sign.samples_per_revolution);
    worst_good = std::max(worst_good, circular_distance(good[i].offset_samples, want,
                                                        with_sign.samples_per_revolution));
    worst_bad = std::max(worst_bad, circular_distance(bad[i].offset_samples, want,
                                                      with_sign.samples_per_revolution));
  }
  EXPECT_LT(worst_good, 0.5);
  EXPECT_GT(worst_bad, 90.0);  // half a turn (100 samples) off for some reading
}

TEST(Alignment, RejectsAReadingShorterThanOneRevolution) {
  VirtualProbeSetup s = fixtures::runout_setup(1);
  VirtualRecord v = virtual_record(s, fixtures::warm_up_history(4));
  Reading& r = v.record.readings[2];
  r.samples_m = Eigen::MatrixXd(r.samples_m.topRows(150));
  try {
    alignment_plan(v.record, {});
    FAIL() << "a reading of 0.75 revolutions was accepted";
  } catch (const tt::core::DataError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("reading 3"), std::string::npos) << what;
    EXPECT_NE(what.find("more than one revolution"), std::string::npos) << what;
  }
}

TEST(Alignment, RejectsOptionsOutOfRange) {
  const VirtualRecord v = virtual_record(fixtures::runout_setup(1), fixtures::warm_up_history(2));
  AlignmentOptions o;
  o.window_revolutions = 1.5;
  EXPECT_THROW(alignment_plan(v.record, o), tt::core::DataError);
  o = {};
  o.bins = 1;
  EXPECT_THROW(alignment_plan(v.record, o), tt::core::DataError);
  o = {};
  o.probes = {0, 7};
  EXPECT_THROW(alignment_plan(v.record, o), tt::core::DataError);
}
