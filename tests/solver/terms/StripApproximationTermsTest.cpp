// Approximation of reference points by a strip (000_… §4.2): the shared closest-point projection
// and the terms of eq. (9), (10) and (11).

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <algorithm>
#include <random>
#include <vector>

#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/KnotVector.h"
#include "devsurf/terms/StripFootPoints.h"
#include "devsurf/terms/StripPointDistanceTerm.h"
#include "devsurf/terms/StripReferenceTangencyTerm.h"
#include "devsurf/terms/StripTangentPlaneDistanceTerm.h"
#include "support/TermTesting.h"

namespace devsurf::terms {
namespace {

constexpr int kPoints = 5;  // per curve; a at x[0..14], b at x[15..29], normal spline at x[30..41]

Eigen::MatrixX3d randomPoints(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::MatrixX3d q(count, 3);
  for (Eigen::Index j = 0; j < q.rows(); ++j) q.row(j) << uniform(rng), uniform(rng), uniform(rng);
  return q;
}

/// A curved strip: a on a wavy line at y = 0, b at y = 1, with a few random offsets.
Eigen::VectorXd curvedStrip(unsigned seed) {
  Eigen::VectorXd x = 0.1 * testing::randomVector(42, seed);
  for (int i = 0; i < kPoints; ++i) {
    x.segment<3>(3 * i) += Eigen::Vector3d(i * 0.5 - 1.0, 0.0, 0.3 * std::sin(i));
    x.segment<3>(15 + 3 * i) += Eigen::Vector3d(i * 0.5 - 1.0, 1.0, 0.3 * std::sin(i));
  }
  for (int k = 0; k < 4; ++k) x.segment<3>(30 + 3 * k) += Eigen::Vector3d(0.0, 0.0, 1.0);
  return x;
}

std::shared_ptr<StripFootPoints> feetOf(const Eigen::MatrixX3d& q, Eigen::VectorXd weights = {}) {
  return std::make_shared<StripFootPoints>(spline::KnotVector::clampedUniform(3, kPoints), std::move(weights), 0, 15, q);
}

TEST(StripFootPoints, ProjectsOntoAFlatStripWithTheExactParameters) {
  // a from (0, 0, 0) to (2, 0, 0), b from (0, 1, 0) to (2, 1, 0): the strip is the rectangle.
  Eigen::VectorXd x = Eigen::VectorXd::Zero(30);
  for (int i = 0; i < kPoints; ++i) {
    x.segment<3>(3 * i) << 2.0 * i / (kPoints - 1), 0.0, 0.0;
    x.segment<3>(15 + 3 * i) << 2.0 * i / (kPoints - 1), 1.0, 0.0;
  }
  Eigen::MatrixX3d q(3, 3);
  q << 0.6, 0.25, 0.7,   // above the strip
      1.3, 1.5, -0.2,    // beyond b: lands on b
      2.5, -0.5, 0.0;    // beyond the end and beyond a: the corner a(1)
  auto feet = feetOf(q);
  feet->update(x);
  EXPECT_NEAR(feet->v(0), 0.25, 1e-10);
  EXPECT_NEAR(feet->a(x, 1).x(), 1.3, 1e-10);
  EXPECT_EQ(feet->v(1), 1.0);
  EXPECT_EQ(feet->u(2), 1.0);
  EXPECT_EQ(feet->v(2), 0.0);
  EXPECT_LT((feet->surfacePoint(x, 0) - Eigen::Vector3d(0.6, 0.25, 0.0)).norm(), 1e-10);
}

TEST(StripFootPoints, ProjectsOntoACylinderGivenByRationalCurves) {
  // Quarter circles of radius 1 at z = 0 (a) and z = 1 (b) as rational quadratics: the strip is a
  // quarter of a cylinder. q at radius 1.5, angle 30°, height 0.4: foot at the same angle and height.
  const double w = std::sqrt(0.5);
  Eigen::VectorXd x(18);
  x << 1, 0, 0, 1, 1, 0, 0, 1, 0, 1, 0, 1, 1, 1, 1, 0, 1, 1;
  Eigen::VectorXd weights(3);
  weights << 1.0, w, 1.0;
  Eigen::MatrixX3d q(1, 3);
  const double angle = M_PI / 6;
  q << 1.5 * std::cos(angle), 1.5 * std::sin(angle), 0.4;
  StripFootPoints feet(spline::KnotVector::clampedUniform(2, 3), weights, 0, 9, q);
  feet.update(x);
  const Eigen::Vector3d foot = feet.surfacePoint(x, 0);
  EXPECT_NEAR(foot.x(), std::cos(angle), 1e-9);
  EXPECT_NEAR(foot.y(), std::sin(angle), 1e-9);
  EXPECT_NEAR(foot.z(), 0.4, 1e-12);
  EXPECT_NEAR(feet.v(0), 0.4, 1e-12);
}

TEST(StripFootPoints, IsAtLeastAsCloseAsADenseSamplingOfTheSurface) {
  // Property over random curved strips and points: the projection is at least as close as the
  // best point of a 401 × 41 grid of the surface, less the grid's resolution.
  const spline::KnotVector knots = spline::KnotVector::clampedUniform(3, kPoints);
  std::vector<double> us(401);
  for (std::size_t s = 0; s < us.size(); ++s) us[s] = static_cast<double>(s) / 400.0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Eigen::VectorXd x = curvedStrip(seed);
    Eigen::MatrixXd A(kPoints, 3), B(kPoints, 3);
    for (int i = 0; i < kPoints; ++i) {
      A.row(i) = x.segment<3>(3 * i).transpose();
      B.row(i) = x.segment<3>(15 + 3 * i).transpose();
    }
    const Eigen::MatrixXd sa = spline::BSplineCurve{knots, A, {}}.evaluate(us, 0);
    const Eigen::MatrixXd sb = spline::BSplineCurve{knots, B, {}}.evaluate(us, 0);
    const Eigen::MatrixX3d q = randomPoints(10, seed + 100) * 1.5;
    auto feet = feetOf(q);
    feet->update(x);
    for (int j = 0; j < q.rows(); ++j) {
      const Eigen::RowVector3d y = q.row(j);
      const double found = (feet->surfacePoint(x, j) - y.transpose()).norm();
      double best = 1e300;
      for (Eigen::Index s = 0; s < sa.rows(); ++s)
        for (int k = 0; k <= 40; ++k) best = std::min(best, ((1.0 - k / 40.0) * sa.row(s) + k / 40.0 * sb.row(s) - y).norm());
      EXPECT_LE(found, best + 1e-9) << "seed " << seed << " point " << j;
      EXPECT_GE(feet->v(j), 0.0);
      EXPECT_LE(feet->v(j), 1.0);
    }
  }
}

TEST(StripFootPoints, ProjectsOnlyWhenTheCurvesMoved) {
  const Eigen::VectorXd x = curvedStrip(3);
  auto feet = feetOf(randomPoints(4, 7));
  feet->update(x);
  feet->update(x);
  EXPECT_EQ(feet->projections(), 1);
  Eigen::VectorXd moved = x;
  moved[30] += 1.0;  // a normal, not a curve point
  feet->update(moved);
  EXPECT_EQ(feet->projections(), 1);
  moved[4] += 1e-3;
  feet->update(moved);
  EXPECT_EQ(feet->projections(), 2);
}

TEST(StripPointDistanceTerm, JacobianMatchesFiniteDifferencesWithFootPointsHeldFixed) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    StripPointDistanceTerm term("approximation_point", feetOf(randomPoints(6, seed)));
    EXPECT_EQ(term.numResiduals(), 18);
    testing::expectNoDuplicateEntries(term);
    testing::expectJacobianMatches(term, curvedStrip(seed));
  }
}

