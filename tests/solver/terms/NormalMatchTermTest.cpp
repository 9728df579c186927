// NormalMatchTerm (000_… §3.1: smooth transition across a shared ruling).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "devsurf/engine/JacobianCheck.h"
#include "devsurf/spline/Basis.h"
#include "devsurf/terms/NormalMatchTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::randomVector;
using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::residuals;

TEST(NormalMatchTerm, JacobianMatchesFiniteDifferences) {
  NormalMatchTerm free("smooth", LinearPoints::identity(2, 0), LinearPoints::identity(2, 6));
  EXPECT_EQ(free.numResiduals(), 6);
  expectNoDuplicateEntries(free);
  expectJacobianMatches(free, randomVector(12, 41));

  // Normal splines of two strips, end of the first against the start of the second.
  const spline::KnotVector k = spline::KnotVector::clampedUniform(3, 5);
  LinearPoints end{spline::evaluationMatrix(k, {1.0}, 0), 0};
  LinearPoints start{spline::evaluationMatrix(k, {0.0}, 0), 15};
  NormalMatchTerm splines("smooth", end, start, NormalMatchTerm::Orientation::Opposite);
  expectNoDuplicateEntries(splines);
  expectJacobianMatches(splines, randomVector(30, 42));
}

TEST(NormalMatchTerm, MergesVariablesSharedByBothSides) {
  // One normal spline on both sides at interior parameters: the rows share control points.
  const spline::KnotVector k = spline::KnotVector::clampedUniform(3, 6);
  LinearPoints a{spline::evaluationMatrix(k, {0.4}, 0), 0};
  LinearPoints b{spline::evaluationMatrix(k, {0.45}, 0), 0};
  NormalMatchTerm term("smooth", a, b, NormalMatchTerm::Orientation::Opposite);
  expectNoDuplicateEntries(term);
  const Eigen::VectorXd x = randomVector(18, 43);
  expectJacobianMatches(term, x);
  const Eigen::Vector3d expected = a.point(x, 0) + b.point(x, 0);
  EXPECT_LT((residuals(term, x) - expected).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(NormalMatchTerm, VanishesForEqualNormalsAndGivesTheDifferenceOtherwise) {
  // Clamped normal splines: n1(1) is n1's last control point, n2(0) is n2's first.
  const spline::KnotVector k = spline::KnotVector::clampedUniform(3, 5);
  LinearPoints end{spline::evaluationMatrix(k, {1.0}, 0), 0};
  LinearPoints start{spline::evaluationMatrix(k, {0.0}, 0), 15};
  Eigen::VectorXd x = randomVector(30, 44);
  const Eigen::Vector3d shared = Eigen::Vector3d(0.2, -0.4, 0.9).normalized();
  x.segment<3>(12) = shared;
  x.segment<3>(15) = shared;
  NormalMatchTerm same("smooth", end, start);
  EXPECT_LT(residuals(same, x).cwiseAbs().maxCoeff(), 1e-15);

  Eigen::VectorXd y(6);
  y << 1, 0, 0, 0, 1, 0;
  NormalMatchTerm plain("smooth", LinearPoints::identity(1, 0), LinearPoints::identity(1, 3));
  EXPECT_EQ(residuals(plain, y), Eigen::Vector3d(1, -1, 0));
  NormalMatchTerm opposite("smooth", LinearPoints::identity(1, 0), LinearPoints::identity(1, 3),
                           NormalMatchTerm::Orientation::Opposite);
  EXPECT_EQ(residuals(opposite, y), Eigen::Vector3d(1, 1, 0));
  EXPECT_THROW(
      NormalMatchTerm("smooth", LinearPoints::identity(2, 0), LinearPoints::identity(1, 6)),
      std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
