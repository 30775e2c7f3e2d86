#include <gtest/gtest.h>

#include <omp.h>

#include "core/errors.hpp"
#include "core/parallel.hpp"
#include "core/rng.hpp"

using namespace tt::core;

TEST(Errors, LocatedNamesFileAndLine) {
  EXPECT_EQ(located("a.toml", 12, "bad"), "a.toml:12: bad");
  EXPECT_EQ(located("a.toml", 0, "bad"), "a.toml: bad");
  EXPECT_THROW(throw CaseError("x"), Error);
}

TEST(Parallel, ChunksAreInOrderWhateverTheThreadCount) {
  for (int threads : {1, 2, 3}) {
    omp_set_num_threads(threads);
    auto chunks = parallel_chunks<long>(1001, 100, [](std::ptrdiff_t b, std::ptrdiff_t e, std::ptrdiff_t) {
      long s = 0;
      for (auto i = b; i < e; ++i) s += i;
      return s;
    });
    ASSERT_EQ(chunks.size(), 11u);
    EXPECT_EQ(chunks[0], 4950);
    EXPECT_EQ(chunks[10], 1000);
  }
}

TEST(Rng, DerivedSeedsDifferPerStreamAndRepeat) {
  EXPECT_NE(derived_seed(1, 0), derived_seed(1, 1));
  EXPECT_NE(derived_seed(1, 0), derived_seed(2, 0));
  EXPECT_EQ(generator(7, 3)(), generator(7, 3)());
}
