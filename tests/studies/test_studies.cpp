// studies::groups_end_to_end: the fitting groups as one placement input.
#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "studies/placement_input.hpp"

namespace {

using namespace tt;

fitting::Group group(const std::string& name, double t0, int n, double value) {
  fitting::Group g;
  g.name = name;
  g.time = Eigen::VectorXd::LinSpaced(n, t0, t0 + 60.0 * (n - 1));
  g.temperature = Eigen::MatrixXd::Constant(n, 2, value);
  g.error = Eigen::MatrixXd::Constant(n, 3, value * 1e-6);
  g.sensor_names = {"T1", "T2"};
  g.target_names = {"dx", "dy", "dz"};
  return g;
}

TEST(Studies, GroupsEndToEndShiftTheTimesAndKeepTheRows) {
  const std::vector<fitting::Group> groups{group("a", 0, 3, 1), group("b", 12, 2, 2),
                                           group("c", 0, 4, 3)};
  const Eigen::MatrixX3d positions = Eigen::MatrixX3d::Random(2, 3);
  const placement::PlacementInput in = studies::groups_end_to_end(groups, {2, 0}, positions, 2);
  ASSERT_EQ(in.times_s.size(), 7);
  for (Eigen::Index i = 1; i < in.times_s.size(); ++i) EXPECT_GT(in.times_s(i), in.times_s(i - 1));
  EXPECT_DOUBLE_EQ(in.times_s(0), 0.0);
  EXPECT_DOUBLE_EQ(in.times_s(4), 180.0 + 1.0);  // group a starts 1 s after c's last reading
  EXPECT_DOUBLE_EQ(in.temperatures_K(0, 0), 3.0);
  EXPECT_DOUBLE_EQ(in.temperatures_K(6, 1), 1.0);
  ASSERT_EQ(in.targets.size(), 2u);
  EXPECT_EQ(in.targets[1].name, "dy");
  EXPECT_DOUBLE_EQ(in.targets[1].values_m(0), 3e-6);
  ASSERT_EQ(in.ids.size(), 2u);
  EXPECT_EQ(static_cast<int>(in.ids[1]), 2);
  EXPECT_TRUE(in.positions_m.isApprox(positions));
}

TEST(Studies, GroupsEndToEndRefusesWhatItCannotLayOut) {
  std::vector<fitting::Group> groups{group("a", 0, 3, 1), group("b", 0, 3, 2)};
  EXPECT_THROW(studies::groups_end_to_end(groups, {}, Eigen::MatrixX3d::Zero(2, 3), 1),
               core::DataError);
  EXPECT_THROW(studies::groups_end_to_end(groups, {0, 2}, Eigen::MatrixX3d::Zero(2, 3), 1),
               core::DataError);
  groups[1].sensor_names = {"T1", "T3"};
  EXPECT_THROW(studies::groups_end_to_end(groups, {0, 1}, Eigen::MatrixX3d::Zero(2, 3), 1),
               core::DataError);
}

}  // namespace
