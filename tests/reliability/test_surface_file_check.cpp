// The checks made before CGAL reads a surface file (mesh/cgal/surface_file_check.hpp): what CGAL
// 5.5 would crash on or allocate without bound is refused with a reason; ordinary files pass.
#include <gtest/gtest.h>

#include <string>

#include "mesh/cgal/surface_file_check.hpp"

namespace tt::mesh::cgal {
namespace {

const std::string kPlyBody =
    "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";

std::string ply(const std::string& header_middle) {
  return "ply\nformat ascii 1.0\n" + header_middle + "end_header\n" + kPlyBody;
}

const std::string kPlainVertex =
    "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n";
const std::string kPlainFace = "element face 4\nproperty list uchar int vertex_indices\n";

TEST(PlyHeader, OrdinaryHeadersPass) {
  EXPECT_EQ(ply_header_problem(ply(kPlainVertex + kPlainFace)), std::nullopt);
  // CRLF line ends, comments, extra vertex properties, doubles, a texture list of floats.
  std::string crlf = ply("comment made by hand\nelement vertex 4\nproperty double x\n"
                         "property double y\nproperty double z\nproperty uchar red\n" +
                         kPlainFace + "property list uchar float texcoord\n");
  std::string with_cr;
  for (char c : crlf) with_cr += c == '\n' ? std::string("\r\n") : std::string(1, c);
  EXPECT_EQ(ply_header_problem(with_cr), std::nullopt);
}

TEST(PlyHeader, WhatCgalCrashesOnIsRefused) {
  // F4: a property before any element.
  EXPECT_NE(ply_header_problem("ply\nformat ascii 1.0\nproperty float x\n" + kPlainVertex +
                               kPlainFace + "end_header\n"),
            std::nullopt);
  // F5: a coordinate of an integer type.
  EXPECT_NE(ply_header_problem(ply("element vertex 4\nproperty float x\nproperty float y\n"
                                   "property uint16 z\n" + kPlainFace)),
            std::nullopt);
  // F6: faces with no vertex element.
  EXPECT_NE(ply_header_problem(ply(kPlainFace)), std::nullopt);
  // Unknown keywords and types, a count beyond the file, indices of a floating type, no end.
  EXPECT_NE(ply_header_problem(ply("elemnt vertex 4\n" + kPlainFace)), std::nullopt);
  EXPECT_NE(ply_header_problem(ply(kPlainVertex + "property flot w\n" + kPlainFace)), std::nullopt);
  EXPECT_NE(ply_header_problem(ply("element vertex 99999999999\nproperty float x\n"
                                   "property float y\nproperty float z\n" + kPlainFace)),
            std::nullopt);
  EXPECT_NE(ply_header_problem(ply(kPlainVertex +
                                   "element face 4\nproperty list uchar float vertex_indices\n")),
            std::nullopt);
  EXPECT_NE(ply_header_problem("ply\nformat ascii 1.0\n" + kPlainVertex), std::nullopt);
  // A word that only begins with end_header does not end the header (found by the fuzzer).
  EXPECT_NE(ply_header_problem("ply\nformat ascii 1.0\n" + kPlainVertex + kPlainFace +
                               "end_header0binary\n" + kPlyBody),
            std::nullopt);
  EXPECT_NE(ply_header_problem("solid x\n"), std::nullopt);
}

TEST(PlyHeader, TheReasonNamesTheLine) {
  const auto problem = ply_header_problem(
      ply("element vertex 4\nproperty float x\nproperty float y\nproperty int z\n" + kPlainFace));
  ASSERT_TRUE(problem.has_value());
  EXPECT_NE(problem->find("line 6"), std::string::npos) << *problem;
  EXPECT_NE(problem->find("'int'"), std::string::npos) << *problem;
}

const std::string kOffTetrahedron =
    "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";

TEST(OffFile, OrdinaryFilesPass) {
  EXPECT_EQ(off_problem(kOffTetrahedron), std::nullopt);
  // Comments, blank lines, the counts on the keyword's line, a coloured variant.
  EXPECT_EQ(off_problem("# made by hand\nCOFF 4 4 0\n\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1\n"
                        "0 1 0 1 1 1 1 # a comment\n0 0 1 1 1 1 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n"),
            std::nullopt);
}

TEST(OffFile, CountsBeyondTheFileAreRefused) {
  // F3: a face count beyond 64 bits; F7: one that fits but cannot be in a file this small.
  EXPECT_NE(off_problem("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n"
                        "999999999999999999999999999999999993 1 3 3\n3 1 2 3\n3 0 3 2\n"),
            std::nullopt);
  const auto huge = off_problem("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n"
                                "40000000000000\x9a junk\n3 1 2 3\n3 0 3 2\n");
  ASSERT_TRUE(huge.has_value());
  EXPECT_NE(huge->find("line 8"), std::string::npos) << *huge;
  // CGAL reads a face's count as a double and casts it: negative or huge is undefined behaviour.
  for (const char* count : {"-3", "1e30", "+1e30", "nan", "-0.5e300"})
    EXPECT_NE(off_problem(std::string("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n") +
                          count + " 1 2 3\n3 1 2 3\n3 0 3 2\n"),
              std::nullopt)
        << count;
  for (const char* index : {"-1", "4", "6.7e44", "nan", "0-10"})
    EXPECT_NE(off_problem(std::string("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 ") +
                          index + " 3\n3 1 2 3\n3 0 3 2\n"),
              std::nullopt)
        << index;
  EXPECT_NE(off_problem("OFF\n4000000000 4 0\n0 0 0\n"), std::nullopt);
  EXPECT_NE(off_problem("OFF\n4 1e9 0\n0 0 0\n"), std::nullopt);
}

TEST(OffFile, UnreadVariantsAreRefused) {
  EXPECT_NE(off_problem("OFF BINARY\n"), std::nullopt);
  EXPECT_NE(off_problem("nOFF\n3\n4 4 0\n"), std::nullopt);
  EXPECT_NE(off_problem("4 4 0\n0 0 0\n"), std::nullopt);
  EXPECT_NE(off_problem("OFF\n4 4\n"), std::nullopt);
  EXPECT_NE(off_problem(""), std::nullopt);
}

TEST(PolygonSoup, IndicesMustNameReadVertices) {
  EXPECT_EQ(soup_problem({{0, 1, 2}, {0, 2, 3}}, 4), std::nullopt);
  const auto beyond = soup_problem({{0, 1, 2}, {0, 2, 4}}, 4);
  ASSERT_TRUE(beyond.has_value());
  EXPECT_NE(beyond->find("polygon 1 names vertex 4"), std::string::npos) << *beyond;
  EXPECT_NE(soup_problem({{0, 1}}, 4), std::nullopt);
  EXPECT_NE(soup_problem({{0, 1, 2}}, 0), std::nullopt);
}

}  // namespace
}  // namespace tt::mesh::cgal