TEST(StripPointDistanceTerm, IsTheGapToTheFootPoint) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(30);
  for (int i = 0; i < kPoints; ++i) {
    x.segment<3>(3 * i) << 2.0 * i / (kPoints - 1), 0.0, 0.0;
    x.segment<3>(15 + 3 * i) << 2.0 * i / (kPoints - 1), 1.0, 0.0;
  }
  Eigen::MatrixX3d q(1, 3);
  q << 0.6, 0.25, 0.7;
  StripPointDistanceTerm term("approximation_point", feetOf(q));
  const Eigen::VectorXd r = testing::residuals(term, x);
  EXPECT_NEAR(r[0], 0.0, 1e-10);
  EXPECT_NEAR(r[1], 0.0, 1e-10);
  EXPECT_NEAR(r[2], -0.7, 1e-10);
}

TEST(StripReferenceTangencyTerm, JacobianMatchesFiniteDifferencesWithScalesHeldFixed) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    const Eigen::MatrixX3d q = randomPoints(6, seed);
    StripReferenceTangencyTerm term("approximation_tangency", feetOf(q), randomPoints(6, seed + 50));
    EXPECT_EQ(term.numResiduals(), 12);
    testing::expectNoDuplicateEntries(term);
    testing::expectJacobianMatches(term, curvedStrip(seed));
  }
}

