// Bad input to the mesher: each is a typed error whose message names the file and the thing that
// is wrong; through the CLI, a non-zero exit and no output directory.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

#include "core/errors.hpp"
#include "io/case_reader.hpp"
#include "io/child_process.hpp"
#include "mesh/mesher.hpp"
#include "mesh/tetgen/tetgen_adapter.hpp"
#include "mesh_fixtures.hpp"

namespace tt::mesh::test {
namespace {

using Eigen::Vector3d;

const std::string kBlock =
    "[[bodies]]\nname = \"block\"\nmaterial = \"steel\"\nmax_edge = 0.05\n"
    "add = [ { box = { min = [0.0, 0.0, 0.0], max = [0.1, 0.1, 0.1] } } ]\n";

template <class E, class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type: " << e.what();
    return "";
  }
  ADD_FAILURE() << "no exception";
  return "";
}

void expect_has(const std::string& msg, const std::string& part) {
  EXPECT_NE(msg.find(part), std::string::npos) << "'" << part << "' not in: " << msg;
}

TEST(BadInput, NonPositiveSizeIsACaseErrorFromTheReader) {
  TempDir dir;
  std::string body = kBlock;
  body.replace(body.find("max_edge = 0.05"), 15, "max_edge = 0.0");
  const auto file = dir.write("zero.toml", small_case(body));
  const std::string msg = error_of<core::CaseError>([&] { io::read_case(file); });
  expect_has(msg, "zero.toml");
  expect_has(msg, "max_edge");
}

TEST(BadInput, OverlappingBodiesWithoutASubtractionAreAGeometryError) {
  TempDir dir;
  const std::string other =
      "[[bodies]]\nname = \"pin\"\nmaterial = \"steel\"\nmax_edge = 0.05\n"
      "add = [ { cylinder = { axis = [0.1, 0.05], radius = 0.02, z = [0.0, 0.1] } } ]\n";
  const auto spec = io::read_case(dir.write("overlap.toml", small_case(kBlock + other)));
  const std::string msg = error_of<core::GeometryError>([&] { mesh_case(spec); });
  expect_has(msg, "overlap.toml");
  expect_has(msg, "'block' and 'pin' overlap");
  expect_has(msg, "subtract");
}

TEST(BadInput, NamedPointOutsideEveryBodyIsAGeometryError) {
  TempDir dir;
  const auto spec = io::read_case(dir.write(
      "far.toml", small_case(kBlock, "  { id = \"far\", position = [0.05, 0.05, 0.2] },")));
  const std::string msg = error_of<core::GeometryError>([&] { mesh_case(spec); });
  expect_has(msg, "far.toml");
  expect_has(msg, "'far'");
  expect_has(msg, "outside every body");
}

TEST(BadInput, NamedPointInsideASubtractedVoidIsOutsideEveryBody) {
  TempDir dir;
  const std::string hollow =
      "[[bodies]]\nname = \"block\"\nmaterial = \"steel\"\nmax_edge = 0.05\n"
      "add = [ { box = { min = [0.0, 0.0, 0.0], max = [0.1, 0.1, 0.1] } } ]\n"
      "subtract = [ { box = { min = [0.03, 0.03, 0.03], max = [0.07, 0.07, 0.07] } } ]\n";
  const auto spec = io::read_case(dir.write(
      "void.toml", small_case(hollow, "  { id = \"hole\", position = [0.05, 0.05, 0.05] },")));
  const std::string msg = error_of<core::GeometryError>([&] { mesh_case(spec); });
  expect_has(msg, "void.toml");
  expect_has(msg, "'hole'");
  expect_has(msg, "outside every body");
}

TEST(BadInput, NamedPointOffTheFaceItNamesIsAGeometryError) {
  TempDir dir;
  // Inside the block, 1 mm below the top face it claims to be on.
  const auto spec = io::read_case(dir.write(
      "off.toml",
      small_case(kBlock, "  { id = \"T1\", position = [0.05, 0.05, 0.099], on = \"outside\" },")));
  const std::string msg = error_of<core::GeometryError>([&] { mesh_case(spec); });
  expect_has(msg, "off.toml");
  expect_has(msg, "'T1' is not on boundary group 'outside'");
}

