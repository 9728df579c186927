#include "devsurf/terms/TriangleOrientationTerm.h"

#include <gtest/gtest.h>

#include "support/TermTesting.h"

namespace devsurf::terms {
namespace {

// Development vertices at x[2 + 2k]: (0,0), (1,0), (0,1), (1,1).
Eigen::VectorXd square() {
  Eigen::VectorXd x(10);
  x << 7, 7, 0, 0, 1, 0, 0, 1, 1, 1;
  return x;
}

TEST(TriangleOrientationTerm, IsZeroForCounterclockwiseTrianglesAboveTheirMinimumArea) {
  TriangleOrientationTerm term("development_orientation", 2, {{0, 1, 2}, {1, 3, 2}}, {0.05, 0.05});
  EXPECT_EQ(testing::residuals(term, square()).norm(), 0.0);
}

TEST(TriangleOrientationTerm, AMirroredTriangleIsPenalized) {
  TriangleOrientationTerm term("development_orientation", 2, {{0, 1, 2}, {1, 3, 2}}, {0.05, 0.05});
  Eigen::VectorXd x = square();
  x[9] = -1.0;  // vertex 3 to (1, −1): triangle (1, 3, 2) turns clockwise, area −½
  const Eigen::VectorXd r = testing::residuals(term, x);
  EXPECT_EQ(r[0], 0.0);
  EXPECT_DOUBLE_EQ(r[1], hingeResidual(1.0 + 0.5 / 0.05));
}

TEST(TriangleOrientationTerm, JacobianMatchesFiniteDifferencesActiveAndInactive) {
  for (unsigned seed = 1; seed <= 8; ++seed) {
    TriangleOrientationTerm term("development_orientation", 2, {{0, 1, 2}, {1, 3, 2}, {0, 3, 1}}, {0.01, 0.3, 2.0});
    testing::expectJacobianMatches(term, testing::randomVector(10, seed));
    testing::expectNoDuplicateEntries(term);
  }
}

TEST(TriangleOrientationTerm, ReadsVerticesStoredWithThreeScalarsEach) {
  // A quad mesh's planar unfolding: (x, y, z) per vertex from x[1]; vertex 3 mirrored below.
  Eigen::VectorXd x(13);
  x << 9, 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, -1, 0;
  TriangleOrientationTerm term("unfolding_orientation", 1, {{0, 1, 2}, {1, 3, 2}}, {0.05, 0.05}, 3);
  const Eigen::VectorXd r = testing::residuals(term, x);
  EXPECT_EQ(r[0], 0.0);
  EXPECT_DOUBLE_EQ(r[1], hingeResidual(1.0 + 0.5 / 0.05));
  for (unsigned seed = 1; seed <= 4; ++seed) {
    TriangleOrientationTerm random("unfolding_orientation", 1, {{0, 1, 2}, {1, 3, 2}, {0, 3, 1}}, {0.01, 0.3, 2.0}, 3);
    testing::expectJacobianMatches(random, testing::randomVector(13, seed));
    testing::expectNoDuplicateEntries(random);
  }
  EXPECT_THROW(TriangleOrientationTerm("t", 0, {{0, 1, 2}}, {0.1}, 1), std::invalid_argument);
}

TEST(TriangleOrientationTerm, TrianglesWithoutAPositiveMinimumHaveNoRow) {
  TriangleOrientationTerm term("development_orientation", 2, {{0, 1, 2}, {1, 3, 2}}, {0.0, 0.1});
  EXPECT_EQ(term.numResiduals(), 1);
  EXPECT_THROW(TriangleOrientationTerm("o", 0, {{0, 1, 1}}, {1.0}), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
