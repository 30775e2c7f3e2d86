#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <string>
#include <vector>

#include "core/dense_product.hpp"
#include "core/enum_names.hpp"
#include "core/errors.hpp"
#include "core/parallel.hpp"
#include "core/rng.hpp"

using namespace tt::core;

TEST(Errors, LocatedNamesFileAndLine) {
  EXPECT_EQ(located("a.toml", 12, "bad"), "a.toml:12: bad");
  EXPECT_EQ(located("a.toml", 0, "bad"), "a.toml: bad");
  EXPECT_THROW(throw CaseError("x"), Error);
}

namespace {
enum class Colour { red, green, blue };
constexpr std::array<Named<Colour>, 3> kColours{
    {{Colour::red, "red"}, {Colour::green, "green"}, {Colour::blue, "blue"}}};
}  // namespace

TEST(EnumNames, BothDirectionsComeFromOneTable) {
  static_assert(one_to_one(kColours));
  for (const auto& entry : kColours) {
    EXPECT_EQ(name_in(kColours, entry.value), entry.name);
    EXPECT_EQ(value_in(kColours, entry.name), entry.value);
  }
  EXPECT_EQ(name_in(kColours, static_cast<Colour>(7)), "unknown");
  EXPECT_FALSE(value_in(kColours, "Red").has_value());
  EXPECT_EQ(names_list(kColours), "red, green or blue");
  constexpr std::array<Named<Colour>, 2> same_name{{{Colour::red, "a"}, {Colour::green, "a"}}};
  constexpr std::array<Named<Colour>, 2> same_value{{{Colour::red, "a"}, {Colour::red, "b"}}};
  static_assert(!one_to_one(same_name) && !one_to_one(same_value));
}

TEST(Parallel, ChunksAreInOrderWhateverTheThreadCount) {
  for (int threads : {1, 2, 3}) {
    omp_set_num_threads(threads);
    auto chunks =
        parallel_chunks<long>(1001, 100, [](std::ptrdiff_t b, std::ptrdiff_t e, std::ptrdiff_t) {
          long s = 0;
          for (auto i = b; i < e; ++i) s += i;
          return s;
        });
    ASSERT_EQ(chunks.size(), 11u);
    EXPECT_EQ(chunks[0], 4950);
    EXPECT_EQ(chunks[10], 1000);
  }
}

TEST(Parallel, AThrowingBodyRethrowsTheLowestIndexAfterTheLoop) {
  for (int threads : {1, 2}) {
    omp_set_num_threads(threads);
    std::vector<int> done(8, 0);
    try {
      parallel_for(8, [&](std::ptrdiff_t i) {
        if (i == 3 || i == 6) throw SolverError("failed at " + std::to_string(i));
        done[static_cast<std::size_t>(i)] = 1;
      });
      ADD_FAILURE() << "no exception";
    } catch (const SolverError& e) {
      EXPECT_STREQ(e.what(), "failed at 3");
    }
    EXPECT_EQ(std::count(done.begin(), done.end(), 1), 6);  // the others ran to the end
    int first = 0, second = 0;
    parallel_invoke([&] { first = 1; }, [&] { second = 2; });
    EXPECT_EQ(first + second, 3);
  }
}

TEST(Rng, DerivedSeedsDifferPerStreamAndRepeat) {
  EXPECT_NE(derived_seed(1, 0), derived_seed(1, 1));
  EXPECT_NE(derived_seed(1, 0), derived_seed(2, 0));
  EXPECT_EQ(generator(7, 3)(), generator(7, 3)());
}

TEST(DenseProduct, EitherMethodIsTheProduct) {
  // Below the work bound the coefficient-wise product, from it the blocked one (rectangular and
  // transposed operands, as the observer's covariance takes them): both are a b to rounding.
  for (const Eigen::Index n : {Eigen::Index{40}, Eigen::Index{200}}) {
    const Eigen::MatrixXd a = Eigen::MatrixXd::Random(n, n + 3);
    const Eigen::MatrixXd b = Eigen::MatrixXd::Random(n, n + 3);
    const Eigen::MatrixXd got = dense_product(a, b.transpose());
    ASSERT_EQ(got.rows(), n);
    ASSERT_EQ(got.cols(), n);
    Eigen::MatrixXd want = Eigen::MatrixXd::Zero(n, n);
    for (Eigen::Index i = 0; i < n; ++i)
      for (Eigen::Index j = 0; j < n; ++j)
        for (Eigen::Index k = 0; k < a.cols(); ++k) want(i, j) += a(i, k) * b(j, k);
    EXPECT_LT((got - want).cwiseAbs().maxCoeff(), 1e-12 * static_cast<double>(n)) << n << " rows";
  }
  EXPECT_LT(40.0 * 43 * 40, kBlockedProductWork);
  EXPECT_GE(200.0 * 203 * 200, kBlockedProductWork);
}
