// VertexAngleSumTerm (000_… §5 "Local developability in vertices").

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include <Eigen/Geometry>

#include "devsurf/engine/JacobianCheck.h"
#include "devsurf/terms/VertexAngleSumTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::randomVector;
using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::residuals;

TEST(VertexAngleSumTerm, JacobianMatchesFiniteDifferences) {
  VertexAngleSumTerm closed("vertex", 0, {3, 6, 9, 12, 15});
  EXPECT_EQ(closed.numResiduals(), 1);
  expectNoDuplicateEntries(closed);
  for (unsigned seed : {71u, 72u, 73u}) expectJacobianMatches(closed, randomVector(18, seed));
  VertexAngleSumTerm open("vertex", 13, {0, 7, 3, 16}, VertexAngleSumTerm::Star::Open, 2.5);
  expectNoDuplicateEntries(open);
  expectJacobianMatches(open, randomVector(19, 74));
}

TEST(VertexAngleSumTerm, JacobianMatchesFiniteDifferencesNearlyFlatAndAtSmallAngles) {
  // A nearly planar star (residual ≈ 0) and a star with a 1e-3 rad angle.
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.3, -1, 0.6).normalized()).toRotationMatrix();
  Eigen::VectorXd x(15);
  x.head<3>() = Eigen::Vector3d(0.1, 0.2, 0.3);
  const double t[4] = {0.0, 1.0e-3, 2.5, 4.0};
  for (int i = 0; i < 4; ++i)
    x.segment<3>(3 + 3 * i) =
        x.head<3>() + R * Eigen::Vector3d((1 + 0.2 * i) * std::cos(t[i]),
                                          (1 + 0.2 * i) * std::sin(t[i]), 0.01 * (i % 2));
  VertexAngleSumTerm term("vertex", 0, {3, 6, 9, 12});
  const engine::JacobianCheckResult r = engine::checkJacobian(term, x, 1e-7);
  EXPECT_LT(r.maxRelativeError, 1e-6);  // FD at a 1e-3 angle needs the smaller step
  expectJacobianMatches(term, randomVector(15, 75));
}

TEST(VertexAngleSumTerm, VanishesOnAFlatStarInATiltedPlane) {
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 1, 0.2).normalized()).toRotationMatrix();
  const Eigen::Vector3d v(0.5, -0.3, 1.2);
  const double angles[5] = {0.1, 1.3, 2.0, 3.9, 5.2};
  Eigen::VectorXd x(18);
  x.head<3>() = v;
  for (int i = 0; i < 5; ++i)
    x.segment<3>(3 + 3 * i) =
        v + R * Eigen::Vector3d((0.5 + i) * std::cos(angles[i]), (0.5 + i) * std::sin(angles[i]),
                                0.0);
  VertexAngleSumTerm term("vertex", 0, {3, 6, 9, 12, 15});
  EXPECT_NEAR(residuals(term, x)[0], 0.0, 1e-14);
  EXPECT_NEAR(term.angleSum(x), 2.0 * M_PI, 1e-14);
}

TEST(VertexAngleSumTerm, PyramidApexHasKnownAngleDefect) {
  // Apex (0,0,√2) over the square (±1, ±1, 0): every face angle is π/3 (cos = 2/4), so the
  // angle sum is 4π/3 and the residual −2π/3.
  Eigen::VectorXd x(15);
  x << 0, 0, std::sqrt(2.0),  1, 1, 0,  -1, 1, 0,  -1, -1, 0,  1, -1, 0;
  VertexAngleSumTerm term("vertex", 0, {3, 6, 9, 12});
  EXPECT_NEAR(residuals(term, x)[0], -2.0 * M_PI / 3.0, 1e-14);
  expectJacobianMatches(term, x);
}

TEST(VertexAngleSumTerm, OpenStarComparesWithThePrescribedSum) {
  Eigen::VectorXd x(12);
  x << 0, 0, 0,  1, 0, 0,  0, 2, 0,  -3, 0, 0;
  VertexAngleSumTerm straight("vertex", 0, {3, 6, 9}, VertexAngleSumTerm::Star::Open, M_PI);
  EXPECT_NEAR(residuals(straight, x)[0], 0.0, 1e-15);
  VertexAngleSumTerm flat("vertex", 0, {3, 6, 9}, VertexAngleSumTerm::Star::Open);
  EXPECT_NEAR(residuals(flat, x)[0], -M_PI, 1e-15);
  // Closed, the same three neighbours add the angle from (−3,0,0) back to (1,0,0): π.
  VertexAngleSumTerm closed("vertex", 0, {3, 6, 9});
  EXPECT_NEAR(residuals(closed, x)[0], 0.0, 1e-15);
}

TEST(VertexAngleSumTerm, ParallelEdgesGiveAFiniteJacobian) {
  Eigen::VectorXd x(12);
  x << 0, 0, 0,  1, 0, 0,  2, 0, 0,  0, 1, 0;
  VertexAngleSumTerm term("vertex", 0, {3, 6, 9});
  std::vector<engine::JacobianEntry> entries;
  term.jacobianStructure(entries);
  std::vector<double> J(entries.size());
  double r = 0;
  term.evaluate(x, &r, J.data());
  EXPECT_NEAR(r, 0.0 + M_PI / 2 + M_PI / 2 - 2.0 * M_PI, 1e-15);
  for (double v : J) EXPECT_TRUE(std::isfinite(v));
}

TEST(VertexAngleSumTerm, RejectsTooFewNeighboursAndSharedVariables) {
  EXPECT_THROW(VertexAngleSumTerm("v", 0, {3, 6}), std::invalid_argument);
  EXPECT_THROW(VertexAngleSumTerm("v", 0, {3}, VertexAngleSumTerm::Star::Open),
               std::invalid_argument);
  EXPECT_THROW(VertexAngleSumTerm("v", 0, {3, 6, 8}), std::invalid_argument);
  EXPECT_THROW(VertexAngleSumTerm("v", 0, {2, 6, 9}), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