TEST(StripReferenceTangencyTerm, VanishesForNormalsOfTheStripAndNotForTiltedOnes) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(30);
  for (int i = 0; i < kPoints; ++i) {
    x.segment<3>(3 * i) << 2.0 * i / (kPoints - 1), 0.0, 0.0;
    x.segment<3>(15 + 3 * i) << 2.0 * i / (kPoints - 1), 1.0, 0.0;
  }
  Eigen::MatrixX3d q(2, 3), m(2, 3);
  q << 0.6, 0.25, 0.1, 1.2, 0.5, -0.1;
  m << 0, 0, 2, 0, std::sin(0.1), std::cos(0.1);  // the strip's normal; tilted by 0.1 about x
  StripReferenceTangencyTerm term("approximation_tangency", feetOf(q), m);
  const Eigen::VectorXd r = testing::residuals(term, x);
  EXPECT_NEAR(r[0], 0.0, 1e-12);
  EXPECT_NEAR(r[1], 0.0, 1e-12);
  EXPECT_NEAR(std::abs(r[2]), std::sin(0.1), 1e-12);  // ⟨m, (a − b)/|a − b|⟩
  EXPECT_NEAR(r[3], 0.0, 1e-12);                       // a′ ∥ x ⟂ m
}

TEST(StripReferenceTangencyTerm, RefusesZeroNormalsAndCountMismatches) {
  const Eigen::MatrixX3d q = randomPoints(3, 1);
  EXPECT_THROW(StripReferenceTangencyTerm("t", feetOf(q), Eigen::MatrixX3d::Zero(3, 3)), std::invalid_argument);
  EXPECT_THROW(StripReferenceTangencyTerm("t", feetOf(q), randomPoints(2, 1)), std::invalid_argument);
}

TEST(StripTangentPlaneDistanceTerm, JacobianMatchesFiniteDifferencesWithANormalSpline) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    StripTangentPlaneDistanceTerm term("approximation_tangent_plane", feetOf(randomPoints(6, seed)),
                                       StripTangentPlaneDistanceTerm::NormalSpline{spline::KnotVector::clampedUniform(3, 4), 30},
                                       0.0, 1.0);
    EXPECT_EQ(term.numResiduals(), 6);
    testing::expectNoDuplicateEntries(term);
    testing::expectJacobianMatches(term, curvedStrip(seed));
  }
}

TEST(StripTangentPlaneDistanceTerm, JacobianMatchesFiniteDifferencesWithNormalsHeldPerIteration) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    StripTangentPlaneDistanceTerm term("approximation_tangent_plane", feetOf(randomPoints(6, seed)), std::nullopt, 0.0, 1.0);
    testing::expectNoDuplicateEntries(term);
    testing::expectJacobianMatches(term, curvedStrip(seed));
  }
}

TEST(StripTangentPlaneDistanceTerm, IsTheHeightAboveTheTangentPlaneInsideAndTheWholeDistanceBeyondTheBoundary) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(42);
  for (int i = 0; i < kPoints; ++i) {
    x.segment<3>(3 * i) << 2.0 * i / (kPoints - 1), 0.0, 0.0;
    x.segment<3>(15 + 3 * i) << 2.0 * i / (kPoints - 1), 1.0, 0.0;
  }
  for (int k = 0; k < 4; ++k) x.segment<3>(30 + 3 * k) << 0.0, 0.0, 2.5;  // n(u) = (0, 0, 2.5)
  Eigen::MatrixX3d q(2, 3);
  q << 0.6, 0.25, 0.7, 1.7, 1.25, -0.3;  // the second beyond b: its foot is on b, its row the whole gap
  StripTangentPlaneDistanceTerm withSpline("p", feetOf(q),
                                           StripTangentPlaneDistanceTerm::NormalSpline{spline::KnotVector::clampedUniform(3, 4), 30},
                                           0.0, 1.0);
  StripTangentPlaneDistanceTerm held("p", feetOf(q), std::nullopt, 0.0, 1.0);
  const Eigen::VectorXd r1 = testing::residuals(withSpline, x), r2 = testing::residuals(held, x);
  EXPECT_NEAR(r1[0], -0.7, 1e-10);
  EXPECT_NEAR(r1[1], 0.5 * std::hypot(0.25, 0.3), 1e-10);
  EXPECT_NEAR(std::abs(r2[0]), 0.7, 1e-10);  // the held normal's sign follows a′ × (b − a)
  EXPECT_NEAR(r2[1], 0.5 * std::hypot(0.25, 0.3), 1e-10);
}

}  // namespace
}  // namespace devsurf::terms
