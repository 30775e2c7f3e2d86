// The full variant of the calibration study (LABELS long, not in CI): 5-hour runs, the
// calibration at the case's own 12 s step and a finer patch grid, three random draws per effect
// kind. Its printed figures are recorded in docs/benchmarks.md, section "Calibration".
#include <gtest/gtest.h>

#include "calibration_checks.hpp"

namespace tt::calibration {
namespace {

testing::Study& study() {
  testing::Scale sc;
  sc.hours = 5;
  sc.declared_step_s = 12;
  sc.patch_spacing = 0.08;
  sc.patch_half = 0.05;
  static std::unique_ptr<testing::Study> s = testing::make_study(sc);
  return *s;
}

class LongKinds : public ::testing::TestWithParam<int> {};

TEST_P(LongKinds, RightKindPlaceAndRms) {
  const auto kind = static_cast<EffectKind>(GetParam() / 3);
  testing::check_kind(study(), kind, 1000 + static_cast<std::uint64_t>(GetParam()));
}
INSTANTIATE_TEST_SUITE_P(AllKinds, LongKinds, ::testing::Range(0, 24));

}  // namespace
}  // namespace tt::calibration