/// A unit cube with two inner facets that cross each other: TetGen must refuse it.
Plc crossing_facets() {
  Plc plc;
  for (int k = 0; k < 8; ++k) plc.vertices.emplace_back(k & 1, (k >> 1) & 1, (k >> 2) & 1);
  for (const auto& q : std::vector<std::vector<int>>{
           {0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}})
    plc.facets.push_back(PlcFacet{{q}, {}});
  const int a = static_cast<int>(plc.vertices.size());
  for (const auto& p : {Vector3d(0.2, 0.2, 0.5), Vector3d(0.8, 0.2, 0.5), Vector3d(0.8, 0.8, 0.5),
                        Vector3d(0.2, 0.8, 0.5), Vector3d(0.5, 0.3, 0.2), Vector3d(0.5, 0.7, 0.2),
                        Vector3d(0.5, 0.7, 0.8), Vector3d(0.5, 0.3, 0.8)})
    plc.vertices.push_back(p);
  plc.facets.push_back(PlcFacet{{{a, a + 1, a + 2, a + 3}}, {}});
  plc.facets.push_back(PlcFacet{{{a + 4, a + 5, a + 6, a + 7}}, {}});
  plc.regions.push_back(PlcRegion{Vector3d(0.1, 0.1, 0.1), 0, 0.01});
  return plc;
}

// TetGen 1.5.0 (Debian libtet1.5 1.5.0-5) frees its mesh before throwing and again while
// unwinding, so run in the caller's process this input kills it; the adapter runs TetGen in a
// child process and must turn the failure into a MeshError.
TEST(BadInput, TetgenFailureIsAMeshErrorNamingTetgenAndItsSwitches) {
  const std::string msg =
      error_of<core::MeshError>([] { tetgen::tetrahedralize(crossing_facets(), TetgenOptions{}); });
  expect_has(msg, "TetGen failed with switches 'pzAaQq1.5/12'");
  expect_has(msg, "16 vertices");
  expect_has(msg, "8 facets");
  expect_has(msg, "self-intersection");
  expect_has(msg, "TetGen error code 3");
  expect_has(msg, "Hint");
}

TEST(BadInput, TetgenFailureMessageCarriesWhatTetgenPrinted) {
  // The unit cube plus a triangle lying in its bottom face: TetGen names the two facets.
  Plc plc = crossing_facets();
  plc.facets.resize(6);
  plc.vertices.resize(8);
  plc.vertices.emplace_back(0.5, 0.5, 0.0);
  plc.facets.push_back(PlcFacet{{{0, 1, 8}}, {}});
  const std::string msg =
      error_of<core::MeshError>([&] { tetgen::tetrahedralize(plc, TetgenOptions{}); });
  expect_has(msg, "TetGen failed with switches 'pzAaQq1.5/12'");
  expect_has(msg, "TetGen error code 3");
  expect_has(msg, "Found two facets intersect each other. | 1st: [0, 1, 3] #5 | 2nd: [0, 1, 8] #7");
}

/// Sum of the tets' volumes [m^3].
double volume_of(const LinearTets& mesh) {
  double volume = 0;
  for (const auto& t : mesh.tets) {
    const Vector3d& a = mesh.nodes[t[0]];
    volume += (mesh.nodes[t[1]] - a).cross(mesh.nodes[t[2]] - a).dot(mesh.nodes[t[3]] - a) / 6;
  }
  return volume;
}

