// Checkerboard curvatures (004_… §2.2.1 eq. 4) from given vertex normals: exact values where the
// normals are an affine function of the vertices, convergence to the smooth curvature otherwise.

#include <gtest/gtest.h>

#include "support/QuadGridTesting.h"

#include <cmath>
#include <iostream>
#include <stdexcept>

#include <Eigen/Geometry>

#include "devsurf/metrics/CheckerboardCurvature.h"

namespace devsurf::metrics {
namespace {

using devsurf::testing::QuadGrid;
using devsurf::testing::quadGrid;

Eigen::MatrixX3d unitSquare() {
  Eigen::MatrixX3d v(4, 3);
  v << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  return v;
}

TEST(CheckerboardCurvature, ReadsKHAndPrincipalFramesOfAHandComputedFace) {
  // n_i = (−2x, −3y, 1): s(d) = diag(2, 3) d on the plane z = 0, so K = 6, H = 2.5, κ1 = 3 along
  // y, κ2 = 2 along x (the ruling: smaller |κ|), n_f = e_z.
  const Eigen::MatrixX3d mesh = unitSquare();
  Eigen::MatrixX3d normals(4, 3);
  for (int i = 0; i < 4; ++i) normals.row(i) << -2 * mesh(i, 0), -3 * mesh(i, 1), 1;
  for (const std::array<int, 4>& face : {std::array<int, 4>{0, 1, 2, 3}, {0, 1, 2, -1}}) {
    const FaceCurvature c = checkerboardCurvature(mesh, normals, {face}).at(0);
    EXPECT_TRUE(c.valid);
    EXPECT_NEAR(c.gauss, 6.0, 1e-14);
    EXPECT_NEAR(c.mean, 2.5, 1e-14);
    EXPECT_NEAR(c.principalMax, 3.0, 1e-14);
    EXPECT_NEAR(c.principalMin, 2.0, 1e-14);
    EXPECT_NEAR(std::abs(c.directionMax.y()), 1.0, 1e-14);
    EXPECT_NEAR(std::abs(c.directionMin.x()), 1.0, 1e-14);
    EXPECT_NEAR(std::abs(c.ruling.x()), 1.0, 1e-14);
    EXPECT_NEAR((c.normal - Eigen::Vector3d(0, 0, 1)).norm(), 0.0, 1e-15);
  }
  // Clockwise order flips n_f but not the curvatures (they depend on the normals' side only).
  const FaceCurvature flipped = checkerboardCurvature(mesh, normals, {{0, 3, 2, 1}}).at(0);
  EXPECT_NEAR(flipped.normal.z(), -1.0, 1e-15);
  EXPECT_NEAR(flipped.gauss, 6.0, 1e-14);
  EXPECT_NEAR(flipped.mean, 2.5, 1e-14);
  // Opposite normals: H changes sign, K does not.
  const FaceCurvature opposite = checkerboardCurvature(mesh, -normals, {{0, 1, 2, 3}}).at(0);
  EXPECT_NEAR(opposite.gauss, 6.0, 1e-14);
  EXPECT_NEAR(opposite.mean, -2.5, 1e-14);
  EXPECT_NEAR(opposite.principalMax, -2.0, 1e-14);
  EXPECT_NEAR(std::abs(opposite.ruling.x()), 1.0, 1e-14);
}

TEST(CheckerboardCurvature, StaysFiniteForANonSymmetricOperatorAndADegenerateFace) {
  // n_i = rotation of v_i by 90° about z: s is a rotation, K = 1, H = 0, complex eigenvalues.
  const Eigen::MatrixX3d mesh = unitSquare();
  Eigen::MatrixX3d normals(4, 3);
  for (int i = 0; i < 4; ++i) normals.row(i) << mesh(i, 1), -mesh(i, 0), 1;
  const FaceCurvature c = checkerboardCurvature(mesh, normals, {{0, 1, 2, 3}}).at(0);
  EXPECT_NEAR(c.gauss, 1.0, 1e-14);
  EXPECT_NEAR(c.mean, 0.0, 1e-14);
  EXPECT_EQ(c.principalMax, c.principalMin);
  EXPECT_NEAR(c.directionMax.norm(), 1.0, 1e-14);
  EXPECT_NEAR(c.directionMax.dot(c.directionMin), 0.0, 1e-14);

  Eigen::MatrixX3d line = mesh;
  line.row(3) = line.row(1) = Eigen::RowVector3d(1, 0, 0);
  line.row(2) << 2, 0, 0;
  const FaceCurvature degenerate = checkerboardCurvature(line, normals, {{0, 1, 2, 3}}).at(0);
  EXPECT_FALSE(degenerate.valid);
  EXPECT_EQ(degenerate.gauss, 0.0);
  EXPECT_TRUE(degenerate.ruling.allFinite());
  EXPECT_THROW(checkerboardCurvature(mesh, normals, {{0, 1, 2, 4}}), std::invalid_argument);
  EXPECT_THROW(checkerboardCurvature(mesh, normals.topRows(3), {{0, 1, 2, 3}}),
               std::invalid_argument);
}

TEST(CheckerboardCurvature, IsExactOnASphereWithRadialNormals) {
  // Latitude band of a sphere, r = 2; n = ±v/r is linear in v, so s = ∓(1/r)·I exactly.
  const double r = 2.0;
  const QuadGrid grid = quadGrid(
      [r](double u, double v) {
        return Eigen::Vector3d(r * std::cos(v) * std::cos(u), r * std::cos(v) * std::sin(u),
                               r * std::sin(v));
      },
      0.0, 2 * M_PI, 13, -1.2, 1.2, 7, true);
  const Eigen::MatrixX3d outward = grid.vertices / r;
  for (const FaceCurvature& c : checkerboardCurvature(grid.vertices, outward, grid.faces)) {
    EXPECT_NEAR(c.gauss, 1.0 / (r * r), 1e-13);
    EXPECT_NEAR(c.mean, -1.0 / r, 1e-13);  // outward normals: the sphere bends away from them
  }
  for (const FaceCurvature& c : checkerboardCurvature(grid.vertices, -outward, grid.faces)) {
    EXPECT_NEAR(c.gauss, 1.0 / (r * r), 1e-13);
    EXPECT_NEAR(c.mean, 1.0 / r, 1e-13);
  }
}

TEST(CheckerboardCurvature, IsExactOnACylinderWithNormalsTowardTheAxis) {
  // r = 0.5, normals −(x, y, 0)/r (toward the axis): K = 0, H = 1/(2r), ruling along the axis.
  const double r = 0.5;
  const QuadGrid grid = quadGrid(
      [r](double u, double v) { return Eigen::Vector3d(r * std::cos(u), r * std::sin(u), v); },
      0.0, 2 * M_PI, 9, 0.0, 1.0, 4, true);
  Eigen::MatrixX3d inward = -grid.vertices / r;
  inward.col(2).setZero();
  for (const FaceCurvature& c : checkerboardCurvature(grid.vertices, inward, grid.faces)) {
    EXPECT_NEAR(c.gauss, 0.0, 1e-13);
    EXPECT_NEAR(c.mean, 1.0 / (2 * r), 1e-13);
    EXPECT_NEAR(c.principalMax, 1.0 / r, 1e-13);
    EXPECT_NEAR(c.principalMin, 0.0, 1e-13);
    EXPECT_NEAR(std::abs(c.ruling.z()), 1.0, 1e-13);
    EXPECT_NEAR(c.directionMax.z(), 0.0, 1e-13);
  }
}

/// Torus, R = 2, r = 0.7: K = cos v / (r (R + r cos v)) changes sign.
Eigen::Vector3d torus(double u, double v) {
  const double R = 2.0, r = 0.7;
  return {(R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u),
          r * std::sin(v)};
}
double torusGauss(double v) {
  const double R = 2.0, r = 0.7;
  return std::cos(v) / (r * (R + r * std::cos(v)));
}

/// Largest |K − K(face centre)| ÷ max |K| over the faces of a torus with its exact unit normals.
double torusGaussError(int cells) {
  const QuadGrid grid = quadGrid(torus, 0.0, 2 * M_PI, 2 * cells, 0.0, 2 * M_PI, cells, true, true);
  Eigen::MatrixX3d normals(grid.vertices.rows(), 3);
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < 2 * cells; ++i) {
      const double u = 2 * M_PI * i / (2 * cells), v = 2 * M_PI * j / cells;
      normals.row(j * 2 * cells + i) << std::cos(v) * std::cos(u), std::cos(v) * std::sin(u),
          std::sin(v);
    }
  const auto curvatures = checkerboardCurvature(grid.vertices, normals, grid.faces);
  double error = 0.0, largest = 0.0;
  bool positive = false, negative = false;
  for (size_t f = 0; f < curvatures.size(); ++f) {
    const double exact = torusGauss(grid.faceCentres[f].y());
    error = std::max(error, std::abs(curvatures[f].gauss - exact));
    largest = std::max(largest, std::abs(exact));
    positive |= curvatures[f].gauss > 0.1;
    negative |= curvatures[f].gauss < -0.1;
  }
  EXPECT_TRUE(positive && negative);
  return error / largest;
}

TEST(CheckerboardCurvature, ConvergesToTheGaussCurvatureOfATorusAtSecondOrder) {
  const double coarse = torusGaussError(16), fine = torusGaussError(32);
  std::cout << "torus, exact normals: max |ΔK| / max |K| = " << coarse << " (16×32), " << fine
            << " (32×64)\n";
  EXPECT_LT(fine, 0.01);
  EXPECT_LT(fine, coarse / 3.0);  // second order: ÷4 per halving
}

}  // namespace
}  // namespace devsurf::metrics
