// Surface candidates for sensor placement ([placement] candidates = "surface"): the set is
// exactly the corner vertices of the chosen body's exterior (checked against the box geometry,
// for 4- and 10-node meshes), of the chosen groups, thinned evenly on request, with listed named
// points under their own ids; the histories a campaign records there equal the nodal
// temperatures of a direct thermal run; candidates.csv reads back exactly.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "core/errors.hpp"
#include "io/candidates_csv.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"
#include "solvers/campaign.hpp"
#include "solvers/thermal.hpp"
#include "studies/histories.hpp"
#include "tests/common/case_toml.hpp"

namespace tt::candidates_test {
namespace {

namespace fs = std::filesystem;

// A block [0, 0.1] x [0, 0.08] x [0, 0.06] [m] with a cap of the same footprint on top
// (z up to 0.09), heated in the cap, fixed at the block's base.
constexpr double kX = 0.1, kY = 0.08, kZ = 0.06, kTop = 0.09;

std::string two_box_case(int order, const std::string& placement) {
  std::string t = test_toml::header("two boxes") + test_toml::steel();
  t += test_toml::box_body("block", "steel", "0.03", "[0.0, 0.0, 0.0]", "[0.1, 0.08, 0.06]");
  t += test_toml::box_body("cap", "steel", "0.03", "[0.0, 0.0, 0.06]", "[0.1, 0.08, 0.09]");
  t += "[mesh]\norder = " + std::to_string(order) + "\n";
  t += "[[boundary]]\nname = \"base\"\nselect = [ { bodies = [\"block\"], plane = { normal = [0.0, "
       "0.0, 1.0], "
       "offset = 0.0 } } ]\n";
  t += "[[boundary]]\nname = \"rest\"\nrest = true\nselect = [ {} ]\n";
  t += "[thermal]\nstep_s = 30.0\noutput_interval_s = 60.0\n";
  t += "[[thermal.convection]]\ngroup = \"rest\"\nh_W_m2K = 10.0\nsink_degC = 20.0\n";
  t += "[[thermal.heat_sources]]\nname = \"heat\"\nbody = \"cap\"\npower_ref_W = "
       "40.0\nref_speed_rpm = 1000.0\n";
  t += "[duty_cycle]\nend_s = 600.0\nsegments = [ { start_s = 0.0, speed_rpm = 1000.0 }, { start_s "
       "= 300.0, "
       "speed_rpm = 0.0 } ]\n";
  t += "[mechanical]\nfixed = [\"base\"]\ntcp = \"TCP\"\nprobes = [\"Z1\", \"Z2\"]\n";
  t += "[points]\nlist = [ { id = \"TCP\", position = [0.05, 0.04, 0.09] }, { id = \"Z1\", "
       "position = [0.0, 0.04, "
       "0.07] }, { id = \"Z2\", position = [0.0, 0.04, 0.08] }, { id = \"S1\", position = [0.1, "
       "0.04, 0.03] } ]\n";
  return t + placement;
}

core::CaseSpec spec_of(int order, const std::string& placement) {
  return io::case_from_toml(two_box_case(order, placement), "two_boxes.toml");
}

bool near(double a, double b) {
  return std::abs(a - b) < 1e-9;
}

/// On the block's outside: its side faces and base; on its top only the rim (the rest of the
/// top is the interface with the cap, where no sensor can go).
bool on_block_outside(const Eigen::RowVector3d& x) {
  const bool side = near(x(0), 0) || near(x(0), kX) || near(x(1), 0) || near(x(1), kY);
  return x(2) <= kZ + 1e-9 && (side || near(x(2), 0));
}

/// Mesh nodes of the block's tets, by the geometry alone.
std::vector<int> block_outside_nodes(const mesh::TetMesh& m, bool corners_only) {
  std::set<int> out;
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t) {
    if (m.region_names[static_cast<size_t>(core::index_of(m.tet_region[static_cast<size_t>(t)]))] !=
        "block")
      continue;
    for (int a = 0; a < m.nodes_per_tet(); ++a) {
      const int n = m.tets(t, a);
      if ((!corners_only || n < m.corner_count) && on_block_outside(m.nodes.row(n))) out.insert(n);
    }
  }
  return {out.begin(), out.end()};
}

const std::string kSurfaceBlock = "[placement]\ncandidates = \"surface\"\nbodies = [\"block\"]\n";

class SurfaceCandidates : public ::testing::TestWithParam<int> {};

TEST_P(SurfaceCandidates, AreTheCornerVerticesOfTheBodysOutside) {
  const int order = GetParam();
  const core::CaseSpec spec = spec_of(order, kSurfaceBlock);
  const mesh::TetMesh m = mesh::mesh_case(spec);
  const studies::CandidateSet set = studies::candidate_set(spec, m);

  const std::vector<int> expected = block_outside_nodes(m, true);
  ASSERT_GT(expected.size(), 20u);
  EXPECT_EQ(set.nodes, expected) << set.nodes.size() << " candidates, " << expected.size()
                                 << " outside corners";
  ASSERT_EQ(set.names.size(), set.nodes.size());
  ASSERT_EQ(set.positions.rows(), static_cast<Eigen::Index>(set.nodes.size()));
  for (size_t c = 0; c < set.nodes.size(); ++c) {
    EXPECT_EQ(set.names[c], "v" + std::to_string(set.nodes[c]));
    EXPECT_EQ(set.positions.row(static_cast<Eigen::Index>(c)), m.nodes.row(set.nodes[c]));
  }
  if (order == 2) {
    // The surface has mid-edge nodes too; none of them is a candidate.
    const auto all = block_outside_nodes(m, false);
    EXPECT_GT(all.size(), expected.size() + 20);
    EXPECT_LT(*std::max_element(set.nodes.begin(), set.nodes.end()), m.corner_count);
  }
}

INSTANTIATE_TEST_SUITE_P(Order, SurfaceCandidates, ::testing::Values(1, 2),
                         [](const auto& info) { return info.param == 1 ? "FourNode" : "TenNode"; });

TEST(SurfaceCandidateSet, GroupsNamedPointsAndThinning) {
  // A boundary group: its faces' corners, here the block's base z = 0.
  const core::CaseSpec base =
      spec_of(1, "[placement]\ncandidates = \"surface\"\ngroups = [\"base\"]\n");
  const mesh::TetMesh m = mesh::mesh_case(base);
  const auto on_base = studies::candidate_set(base, m);
  std::vector<int> expected;
  for (int n = 0; n < m.corner_count; ++n)
    if (near(m.nodes(n, 2), 0)) expected.push_back(n);
  EXPECT_EQ(on_base.nodes, expected);

  // A listed named point comes first under its id, and its vertex is not listed twice.
  const core::CaseSpec with_point = spec_of(1, kSurfaceBlock + "points = [\"S1\"]\n");
  const auto all = studies::candidate_set(with_point, m);  // same geometry: the same mesh
  const int s1 = mesh::named_node(m, "S1");
  ASSERT_GE(s1, 0);
  EXPECT_EQ(all.names.front(), "S1");
  EXPECT_EQ(all.nodes.front(), s1);
  EXPECT_EQ(std::count(all.nodes.begin(), all.nodes.end(), s1), 1);
  EXPECT_EQ(all.nodes.size(), block_outside_nodes(m, true).size());

  // Thinned: as many as asked, a subset, spread out: farthest-point sampling leaves no vertex
  // farther from the chosen ones than the closest two chosen ones are from each other.
  const core::CaseSpec thin = spec_of(1, kSurfaceBlock + "max_candidates = 25\n");
  const auto few = studies::candidate_set(thin, m);
  ASSERT_EQ(few.nodes.size(), 25u);
  const auto full = block_outside_nodes(m, true);
  EXPECT_TRUE(std::includes(full.begin(), full.end(), few.nodes.begin(), few.nodes.end()));
  double separation = INFINITY, cover = 0;
  for (size_t i = 0; i < few.nodes.size(); ++i)
    for (size_t j = i + 1; j < few.nodes.size(); ++j)
      separation =
          std::min(separation, (m.nodes.row(few.nodes[i]) - m.nodes.row(few.nodes[j])).norm());
  for (int n : full) {
    double nearest = INFINITY;
    for (int c : few.nodes) nearest = std::min(nearest, (m.nodes.row(n) - m.nodes.row(c)).norm());
    cover = std::max(cover, nearest);
  }
  EXPECT_LE(cover, separation + 1e-12);
  EXPECT_GT(separation, 0.01);  // 25 points on a 0.1 x 0.08 x 0.06 box do not bunch up
}

TEST(SurfaceCandidateSet, CampaignHistoriesEqualTheNodalTemperaturesOfADirectRun) {
  const core::CaseSpec spec = spec_of(1, kSurfaceBlock + "points = [\"S1\"]\n");
  const mesh::TetMesh m = mesh::mesh_case(spec);
  const studies::CandidateSet set = studies::candidate_set(spec, m);
  const auto results =
      solvers::simulate_campaign(m, spec, {{"case", "the case", spec}}, {}, set.nodes);
  ASSERT_EQ(results.size(), 1u);
  const auto& r = results[0];
  const studies::Histories h =
      studies::histories_from_nodes(spec, set, r.times, r.node_temperature, r.error);

  const solvers::ThermalHistory direct =
      solvers::thermal_history(m, spec, solvers::thermal_system(m, spec));
  ASSERT_EQ(h.times.size(), static_cast<Eigen::Index>(direct.times.size()));
  ASSERT_EQ(h.temperature.cols(), static_cast<Eigen::Index>(set.nodes.size()));
  double worst = 0;
  for (size_t c = 0; c < set.nodes.size(); ++c)
    for (size_t t = 0; t < direct.times.size(); ++t)
      worst = std::max(
          worst,
          std::abs(h.temperature(static_cast<Eigen::Index>(t), static_cast<Eigen::Index>(c)) -
                   direct.temperature(set.nodes[c], static_cast<Eigen::Index>(t))));
  EXPECT_LE(worst, 1e-9);
  // The cap is heated: the block's surface warms, most near the interface.
  EXPECT_GT(h.temperature.bottomRows(1).maxCoeff() - h.temperature.topRows(1).maxCoeff(), 0.05);
  EXPECT_EQ(h.names, set.names);
  EXPECT_EQ(h.nodes, set.nodes);
  EXPECT_EQ(h.target_names, (std::vector<std::string>{"dy", "dz"}));
  EXPECT_GT(h.targets.cwiseAbs().maxCoeff(), 0.0);
  // The listed named point's column is the named-point history the campaign records anyway.
  const auto s1 = static_cast<Eigen::Index>(
      std::find_if(m.points.begin(), m.points.end(), [](const auto& p) { return p.id == "S1"; }) -
      m.points.begin());
  EXPECT_EQ(h.temperature.col(0), r.point_temperature.col(s1));
}

TEST(SurfaceCandidateSet, NamedPointsModeIsTodaysCandidatesOrTheListedOnes) {
  const core::CaseSpec all = spec_of(1, "");
  const mesh::TetMesh m = mesh::mesh_case(all);
  EXPECT_EQ(studies::candidate_set(all, m).names,
            std::vector<std::string>{"S1"});  // not TCP, Z1, Z2
  const core::CaseSpec listed = spec_of(1, "[placement]\npoints = [\"S1\"]\n");
  EXPECT_EQ(studies::candidate_set(listed, m).nodes, std::vector<int>{mesh::named_node(m, "S1")});
}

TEST(SurfaceCandidateSet, BadNamesAreCaseErrorsNamingKeyAndValue) {
  const auto message = [](const std::string& placement) {
    try {
      spec_of(1, placement);
    } catch (const core::CaseError& e) {
      return std::string(e.what());
    }
    return std::string("no CaseError");
  };
  const std::string body = message("[placement]\ncandidates = \"surface\"\nbodies = [\"blok\"]\n");
  EXPECT_NE(body.find("two_boxes.toml:"), std::string::npos) << body;
  EXPECT_NE(body.find("placement.bodies[0] = \"blok\""), std::string::npos) << body;
  EXPECT_NE(body.find("did you mean 'block'?"), std::string::npos) << body;
  const std::string group =
      message("[placement]\ncandidates = \"surface\"\ngroups = [\"bottom\"]\n");
  EXPECT_NE(group.find("placement.groups[0] = \"bottom\""), std::string::npos) << group;
  EXPECT_NE(group.find("no boundary group of that name"), std::string::npos) << group;
}

TEST(CandidatesCsv, ReadsBackExactlyAndRejectsAMalformedFile) {
  const fs::path dir = fs::temp_directory_path() / ("tt_candidates_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  io::CandidateTable t;
  t.ids = {"S1", "v17", "v4096"};
  t.nodes = {3, 17, 4096};
  t.positions.resize(3, 3);
  t.positions << 0.1, 0.04, 0.03, 1.0 / 3.0, -2e-7, 0.06, 0.1 + 0.2, 0.08, 1e-300;
  io::write_candidates_csv(dir / "candidates.csv", t);
  const io::CandidateTable back = io::read_candidates_csv(dir / "candidates.csv");
  EXPECT_EQ(back.ids, t.ids);
  EXPECT_EQ(back.nodes, t.nodes);
  EXPECT_EQ(back.positions, t.positions);

  std::ofstream(dir / "bad.csv") << "id,node,x_m,y_m,z_m\nv1,1,0,0,0\nv1,2,0,0,0\n";
  try {
    io::read_candidates_csv(dir / "bad.csv");
    ADD_FAILURE() << "a repeated id was accepted";
  } catch (const core::DataError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:3"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace tt::candidates_test
