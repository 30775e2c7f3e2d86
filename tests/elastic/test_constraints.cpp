// Supports that leave a rigid motion free are refused with a SolverError naming how many (rather
// than a singular factorisation or NaN displacements), and the multi-right-hand-side solve gives
// the same columns as one solve per temperature field, linear in T - T_ref.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "core/errors.hpp"
#include "elastic_fixtures.hpp"

namespace tt::elastic_test {
namespace {

constexpr double kE = 1.2e11, kNu = 0.26, kAlpha = 1.1e-5;
const Eigen::Vector3d kSize(0.06, 0.04, 0.03);  // [m]

/// Two bodies stacked in y with different materials, corner points A (origin), B on the x edge,
/// M halfway along it, C on the y edge, and the bottom face as group "base".
BoxCase two_body_block(const std::string& mechanical) {
  BoxCase c;
  c.materials = {{"iron", kE, kNu, kAlpha}, {"steel", 2.1e11, 0.3, 1.2e-5}};
  const double yi = 0.5 * kSize.y();
  c.bodies = {
      {"lower", "iron", Eigen::Vector3d::Zero(), Eigen::Vector3d(kSize.x(), yi, kSize.z()), 0.012},
      {"upper", "steel", Eigen::Vector3d(0, yi, 0), kSize, 0.012}};
  c.points = {{"A", Eigen::Vector3d::Zero()},
              {"B", Eigen::Vector3d(kSize.x(), 0, 0)},
              {"M", Eigen::Vector3d(0.5 * kSize.x(), 0, 0)},
              {"C", Eigen::Vector3d(0, kSize.y(), 0)}};
  c.boundary =
      "[[boundary]]\nname = \"base\"\nselect = [ { plane = { normal = [0.0, 1.0, 0.0], "
      "offset = 0.0 } } ]\n";
  c.mechanical = mechanical;
  c.order = 2;
  return c;
}

constexpr const char* kThreeTwoOne =
    "point_supports = [ { point = \"A\" }, { point = \"B\", fixed = [\"y\", \"z\"] }, "
    "{ point = \"C\", fixed = [\"z\"] } ]";

/// The SolverError message of f(), or "" when it does not throw one.
template <class F>
std::string solver_error(F&& f) {
  try {
    f();
  } catch (const core::SolverError& e) {
    return e.what();
  }
  return "";
}

void expect_refused(const mesh::TetMesh& mesh, const core::CaseSpec& spec, int free_motions) {
  const std::string count = std::to_string(free_motions) + " rigid motion(s) free";
  const std::string from_dofs = solver_error([&] { solvers::constrained_dofs(mesh, spec); });
  EXPECT_NE(from_dofs.find(count), std::string::npos) << "message: " << from_dofs;
  const Eigen::MatrixXd temp = Eigen::MatrixXd::Constant(mesh.nodes.rows(), 2, 330.0);
  const std::string from_history =
      solver_error([&] { solvers::elastic_history(mesh, spec, temp); });
  EXPECT_NE(from_history.find(count), std::string::npos) << "message: " << from_history;
  std::printf("[rigid motion] %s\n", from_history.c_str());
}

TEST(RigidMotion, NoSupportIsRefused) {
  // The case reader already rejects a [mechanical] table without supports ...
  EXPECT_THROW(spec_of(two_body_block("reference_temperature_degC = 20.0")), core::CaseError);
  // ... and the solver refuses a spec built in code without any.
  auto spec = spec_of(two_body_block(kThreeTwoOne));
  const auto mesh = mesh::mesh_case(spec);
  EXPECT_NO_THROW(solvers::constrained_dofs(mesh, spec));
  spec.mechanical.point_supports.clear();
  expect_refused(mesh, spec, 6);
}

TEST(RigidMotion, SupportsInOneDirectionOnlyAreRefused) {
  // Holding u_z at three points fixes z translation and the rotations about x and y only.
  const auto spec = spec_of(two_body_block(
      "point_supports = [ { point = \"A\", fixed = [\"z\"] }, { point = \"B\", fixed = [\"z\"] }, "
      "{ point = \"C\", fixed = [\"z\"] } ]"));
  expect_refused(mesh::mesh_case(spec), spec, 3);
}

TEST(RigidMotion, CollinearPinsLeaveTheRotationAboutTheirLine) {
  // Three points on one line held in x, y, z: nine dofs, but the rotation about the line is free.
  const auto spec = spec_of(two_body_block(
      "point_supports = [ { point = \"A\" }, { point = \"M\" }, { point = \"B\" } ]"));
  expect_refused(mesh::mesh_case(spec), spec, 1);
}

TEST(RigidMotion, ClampedFaceAndThreeTwoOneAreAccepted) {
  const auto spec = spec_of(two_body_block("fixed = [\"base\"]"));
  const auto mesh = mesh::mesh_case(spec);
  const auto held = solvers::constrained_dofs(mesh, spec);
  long count = 0;
  for (char h : held) count += h;
  EXPECT_GT(count, 9);
  const auto pinned = spec_of(two_body_block(kThreeTwoOne));
  const auto held_321 = solvers::constrained_dofs(mesh, pinned);
  count = 0;
  for (char h : held_321) count += h;
  EXPECT_EQ(count, 6);
}

TEST(MultiTime, BlockSolveEqualsSingleSolvesAndIsLinear) {
  const auto spec = spec_of(two_body_block(kThreeTwoOne));
  const auto mesh = mesh::mesh_case(spec);
  const double tref = spec.mechanical.reference_temperature_c;
  // Uniform, linear, and non-polynomial fields [degC], and a combination of the first two.
  const Eigen::VectorXd t0 =
      nodal_temperature_k(mesh, [&](const Eigen::Vector3d&) { return tref + 12.0; });
  const Eigen::VectorXd t1 = nodal_temperature_k(mesh, [&](const Eigen::Vector3d& x) {
    return tref + 300.0 * x.x() - 500.0 * x.y() + 200.0 * x.z();
  });
  const Eigen::VectorXd t2 = nodal_temperature_k(mesh, [&](const Eigen::Vector3d& x) {
    return tref + 15.0 * std::sin(80.0 * x.x()) * std::cos(60.0 * x.y()) +
           5.0 * std::exp(30.0 * x.z());
  });
  const double tref_k = tref + core::kCelsiusOffset;
  const Eigen::VectorXd t3 =
      (tref_k + 2.0 * (t0.array() - tref_k) - 0.5 * (t1.array() - tref_k)).matrix();
  Eigen::MatrixXd temp(mesh.nodes.rows(), 4);
  temp << t0, t1, t2, t3;

  const auto block = solvers::elastic_history(mesh, spec, temp);
  ASSERT_EQ(block.displacement.cols(), 4);
  double worst = 0;
  for (int k = 0; k < 4; ++k) {
    const Eigen::VectorXd single =
        solvers::elastic_history(mesh, spec, temp.col(k)).displacement.col(0);
    ASSERT_GT(single.lpNorm<Eigen::Infinity>(), 0.0);
    worst = std::max(worst, max_relative_error(block.displacement.col(k), single));
  }
  const Eigen::VectorXd combined =
      2.0 * block.displacement.col(0) - 0.5 * block.displacement.col(1);
  const double linearity = max_relative_error(block.displacement.col(3), combined);
  // At T = T_ref the displacement is zero.
  const Eigen::MatrixXd at_ref = Eigen::MatrixXd::Constant(mesh.nodes.rows(), 1, tref_k);
  const double at_ref_norm =
      solvers::elastic_history(mesh, spec, at_ref).displacement.lpNorm<Eigen::Infinity>();
  std::printf(
      "[multi-time] %ld nodes: block vs single solves max rel diff %.2e, superposition %.2e, "
      "max |u| at T_ref %.1e m\n",
      static_cast<long>(mesh.nodes.rows()), worst, linearity, at_ref_norm);
  EXPECT_LT(worst, 1e-12);
  EXPECT_LT(linearity, 1e-10);
  EXPECT_EQ(at_ref_norm, 0.0);
  EXPECT_TRUE(block.displacement.allFinite());
}

TEST(MultiTime, FactoredModelAndInfluenceVectorsAgreeWithTheHistory) {
  const auto spec = spec_of(two_body_block(kThreeTwoOne));
  const auto mesh = mesh::mesh_case(spec);
  const double tref = spec.mechanical.reference_temperature_c;
  Eigen::MatrixXd temp(mesh.nodes.rows(), 3);
  temp << nodal_temperature_k(mesh, [&](const Eigen::Vector3d&) { return tref - 8.0; }),
      nodal_temperature_k(mesh, [&](const Eigen::Vector3d& x) { return tref + 400.0 * x.y(); }),
      nodal_temperature_k(mesh, [&](const Eigen::Vector3d& x) {
        return tref + 10.0 * std::cos(70.0 * x.x() + 40.0 * x.z());
      });
  const solvers::ElasticModel model(mesh, spec);
  const Eigen::MatrixXd u = model.displacements(temp);
  const Eigen::MatrixXd history = solvers::elastic_history(mesh, spec, temp).displacement;
  const double model_vs_history =
      (u - history).lpNorm<Eigen::Infinity>() / history.lpNorm<Eigen::Infinity>();

  // u(node, d) = a . (T - T_ref) at the far corner B (held in y, z; free in x), at C (free in x, y)
  // and at the middle node of the mesh, in every direction; zero at held dofs.
  const Eigen::MatrixXd dt = (temp.array() - model.reference_temperature_k()).matrix();
  double worst = 0;
  int free_checked = 0;
  const int nodes[3] = {mesh::named_node(mesh, "B"), mesh::named_node(mesh, "C"),
                        static_cast<int>(mesh.nodes.rows() / 2)};
  const auto held = solvers::constrained_dofs(mesh, spec);
  for (int node : nodes) {
    for (int d = 0; d < 3; ++d) {
      const Eigen::VectorXd a = model.influence(node, d);
      ASSERT_EQ(a.size(), mesh.nodes.rows());
      const Eigen::RowVectorXd predicted = a.transpose() * dt;
      if (held[3 * node + d]) {
        EXPECT_EQ(a.lpNorm<Eigen::Infinity>(), 0.0);
        continue;
      }
      ++free_checked;
      const Eigen::RowVectorXd solved = u.row(3 * node + d);
      worst = std::max(
          worst, (predicted - solved).lpNorm<Eigen::Infinity>() / u.lpNorm<Eigen::Infinity>());
    }
  }
  std::printf(
      "[influence] model vs history %.1e, influence vs solve max rel diff %.2e over %d "
      "free dofs\n",
      model_vs_history, worst, free_checked);
  EXPECT_LT(model_vs_history, 1e-13);
  EXPECT_EQ(free_checked, 9 - 3);
  EXPECT_LT(worst, 1e-11);
}

// Temperature fields must have one row per mesh node: a field of the corner nodes only on a
// 10-node mesh was once read out of bounds, and extra rows were ignored.
TEST(InputChecks, TemperatureWithWrongRowCountIsRefused) {
  const auto spec = spec_of(two_body_block(kThreeTwoOne));
  const auto mesh = mesh::mesh_case(spec);
  for (Eigen::Index rows : {static_cast<Eigen::Index>(mesh.corner_count), mesh.nodes.rows() + 7}) {
    const Eigen::MatrixXd temp = Eigen::MatrixXd::Constant(rows, 1, 330.0);
    EXPECT_THROW(solvers::elastic_history(mesh, spec, temp), core::SolverError) << rows << " rows";
  }
}

}  // namespace
}  // namespace tt::elastic_test
