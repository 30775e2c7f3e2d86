// Pins the node order and parametric coordinates of the kernels to VTK's: the tet10 shape
// functions and their derivatives equal vtkQuadraticTetra's, and the tet4's equal vtkTetra's.
#include <gtest/gtest.h>
#include <vtkNew.h>
#include <vtkQuadraticTetra.h>
#include <vtkTetra.h>

#include "solvers/kernels/element.hpp"

namespace tt::solvers::kernels {
namespace {

const Eigen::Vector3d parametric_points[] = {
    {0.25, 0.25, 0.25}, {0.1, 0.2, 0.3},    {0.7, 0.05, 0.1}, {0.0, 0.5, 0.5},
    {0.3, 0.0, 0.0},    {0.05, 0.05, 0.85}, {0.0, 0.0, 0.0},  {0.2, 0.6, 0.1}};

TEST(VtkOrdering, Tet10ShapeFunctionsMatchVtkQuadraticTetra) {
  for (const Eigen::Vector3d& xi : parametric_points) {
    double weights[10];
    double derivs[30];
    vtkQuadraticTetra::InterpolationFunctions(xi.data(), weights);
    vtkQuadraticTetra::InterpolationDerivs(xi.data(), derivs);
    const Eigen::Matrix<double, 10, 1> n = tet10_shape(xi);
    const Eigen::Matrix<double, 10, 3> d = tet10_shape_derivatives(xi);
    for (int a = 0; a < 10; ++a) {
      EXPECT_NEAR(n(a), weights[a], 1e-14) << "node " << a;
      // VTK stores all d/dr, then all d/ds, then all d/dt.
      for (int j = 0; j < 3; ++j) EXPECT_NEAR(d(a, j), derivs[10 * j + a], 1e-13) << a << "," << j;
    }
  }
}

TEST(VtkOrdering, Tet10NodeParametricCoordinatesMatchVtk) {
  vtkNew<vtkQuadraticTetra> cell;
  const double* pcoords = cell->GetParametricCoords();
  const Eigen::Matrix<double, 3, 10> nodes = tet10_node_natural();
  for (int a = 0; a < 10; ++a) {
    for (int j = 0; j < 3; ++j) EXPECT_DOUBLE_EQ(nodes(j, a), pcoords[3 * a + j]) << "node " << a;
  }
}

TEST(VtkOrdering, Tet4ShapeFunctionsMatchVtkTetra) {
  for (const Eigen::Vector3d& xi : parametric_points) {
    double weights[4];
    vtkTetra::InterpolationFunctions(xi.data(), weights);
    const Eigen::Vector4d n = tet4_shape(xi);
    for (int a = 0; a < 4; ++a) EXPECT_NEAR(n(a), weights[a], 1e-15) << "node " << a;
  }
}

}  // namespace
}  // namespace tt::solvers::kernels
