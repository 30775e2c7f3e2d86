// Inputs that made a fuzz target fail (fuzz/regressions/<reader>/) stay as tests: each is read by
// the same entry point and must end in success or a typed project error, never anything else.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "io/case_reader.hpp"
#include "tests/reliability/process.hpp"
#ifdef TT_HAVE_CGAL_SURFACE
#include "mesh/cgal/surface_body.hpp"
#endif

namespace tt::reliability_test {
namespace {

TEST(FuzzRegressions, CaseReader) {
  const auto files = fuzz_regressions("case");
  EXPECT_FALSE(files.empty());
  for (const auto& f : files)
    EXPECT_EQ(escaped([&] { io::case_from_toml(read_text(f), "/nonexistent-tt-fuzz/case.toml"); }),
              "")
        << f;
}

#ifdef TT_HAVE_CGAL_SURFACE
TEST(FuzzRegressions, SurfaceReader) {
  const fs::path dir = scratch("fuzz_surface");
  for (const auto& f : fuzz_regressions("surface")) {
    const std::string input = read_text(f);
    if (input.empty()) continue;
    static const char* const extensions[] = {".stl", ".off", ".ply"};
    const fs::path file =
        dir / (std::string("surface") + extensions[static_cast<unsigned char>(input[0]) % 3]);
    std::ofstream(file, std::ios::binary) << input.substr(1);
    EXPECT_EQ(escaped([&] { mesh::cgal::surface_solid(file, 1e-3, "fuzz body"); }), "") << f;
  }
}
#endif

}  // namespace
}  // namespace tt::reliability_test
