// Every term's analytic Jacobian against central finite differences (engine::checkJacobian),
// at random points, including the per-iteration constants refreshed by linearizeAt().

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <random>

#include <Eigen/Geometry>

#include "devsurf/engine/JacobianCheck.h"
#include "devsurf/spline/Basis.h"
#include "devsurf/spline/RationalBasis.h"
#include "devsurf/terms/ControlPolygonFairnessTerm.h"
#include "devsurf/terms/HandleTargetTerm.h"
#include "devsurf/terms/StripDevelopabilityTerm.h"
#include "devsurf/terms/NormalSplineUnitTerm.h"
#include "devsurf/terms/UnitNormalTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::randomVector;
using devsurf::testing::expectJacobianMatches;

/// Curves a (n points), b (n points) and normals laid out as [a | b | normals].
struct StripFixture {
  int n = 6, degree = 3;
  spline::KnotVector knots = spline::KnotVector::clampedUniform(3, 6);
  std::vector<double> params = knots.spanSamples(7);
  int K = static_cast<int>(params.size());
  int offA = 0, offB = 18, offN = 36;
};

TEST(StripDevelopabilityTerm, JacobianMatchesFiniteDifferencesWithNormalVectors) {
  StripFixture f;
  LinearPoints a{spline::evaluationMatrix(f.knots, f.params, 0), f.offA};
  LinearPoints da{spline::evaluationMatrix(f.knots, f.params, 1), f.offA};
  LinearPoints b{spline::evaluationMatrix(f.knots, f.params, 0), f.offB};
  LinearPoints db{spline::evaluationMatrix(f.knots, f.params, 1), f.offB};
  StripDevelopabilityTerm term("developability", a, da, b, db, LinearPoints::identity(f.K, f.offN));
  EXPECT_EQ(term.numResiduals(), 3 * f.K);
  expectJacobianMatches(term, randomVector(f.offN + 3 * f.K, 1));
}

TEST(StripDevelopabilityTerm, JacobianMatchesFiniteDifferencesWithANormalSpline) {
  StripFixture f;
  const spline::KnotVector nk = spline::KnotVector::clampedUniform(3, 5);
  LinearPoints a{spline::evaluationMatrix(f.knots, f.params, 0), f.offA};
  LinearPoints da{spline::evaluationMatrix(f.knots, f.params, 1), f.offA};
  LinearPoints b{spline::evaluationMatrix(f.knots, f.params, 0), f.offB};
  LinearPoints db{spline::evaluationMatrix(f.knots, f.params, 1), f.offB};
  LinearPoints normals{spline::evaluationMatrix(nk, f.params, 0), f.offN};
  StripDevelopabilityTerm term("developability", a, da, b, db, normals);
  expectJacobianMatches(term, randomVector(f.offN + 15, 2));
}

TEST(StripDevelopabilityTerm, JacobianMatchesFiniteDifferencesForNurbsCurves) {
  StripFixture f;
  Eigen::VectorXd w(6);
  w << 1.0, 0.7, 1.4, 0.9, 1.2, 1.0;
  LinearPoints a{spline::curveEvaluationMatrix(f.knots, w, f.params, 0), f.offA};
  LinearPoints da{spline::curveEvaluationMatrix(f.knots, w, f.params, 1), f.offA};
  LinearPoints b{spline::curveEvaluationMatrix(f.knots, w, f.params, 0), f.offB};
  LinearPoints db{spline::curveEvaluationMatrix(f.knots, w, f.params, 1), f.offB};
  StripDevelopabilityTerm term("developability", a, da, b, db, LinearPoints::identity(f.K, f.offN));
  expectJacobianMatches(term, randomVector(f.offN + 3 * f.K, 3));
}

