// HingeFoldAngleTerm: fold-angle targets of the fold slider (issue 16, item 2).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <cmath>
#include <stdexcept>

#include "devsurf/terms/HingeFoldAngleTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

constexpr double kHingePi = 3.14159265358979323846;

TEST(HingeFoldAngleTerm, JacobianMatchesFiniteDifferences) {
  // Two hinges sharing their axis points, offsets scattered through x.
  HingeFoldAngleTerm term("fold", {{0, 6, 12, 3}, {6, 0, 15, 9}}, {0.3, -1.2});
  EXPECT_EQ(term.numResiduals(), 2);
  expectNoDuplicateEntries(term);
  for (unsigned seed : {7u, 11u, 1331u, 2026u}) expectJacobianMatches(term, randomVector(18, seed));
}

TEST(HingeFoldAngleTerm, MeasuresValleyPositiveMountainNegativeAndFlatZero) {
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(0.5, 1, 0);
  EXPECT_NEAR(hingeFoldAngle(a, b, c, {0.5, -1, 0}), 0.0, 1e-15);
  EXPECT_NEAR(hingeFoldAngle(a, b, c, {0.5, 0, 1}), kHingePi / 2, 1e-15);   // right face up: valley
  EXPECT_NEAR(hingeFoldAngle(a, b, c, {0.5, 0, -1}), -kHingePi / 2, 1e-15); // down: mountain
  EXPECT_NEAR(hingeFoldAngle(a, b, c, {0.5, -std::cos(0.3), std::sin(0.3)}), 0.3, 1e-14);
  // Independent of where along the faces c and d lie and of the axis length.
  EXPECT_NEAR(hingeFoldAngle(a, {3, 0, 0}, {-2, 5, 0}, {7, -std::cos(0.3), std::sin(0.3)}), 0.3, 1e-14);
}

TEST(HingeFoldAngleTerm, ResidualIsTheAngleMinusItsTargetWrappedIntoOneTurn) {
  HingeFoldAngleTerm term("fold", {{0, 3, 6, 9}}, {kHingePi - 0.1});
  Eigen::VectorXd x(12);
  // θ = −(π − 0.1): folded almost flat the other way; the shorter way round is 0.2.
  x << 0, 0, 0, 1, 0, 0, 0.5, 1, 0, 0.5, std::cos(0.1), -std::sin(0.1);
  EXPECT_NEAR(residuals(term, x)[0], 0.2, 1e-12);
  term.setTargets({0.0});
  EXPECT_NEAR(residuals(term, x)[0], -(kHingePi - 0.1), 1e-12);
}

TEST(HingeFoldAngleTerm, RejectsInvalidInput) {
  EXPECT_THROW(HingeFoldAngleTerm("f", {{0, 3, 6, 3}}, {0.0}), std::invalid_argument);
  EXPECT_THROW(HingeFoldAngleTerm("f", {{0, 3, 6, -9}}, {0.0}), std::invalid_argument);
  EXPECT_THROW(HingeFoldAngleTerm("f", {{0, 3, 6, 9}}, {}), std::invalid_argument);
  HingeFoldAngleTerm term("f", {{0, 3, 6, 9}}, {0.0});
  EXPECT_THROW(term.setTargets({std::nan("")}), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
