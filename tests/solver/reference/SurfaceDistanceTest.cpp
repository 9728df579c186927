// One-sided distances from reference points to a triangle surface, against exact values.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "devsurf/reference/SurfaceDistance.h"

namespace devsurf::reference {
namespace {

/// The unit square z = 0 as two triangles, plus a zero-area sliver that must be ignored.
void unitSquare(Eigen::MatrixX3d& V, Eigen::MatrixX3i& T) {
  V.resize(5, 3);
  V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 2, 0, 0;
  T.resize(3, 3);
  T << 0, 1, 2, 0, 2, 3, 0, 1, 4;  // the last one has its three corners on a line
}

TEST(SurfaceDistance, PointsAboveASquareAreTheirHeightsAwayAndBesideItTheirDistanceToItsEdge) {
  Eigen::MatrixX3d V;
  Eigen::MatrixX3i T;
  unitSquare(V, T);
  std::mt19937 random(3);
  std::uniform_real_distribution<double> u(0.0, 1.0), h(-0.2, 0.2);
  Eigen::MatrixX3d reference(500, 3);
  double maxExact = 0.0, sumSquares = 0.0;
  int within = 0;
  for (int i = 0; i < 500; ++i) {
    double exact;
    if (i % 5 == 4) {  // beside the square, off its right edge x = 1
      const double dx = 0.1 * u(random), z = h(random);
      reference.row(i) << 1.0 + dx, 0.2 + 0.6 * u(random), z;
      exact = std::hypot(dx, z);
    } else {
      const double z = h(random);
      reference.row(i) << u(random), u(random), z;
      exact = std::abs(z);
    }
    maxExact = std::max(maxExact, exact);
    sumSquares += exact * exact;
    within += exact <= 0.05;
  }
  const SurfaceDistance d = surfaceDistance(reference, V, T, 0.05);
  EXPECT_EQ(d.points, 500);
  EXPECT_NEAR(d.maxDistance, maxExact, 1e-12);
  EXPECT_NEAR(d.rmsDistance, std::sqrt(sumSquares / 500), 1e-12);
  EXPECT_NEAR(d.coverage, within / 500.0, 1e-12);
  const double diagonal = (reference.colwise().maxCoeff() - reference.colwise().minCoeff()).norm();
  EXPECT_NEAR(d.diagonal, diagonal, 1e-12);
  EXPECT_NEAR(d.maxRelative, maxExact / diagonal, 1e-12);
  // Default tolerance: 1% of the reference's diagonal.
  EXPECT_NEAR(surfaceDistance(reference, V, T).tolerance, 0.01 * diagonal, 1e-15);
}

TEST(SurfaceDistance, NothingToMeasureIsRefused) {
  Eigen::MatrixX3d V;
  Eigen::MatrixX3i T;
  unitSquare(V, T);
  EXPECT_THROW(surfaceDistance(Eigen::MatrixX3d(0, 3), V, T), std::invalid_argument);
  Eigen::MatrixX3i sliver(1, 3);
  sliver << 0, 1, 4;
  EXPECT_THROW(surfaceDistance(Eigen::MatrixX3d::Zero(1, 3), V, sliver), std::invalid_argument);
  Eigen::MatrixX3i outOfRange(1, 3);
  outOfRange << 0, 1, 9;
  EXPECT_THROW(surfaceDistance(Eigen::MatrixX3d::Zero(1, 3), V, outOfRange), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::reference
