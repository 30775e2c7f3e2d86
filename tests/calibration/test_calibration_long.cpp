// The long variants of the calibration study (LABELS long, not in CI); their printed figures are
// recorded in docs/benchmarks.md, section "Calibration".
// - LongKinds: 5-hour runs, the calibration at the case's own 12 s step and a finer patch grid,
//   three random draws per effect kind.
// - MoreDraws: the CI scale with further draws per kind (seeds 100 and 200 above the CI tests'),
//   for the kinds whose drawn magnitudes reach down to the detection limit.
#include <gtest/gtest.h>

#include "calibration_checks.hpp"

namespace tt::calibration {
namespace {

testing::Study& long_study() {
  testing::Scale sc;
  sc.hours = 5;
  sc.declared_step_s = 12;
  sc.patch_spacing = 0.08;
  sc.patch_half = 0.05;
  static std::unique_ptr<testing::Study> s = testing::make_study(sc);
  return *s;
}

testing::Study& ci_study() {
  static std::unique_ptr<testing::Study> s = testing::make_study(testing::Scale{});
  return *s;
}

class LongKinds : public ::testing::TestWithParam<int> {};

TEST_P(LongKinds, RightKindPlaceAndRms) {
  const auto kind = static_cast<EffectKind>(GetParam() / 3);
  testing::check_kind(long_study(), kind, 1000 + static_cast<std::uint64_t>(GetParam()));
}
INSTANTIATE_TEST_SUITE_P(AllKinds, LongKinds, ::testing::Range(0, 24));

// Seeds as the CI tests draw them: 11 + kind, plus 100 or 200.
class MoreDraws : public ::testing::TestWithParam<int> {};

TEST_P(MoreDraws, RightKindPlaceAndRms) {
  const auto kind = static_cast<EffectKind>(GetParam() % 8);
  const auto seed = static_cast<std::uint64_t>(11 + GetParam() % 8 + 100 * (1 + GetParam() / 8));
  testing::check_kind(ci_study(), kind, seed);
}
INSTANTIATE_TEST_SUITE_P(CiScale, MoreDraws, ::testing::Range(0, 16));

}  // namespace
}  // namespace tt::calibration
