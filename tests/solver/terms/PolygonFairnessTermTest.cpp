#include "devsurf/terms/PolygonFairnessTerm.h"

#include <gtest/gtest.h>

#include <random>

#include "devsurf/engine/JacobianCheck.h"

namespace devsurf::terms {
namespace {

TEST(PolygonFairnessTerm, JacobianMatchesFiniteDifferencesWithScatteredPoints) {
  // Points taken from anywhere in x, as an S edge's polygon is (vertex blocks + its own block).
  PolygonFairnessTerm term("fairness", {9, 0, 15, 3, 21});
  EXPECT_EQ(term.numResiduals(), 3 * 3);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uni(-1, 1);
  Eigen::VectorXd x(24);
  for (int i = 0; i < 24; ++i) x[i] = uni(rng);
  const engine::JacobianCheckResult r = engine::checkJacobian(term, x);
  EXPECT_LT(r.maxRelativeError, 1e-8);
  EXPECT_TRUE(r.structureComplete);
}

TEST(PolygonFairnessTerm, VanishesOnEquallySpacedCollinearPointsOnly) {
  PolygonFairnessTerm term("fairness", {6, 0, 3});
  Eigen::VectorXd x(9);
  x << 1, 1, 1, 2, 2, 2, 0, 0, 0;  // point order: x[6..8], x[0..2], x[3..5] = 0, 1, 2 along a line
  Eigen::Vector3d r;
  term.evaluate(x, r.data(), nullptr);
  EXPECT_LT(r.norm(), 1e-15);
  x[4] = 3.0;  // bend the last point
  term.evaluate(x, r.data(), nullptr);
  EXPECT_DOUBLE_EQ(r[1], 1.0);
}

TEST(PolygonFairnessTerm, RejectsAStencilThatRepeatsAPoint) {
  EXPECT_THROW(PolygonFairnessTerm("f", {0, 3, 0}), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
