#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.hpp"
#include "probe_fixtures.hpp"
#include "probes/drift.hpp"

using namespace tt::probes;

TEST(Drift, FormulasOneToFourOnHandMadeLevels) {
  // Columns S1 (y1), S2 (y2), S3 (x1), S4 (x2) [m].
  Eigen::MatrixXd levels(2, 4);
  levels << 10e-6, 20e-6, 30e-6, 40e-6,  //
      11e-6, 23e-6, 29e-6, 42e-6;
  const DriftSeries d = drift_from_levels(levels, {0.0, 300.0}, 0.2);
  ASSERT_EQ(d.points.size(), 2u);
  EXPECT_FALSE(d.has_axial);
  const DriftPoint& p = d.points[1];
  EXPECT_DOUBLE_EQ(p.time_s, 300.0);
  EXPECT_NEAR(p.drift.y1_m, 1e-6, 1e-18);
  EXPECT_NEAR(p.drift.y2_m, 3e-6, 1e-18);
  EXPECT_NEAR(p.drift.x1_m, -1e-6, 1e-18);
  EXPECT_NEAR(p.drift.x2_m, 2e-6, 1e-18);
  EXPECT_NEAR(p.tilt_x_rad, std::atan((2e-6 - -1e-6) / 0.2), 1e-15);
  EXPECT_NEAR(p.tilt_y_rad, std::atan((3e-6 - 1e-6) / 0.2), 1e-15);
  EXPECT_THROW(drift_from_levels(levels, {0.0}, 0.2), tt::core::DataError);
  EXPECT_THROW(drift_from_levels(levels, {0.0, 1.0}, 0.0), tt::core::DataError);
}

TEST(Drift, ArcMeanInterpolatesBetweenSamples) {
  Eigen::MatrixXd s(5, 1);
  s << 0, 1, 2, 3, 4;
  EXPECT_DOUBLE_EQ(arc_mean(s, 0, 0.0, 1), 0.0);
  EXPECT_DOUBLE_EQ(arc_mean(s, 0, 1.25, 1), 1.25);
  EXPECT_DOUBLE_EQ(arc_mean(s, 0, 0.5, 3), 1.5);
  EXPECT_THROW(arc_mean(s, 0, 2.5, 3), tt::core::DataError);
}

// The acceptance check: 5 µm runout, 0.1 µm noise. Information-distance alignment
// recovers the drift within 0.3 µm at every reading and the tilts within 2 µrad, while taking
// each reading's first sample (no alignment) is off by about the runout.
TEST(Drift, RecoversDriftAndTiltOnARunningSpindle) {
  const DriftHistory h = fixtures::warm_up_history();
  for (std::uint64_t seed : {21u, 22u, 23u, 24u}) {
    VirtualProbeSetup s = fixtures::runout_setup(seed);
    s.axial_probe = true;
    const VirtualRecord v = virtual_record(s, h);
    const DriftSeries truth = drift_relative_to_first(h, s.probe_distance_m, true);

    const RecoveredDrift info =
        recovered_drift(v.record, {}, AlignmentMethod::information_distance);
    ASSERT_EQ(info.drift.points.size(), h.size());
    ASSERT_TRUE(info.drift.has_axial);
    for (std::size_t i = 0; i < h.size(); ++i) {
      const DriftState& got = info.drift.points[i].drift;
      const DriftState& want = truth.points[i].drift;
      EXPECT_NEAR(got.x1_m, want.x1_m, 0.3e-6) << "seed " << seed << " reading " << i + 1;
      EXPECT_NEAR(got.y1_m, want.y1_m, 0.3e-6) << "seed " << seed << " reading " << i + 1;
      EXPECT_NEAR(got.x2_m, want.x2_m, 0.3e-6) << "seed " << seed << " reading " << i + 1;
      EXPECT_NEAR(got.y2_m, want.y2_m, 0.3e-6) << "seed " << seed << " reading " << i + 1;
      EXPECT_NEAR(got.z_m, want.z_m, 0.3e-6) << "seed " << seed << " reading " << i + 1;
      EXPECT_NEAR(info.drift.points[i].tilt_x_rad, truth.points[i].tilt_x_rad, 2e-6);
      EXPECT_NEAR(info.drift.points[i].tilt_y_rad, truth.points[i].tilt_y_rad, 2e-6);
    }
    const DriftError none =
        drift_error(recovered_drift(v.record, {}, AlignmentMethod::none).drift, truth);
    EXPECT_GT(none.max_drift_m, 2.5e-6) << "without alignment the runout should show";
    EXPECT_LT(none.max_drift_m, 25e-6);
    EXPECT_GT(none.max_tilt_rad, 10e-6);
    const DriftError xcorr =
        drift_error(recovered_drift(v.record, {}, AlignmentMethod::cross_correlation).drift, truth);
    EXPECT_LT(xcorr.max_drift_m, 0.3e-6);
  }
}

TEST(Drift, ShortReadingsAndOddSamplesPerRevolutionStillAlign) {
  // 1.1 revolutions per reading and 203.4 samples per revolution: the window is completed
  // from the reading's own periodicity.
  const DriftHistory h = fixtures::warm_up_history(8);
  VirtualProbeSetup s = fixtures::runout_setup(31);
  s.speed_rpm = 2950.0;
  s.revolutions_per_reading = 1.1;
  const VirtualRecord v = virtual_record(s, h);
  const DriftError e =
      drift_error(recovered_drift(v.record, {}, AlignmentMethod::information_distance).drift,
                  drift_relative_to_first(h, s.probe_distance_m, false));
  EXPECT_LT(e.max_drift_m, 0.3e-6);
  EXPECT_LT(e.max_tilt_rad, 2e-6);
}

TEST(Drift, RevolutionMeanNeedsNoAngle) {
  // The baseline that averages whole turns: runout cancels without any alignment.
  const DriftHistory h = fixtures::warm_up_history(6);
  const VirtualRecord v = virtual_record(fixtures::runout_setup(41), h);
  const DriftError e =
      drift_error(recovered_drift(v.record, {}, AlignmentMethod::revolution_mean).drift,
                  drift_relative_to_first(h, 0.15, false));
  EXPECT_LT(e.max_drift_m, 0.1e-6);
}
