// The checks made before CGAL reads a surface file (mesh/cgal/surface_file_check.hpp): what CGAL
// 5.5 would crash on or allocate without bound is refused with a reason; ordinary files pass.
#include <gtest/gtest.h>

#include <string>

#include "mesh/cgal/surface_file_check.hpp"

namespace tt::mesh::cgal {
namespace {

const std::string kPlyBody = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";

std::string ply(const std::string& header_middle) {
  return "ply\nformat ascii 1.0\n" + header_middle + "end_header\n" + kPlyBody;
}

const std::string kPlainVertex =
    "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n";
const std::string kPlainFace = "element face 4\nproperty list uchar int vertex_indices\n";

TEST(PlyHeader, OrdinaryHeadersPass) {
  EXPECT_EQ(ply_header_problem(ply(kPlainVertex + kPlainFace)), std::nullopt);
  // CRLF line ends, comments, extra vertex properties, doubles, a texture list of floats.
  std::string crlf =
      ply("comment made by hand\nelement vertex 4\nproperty double x\n"
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
                                   "property uint16 z\n" +
                                   kPlainFace)),
            std::nullopt);
  // F6: faces with no vertex element.
  EXPECT_NE(ply_header_problem(ply(kPlainFace)), std::nullopt);
  // Unknown keywords and types, a count beyond the file, indices of a floating type, no end.
  EXPECT_NE(ply_header_problem(ply("elemnt vertex 4\n" + kPlainFace)), std::nullopt);
  EXPECT_NE(ply_header_problem(ply(kPlainVertex + "property flot w\n" + kPlainFace)), std::nullopt);
  EXPECT_NE(ply_header_problem(ply("element vertex 99999999999\nproperty float x\n"
                                   "property float y\nproperty float z\n" +
                                   kPlainFace)),
            std::nullopt);
  EXPECT_NE(ply_header_problem(
                ply(kPlainVertex + "element face 4\nproperty list uchar float vertex_indices\n")),
            std::nullopt);
  EXPECT_NE(ply_header_problem("ply\nformat ascii 1.0\n" + kPlainVertex), std::nullopt);
  // A list count wider than 8 bits: CGAL would size the list by a count of up to 4e9 (found by
  // the fuzzer: a 17 GB allocation).
  EXPECT_NE(ply_header_problem(
                ply(kPlainVertex + "element face 4\nproperty list uint32 int vertex_indices\n")),
            std::nullopt);
  // A vertex coordinate declared as a list (found by the fuzzer: a null call in CGAL).
  EXPECT_NE(ply_header_problem(ply(kPlainVertex + "property list uchar float x\n" + kPlainFace)),
            std::nullopt);
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

std::string off_with_face(const std::string& second_face) {
  return "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n" + second_face + "\n3 1 2 3\n3 0 3 2\n";
}

TEST(OffFile, OrdinaryFilesAreRead) {
  const OffReading tet = read_off(kOffTetrahedron);
  EXPECT_EQ(tet.problem, "");
  ASSERT_EQ(tet.soup.points.size(), 4u);
  ASSERT_EQ(tet.soup.polygons.size(), 4u);
  EXPECT_EQ(tet.soup.points[3], (std::array<double, 3>{0, 0, 1}));
  EXPECT_EQ(tet.soup.polygons[1], (std::vector<std::size_t>{0, 1, 3}));
  // Comments, blank lines, the counts on the keyword's line, colours after the coordinates and
  // after a face's indices, CRLF line ends, a quad.
  const OffReading coloured = read_off(
      "# made by hand\r\nCOFF 5 2 0\r\n\r\n0 0 0 1 1 1 1\r\n1 0 0 1 1 1 1\r\n"
      "  # a comment line\r\n1 1 0 1 1 1 1 # a comment\r\n0 1 0 1 1 1 1\r\n0 0 1 0 0 0 1\r\n"
      "4 0 1 2 3 255 0 0\r\n3 0 1 4\r\n");
  EXPECT_EQ(coloured.problem, "");
  ASSERT_EQ(coloured.soup.polygons.size(), 2u);
  EXPECT_EQ(coloured.soup.polygons[0], (std::vector<std::size_t>{0, 1, 2, 3}));
  EXPECT_EQ(coloured.soup.points[2], (std::array<double, 3>{1, 1, 0}));
}

TEST(OffFile, CountsAndIndicesOutOfRangeAreRefused) {
  // F3, F7, F8: face counts beyond 64 bits, beyond the file, negative; F9: indices that CGAL casts
  // from doubles (huge, negative, glued to a minus sign), or that name no vertex.
  for (const char* face : {"999999999999999999999999999999999993 1 3 3", "40000000000000\x9a junk",
                           "-3 1 2 3", "1e30 1 2 3", "nan 1 2 3", "3 0 6.7e44 3", "3 0 -1 3",
                           "3 0 0-10 3", "3 0 4 3", "3 0 1", "2 0 1", ""})
    EXPECT_NE(read_off(off_with_face(face)).problem, "") << face;
  const OffReading huge = read_off(off_with_face("40000000000000 junk"));
  EXPECT_NE(huge.problem.find("line 8"), std::string::npos) << huge.problem;
  EXPECT_TRUE(huge.soup.points.empty());
  EXPECT_NE(read_off("OFF\n4000000000 4 0\n0 0 0\n").problem, "");
  EXPECT_NE(read_off("OFF\n4 1e9 0\n0 0 0\n").problem, "");
  // F10's far vertex is read here (it is finite) and refused by surface_solid; non-finite is not.
  EXPECT_NE(read_off("OFF\n4 4 0\n0 0 0\n1 nan 0\n0 1 0\n0 0 1\n").problem, "");
  EXPECT_NE(read_off("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n").problem, "");
}

TEST(OffFile, UnreadVariantsAreRefused) {
  EXPECT_NE(read_off("OFF BINARY\n").problem, "");
  EXPECT_NE(read_off("nOFF\n3\n4 4 0\n").problem, "");
  EXPECT_NE(read_off("4OFF\n4 4 0\n").problem, "");
  EXPECT_NE(read_off("4 4 0\n0 0 0\n").problem, "");
  EXPECT_NE(read_off("OFF\n4 4\n").problem, "");
  EXPECT_NE(read_off("").problem, "");
}

TEST(PolygonSoup, IndicesMustNameReadVertices) {
  EXPECT_EQ(soup_problem({{0, 1, 2}, {0, 2, 3}}, 4), std::nullopt);
  const auto beyond = soup_problem({{0, 1, 2}, {0, 2, 4}}, 4);
  ASSERT_TRUE(beyond.has_value());
  EXPECT_NE(beyond->find("polygon 1 names vertex 4"), std::string::npos) << *beyond;
  EXPECT_NE(soup_problem({{0, 1}}, 4), std::nullopt);
  EXPECT_NE(soup_problem({{0, 1, 2}}, 0), std::nullopt);
}

// F15: CGAL's triangulation of polygon faces dereferenced a null face on a degenerate polygon; the
// soup is now split here, and only flat convex polygons are split.
TEST(PolygonSoup, FlatConvexPolygonsAreSplitAsFans) {
  const std::vector<std::array<double, 3>> square{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const Triangulation t = fan_triangulated(square, {{0, 1, 2, 3}, {0, 1, 2}});
  ASSERT_EQ(t.problem, "");
  const std::vector<std::vector<std::size_t>> expected{{0, 1, 2}, {0, 2, 3}, {0, 1, 2}};
  EXPECT_EQ(t.triangles, expected);
}

TEST(PolygonSoup, DegenerateOrConcaveOrWarpedPolygonsAreRefused) {
  auto problem = [](const std::vector<std::array<double, 3>>& points,
                    const std::vector<std::size_t>& polygon) {
    const Triangulation t = fan_triangulated(points, {{0, 1, 2}, polygon});
    EXPECT_TRUE(t.triangles.empty());
    return t.problem;
  };
  const std::vector<std::array<double, 3>> square{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  EXPECT_NE(problem(square, {0, 1, 2, 0}).find("polygon 1 (4 vertices) names a vertex twice"),
            std::string::npos);
  const std::vector<std::array<double, 3>> line{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  EXPECT_NE(problem(line, {0, 1, 2, 3}).find("has no area"), std::string::npos);
  const std::vector<std::array<double, 3>> dart{{0, 0, 0}, {2, 0, 0}, {1, 0.5, 0}, {1, 2, 0}};
  EXPECT_NE(problem(dart, {0, 1, 2, 3}).find("not strictly convex"), std::string::npos);
  const std::vector<std::array<double, 3>> straight{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {1, 1, 0}};
  EXPECT_NE(problem(straight, {0, 1, 2, 3}).find("corner 1 is straight"), std::string::npos);
  const std::vector<std::array<double, 3>> warped{{0, 0, 0}, {1, 0, 0}, {1, 1, 0.1}, {0, 1, 0}};
  EXPECT_NE(problem(warped, {0, 1, 2, 3}).find("is not flat"), std::string::npos);
  // The F15 input's shape: a polygon that returns to its first vertex.
  EXPECT_NE(problem(square, {0, 1, 2, 3, 0}).find("names a vertex twice"), std::string::npos);
}

}  // namespace
}  // namespace tt::mesh::cgal