TEST(BadInput, AfterATetgenFailureTheCallerStillMeshesAndGetsTheSameMeshTwice) {
  EXPECT_THROW(tetgen::tetrahedralize(crossing_facets(), TetgenOptions{}), core::MeshError);
  Plc cube = crossing_facets();
  cube.facets.resize(6);  // the unit cube alone; the inner facets' vertices stay as free points
  const LinearTets first = tetgen::tetrahedralize(cube, TetgenOptions{});
  ASSERT_GT(first.tets.size(), 100u);
  EXPECT_NEAR(volume_of(first), 1.0, 1e-12);
  for (const auto& t : first.tets) {
    const Vector3d& a = first.nodes[t[0]];
    EXPECT_GT((first.nodes[t[1]] - a).cross(first.nodes[t[2]] - a).dot(first.nodes[t[3]] - a), 0);
  }
  EXPECT_EQ(first.region, std::vector<int>(first.tets.size(), 0));
  for (size_t i = 0; i < cube.vertices.size(); ++i)
    EXPECT_EQ(first.nodes[i], cube.vertices[i]) << "PLC vertex " << i << " moved";
  const LinearTets second = tetgen::tetrahedralize(cube, TetgenOptions{});
  EXPECT_EQ(second.nodes, first.nodes);
  EXPECT_EQ(second.tets, first.tets);
}

TEST(BadInput, ImpossibleQualityBoundsAreAMeshErrorBeforeTetgenRuns) {
  Plc plc = crossing_facets();
  plc.facets.resize(6);
  const std::string msg = error_of<core::MeshError>([&] {
    tetgen::tetrahedralize(plc, TetgenOptions{1.5, 40.0});
  });
  expect_has(msg, "min_dihedral_deg = 40");
  expect_has(msg, "<= 18");
}

#ifdef TT_CLI
/// Exit status of `thermotwin mesh CASE --out OUT`, its output (only this run's) in `log`.
int mesh_cli(const fs::path& case_file, const fs::path& out, const fs::path& log) {
  fs::remove(log);
  return io::run_program({TT_CLI, "mesh", case_file.string(), "--out", out.string()}, {}, log);
}

std::string text_of(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(BadInput, CliExitsNonZeroAndLeavesNoOutputDirectory) {
  TempDir dir;
  dir.write("cube.stl", stl_text(without_face(cube(Vector3d(0, 0, 0), 0.1), 0)));
  const std::string open_body =
      "[[bodies]]\nname = \"part\"\nmaterial = \"steel\"\nmax_edge = 0.05\n"
      "add = [ { surface = { file = \"cube.stl\" } } ]\n";
  const std::string pin =
      "[[bodies]]\nname = \"pin\"\nmaterial = \"steel\"\nmax_edge = 0.05\n"
      "add = [ { cylinder = { axis = [0.1, 0.05], radius = 0.02, z = [0.0, 0.1] } } ]\n";
  std::string zero = kBlock;
  zero.replace(zero.find("max_edge = 0.05"), 15, "max_edge = -1.0");
  struct Bad {
    std::string name, text, named;  /// case file, its text, the file the message must name
  };
  const std::vector<Bad> cases = {
      {"size.toml", small_case(zero), "size.toml"},
      {"overlap.toml", small_case(kBlock + pin), "overlap.toml"},
      {"open.toml", small_case(open_body), "cube.stl"},
      {"outside.toml", small_case(kBlock, "  { id = \"far\", position = [0.05, 0.05, 0.2] },"),
       "outside.toml"},
      {"off_face.toml",
       small_case(kBlock, "  { id = \"T1\", position = [0.05, 0.05, 0.099], on = \"outside\" },"),
       "off_face.toml"}};
  for (const auto& [name, text, named] : cases) {
    const fs::path out = dir.path() / (name + ".out");
    const int code = mesh_cli(dir.write(name, text), out, dir.path() / "log.txt");
    EXPECT_NE(code, 0) << name;
    EXPECT_FALSE(fs::exists(out)) << name;
    EXPECT_FALSE(fs::exists(fs::path(out.string() + ".partial"))) << name;
    const std::string log = text_of(dir.path() / "log.txt");
    expect_has(log, named);
    expect_has(log, "error");
  }
  // The same driver on a good case succeeds, so the failures above are the inputs' fault.
  const fs::path out = dir.path() / "good.out";
  EXPECT_EQ(mesh_cli(dir.write("good.toml", small_case(kBlock)), out, dir.path() / "log.txt"), 0);
  EXPECT_TRUE(fs::exists(out / "mesh.vtu"));
}
#endif

}  // namespace
}  // namespace tt::mesh::test
