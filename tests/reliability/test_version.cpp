// thermotwin --version: one line on stdout, exit 0, the version that CMake's project(VERSION)
// declares and, in a git checkout, the git describe of the source it was configured from.
#include <gtest/gtest.h>

#include "tests/reliability/process.hpp"

namespace tt::reliability_test {
namespace {

// No command is given: --version is answered before the check that one is.
TEST(Version, PrintsTheProjectVersionAndTheGitDescribe) {
  const fs::path dir = scratch("version");
  const fs::path log = dir / "version.txt";
  ASSERT_EQ(run({"--version"}, {}, log), 0);
  const std::string text = read_text(log);
  const std::string head = std::string("thermotwin ") + TT_PROJECT_VERSION;
  ASSERT_EQ(text.rfind(head, 0), 0u) << text;
  EXPECT_EQ(text.find('\n'), text.size() - 1) << "one line: " << text;
  if (fs::exists(fs::path(TT_SOURCE_DIR) / ".git")) {
    EXPECT_EQ(text.substr(head.size(), 6), " (git ") << text;
    EXPECT_EQ(text.substr(text.size() - 2), ")\n") << text;
  } else {
    EXPECT_EQ(text, head + "\n");
  }
}

}  // namespace
}  // namespace tt::reliability_test