TEST(StripDevelopabilityTerm, VanishesOnACylinderWithItsTrueNormals) {
  StripFixture f;
  Eigen::VectorXd x = randomVector(f.offN + 3 * f.K, 4);
  const Eigen::Vector3d shift(0.2, 0.5, 1.0);
  for (int i = 0; i < f.n; ++i) x.segment<3>(f.offB + 3 * i) = x.segment<3>(f.offA + 3 * i) + shift;
  LinearPoints a{spline::evaluationMatrix(f.knots, f.params, 0), f.offA};
  LinearPoints da{spline::evaluationMatrix(f.knots, f.params, 1), f.offA};
  LinearPoints b{spline::evaluationMatrix(f.knots, f.params, 0), f.offB};
  LinearPoints db{spline::evaluationMatrix(f.knots, f.params, 1), f.offB};
  for (int k = 0; k < f.K; ++k) x.segment<3>(f.offN + 3 * k) = da.point(x, k).cross(shift).normalized();
  StripDevelopabilityTerm term("developability", a, da, b, db, LinearPoints::identity(f.K, f.offN));
  term.linearizeAt(x);
  Eigen::VectorXd r(term.numResiduals());
  term.evaluate(x, r.data(), nullptr);
  EXPECT_LT(r.cwiseAbs().maxCoeff(), 1e-14);
  // Rows are scaled: a twisted configuration gives O(1) residuals whatever the strip's size.
  Eigen::VectorXd big = 1000.0 * x;
  for (int k = 0; k < f.K; ++k) big.segment<3>(f.offN + 3 * k) = x.segment<3>(f.offN + 3 * k);
  term.linearizeAt(big);
  term.evaluate(big, r.data(), nullptr);
  EXPECT_LT(r.cwiseAbs().maxCoeff(), 1e-12);
}

TEST(UnitNormalTerm, JacobianMatchesFiniteDifferences) {
  UnitNormalTerm term("unit_normal", {0, 3, 9});
  expectJacobianMatches(term, randomVector(12, 5));
}

TEST(NormalSplineUnitTerm, JacobianMatchesFiniteDifferencesAndResidualsAreTheEvaluatedLengths) {
  StripFixture f;
  const spline::KnotVector nk = spline::KnotVector::clampedUniform(3, 5);
  const LinearPoints normals{spline::evaluationMatrix(nk, f.params, 0), f.offN};
  NormalSplineUnitTerm term("unit_normal", normals);
  EXPECT_EQ(term.numResiduals(), f.K);
  const Eigen::VectorXd x = randomVector(f.offN + 15, 6);
  expectJacobianMatches(term, x);
  Eigen::VectorXd r(f.K);
  term.evaluate(x, r.data(), nullptr);
  for (int k = 0; k < f.K; ++k) EXPECT_NEAR(r[k], normals.point(x, k).squaredNorm() - 1.0, 1e-14);
  // Control points that are the same unit vector give unit normals everywhere (partition of unity).
  Eigen::VectorXd unit = x;
  for (int j = 0; j < 5; ++j) unit.segment<3>(f.offN + 3 * j) = Eigen::Vector3d(0.6, 0.0, 0.8);
  term.evaluate(unit, r.data(), nullptr);
  EXPECT_LT(r.cwiseAbs().maxCoeff(), 1e-14);
}

TEST(UnitNormalTerm, ResidualIsSquaredLengthMinusOne) {
  UnitNormalTerm term("unit_normal", {0});
  double r = 0;
  term.evaluate(Eigen::Vector3d(0.0, 3.0, 4.0), &r, nullptr);
  EXPECT_DOUBLE_EQ(r, 24.0);
}

TEST(ControlPolygonFairnessTerm, JacobianMatchesFiniteDifferencesOpenAndClosed) {
  ControlPolygonFairnessTerm open("fairness", 3, 5, 3, false);
  EXPECT_EQ(open.numResiduals(), 9);
  expectJacobianMatches(open, randomVector(18, 6));
  ControlPolygonFairnessTerm closed("fairness", 0, 5, 2, true);
  EXPECT_EQ(closed.numResiduals(), 10);
  expectJacobianMatches(closed, randomVector(10, 7));
}

TEST(ControlPolygonFairnessTerm, VanishesOnEquallySpacedCollinearPoints) {
  ControlPolygonFairnessTerm term("fairness", 0, 4, 3, false);
  Eigen::VectorXd x(12);
  for (int i = 0; i < 4; ++i) x.segment<3>(3 * i) = Eigen::Vector3d(1, 2, 3) * i + Eigen::Vector3d(0, 1, 0);
  Eigen::VectorXd r(term.numResiduals());
  term.evaluate(x, r.data(), nullptr);
  EXPECT_LT(r.cwiseAbs().maxCoeff(), 1e-15);
}

TEST(HandleTargetTerm, JacobianMatchesFiniteDifferencesAndTargetsMove) {
  HandleTargetTerm term("handle", 3, Eigen::Vector3d(1, 2, 3));
  expectJacobianMatches(term, randomVector(9, 8));
  term.setTarget(Eigen::Vector3d(0, 0, 0));
  Eigen::Vector3d r;
  term.evaluate(Eigen::VectorXd::Ones(9), r.data(), nullptr);
  EXPECT_EQ(r, Eigen::Vector3d(1, 1, 1));
}

}  // namespace
}  // namespace devsurf::terms
