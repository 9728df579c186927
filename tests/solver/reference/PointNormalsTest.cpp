// reference::orientedPointNormals (issue 15): a normal per point, oriented alike, for segmenting a
// whole shape (000_… Fig. 10e).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "devsurf/reference/PointNormals.h"

namespace devsurf::reference {
namespace {

/// A random rotation from three uniform numbers.
Eigen::Matrix3d randomTurn(std::mt19937& random) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Vector3d axis(unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5);
  return Eigen::AngleAxisd(2.0 * M_PI * unit(random), axis.normalized()).toRotationMatrix();
}

TEST(PointNormals, AnEllipsoidCloudWithoutNormalsGetsOutwardNormalsInFiftyRandomPoses) {
  std::mt19937 random(1510);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector3d axes(0.5 + 1.5 * unit(random), 0.5 + 1.5 * unit(random), 0.5 + 1.5 * unit(random));
    const Eigen::Matrix3d turn = randomTurn(random);
    const Eigen::Vector3d shift(10 * unit(random), -5 * unit(random), 3 * unit(random));
    ReferenceShape shape;
    const int n = 3000;
    shape.points.resize(n, 3);
    Eigen::MatrixX3d truth(n, 3);
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector3d d = Eigen::Vector3d(gauss(random), gauss(random), gauss(random)).normalized();
      const Eigen::Vector3d p = axes.cwiseProduct(d);
      // The outward normal of x²/a² + y²/b² + z²/c² = 1: the gradient p / axes².
      truth.row(j) = (turn * p.cwiseQuotient(axes.cwiseProduct(axes))).normalized().transpose();
      shape.points.row(j) = (turn * p + shift).transpose();
    }
    const Eigen::MatrixX3d normals = orientedPointNormals(shape);
    ASSERT_EQ(normals.rows(), n);
    int outward = 0, close = 0;
    for (int j = 0; j < n; ++j) {
      const double c = normals.row(j).dot(truth.row(j));
      outward += c > 0.0;
      close += c > std::cos(25.0 * M_PI / 180.0);
    }
    // Orientation is all or nothing per connected cloud; fitted planes at 3 % of the size tilt
    // where the ellipsoid is most curved.
    EXPECT_EQ(outward, n) << "trial " << trial << ", axes " << axes.transpose();
    EXPECT_GE(close, 0.97 * n) << "trial " << trial << ", axes " << axes.transpose();
  }
}

TEST(PointNormals, AMeshsNormalsFollowItsTrianglesOrientation) {
  // An octahedron, triangles counter-clockwise seen from outside; then the same turned inside out.
  ReferenceShape shape;
  shape.points.resize(6, 3);
  shape.points << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  shape.triangles.resize(8, 3);
  shape.triangles << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  Eigen::MatrixX3d normals = orientedPointNormals(shape);
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(normals.row(j).dot(shape.points.row(j)), 1.0, 1e-12) << "vertex " << j;
  shape.triangles.col(1).swap(shape.triangles.col(2));
  normals = orientedPointNormals(shape);
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(normals.row(j).dot(shape.points.row(j)), -1.0, 1e-12) << "vertex " << j;
}

TEST(PointNormals, AFilesNormalsAreKeptAsGivenAndNormalized) {
  ReferenceShape shape;
  shape.points = Eigen::MatrixX3d::Random(10, 3);
  shape.normals = Eigen::MatrixX3d::Random(10, 3) * 3.0;
  const Eigen::MatrixX3d normals = orientedPointNormals(shape);
  for (int j = 0; j < 10; ++j) EXPECT_LT((normals.row(j) - shape.normals.row(j).normalized()).norm(), 1e-12);
}

TEST(PointNormals, RefusesAnEmptyOrNonFiniteShape) {
  ReferenceShape shape;
  shape.points.resize(0, 3);
  EXPECT_THROW(orientedPointNormals(shape), std::invalid_argument);
  shape.points = Eigen::MatrixX3d::Zero(4, 3);
  shape.points(2, 1) = std::nan("");
  EXPECT_THROW(orientedPointNormals(shape), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::reference
