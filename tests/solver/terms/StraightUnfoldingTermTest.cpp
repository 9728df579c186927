// StraightUnfoldingTerm (000_… §3.3 "Straight unfolding property").

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include <Eigen/Geometry>

#include "devsurf/engine/JacobianCheck.h"
#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/Basis.h"
#include "devsurf/terms/StraightUnfoldingTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::randomVector;
using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::residuals;

/// Boundary a (6 control points), strip normals and osculating normals: [a | n_left | n_osc].
struct Fixture {
  int n = 6;
  spline::KnotVector knots = spline::KnotVector::clampedUniform(3, 6);
  std::vector<double> params = knots.spanSamples(5);
  int K = static_cast<int>(params.size());
  int offA = 0, offLeft = 18, offOsc = 18 + 3 * K;
  int size = 18 + 6 * K;
  LinearPoints da{spline::evaluationMatrix(knots, params, 1), offA};
  LinearPoints dda{spline::evaluationMatrix(knots, params, 2), offA};
  LinearPoints left = LinearPoints::identity(K, offLeft);
  LinearPoints osc = LinearPoints::identity(K, offOsc);
};

TEST(StraightUnfoldingTerm, JacobianMatchesFiniteDifferences) {
  Fixture f;
  StraightUnfoldingTerm term("straight", f.da, f.dda, f.left, f.osc);
  EXPECT_EQ(term.numResiduals(), 3 * f.K);
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(f.size, 21));
}

TEST(StraightUnfoldingTerm, JacobianMatchesFiniteDifferencesWithANormalSpline) {
  Fixture f;
  const spline::KnotVector nk = spline::KnotVector::clampedUniform(2, 4);
  LinearPoints left{spline::evaluationMatrix(nk, f.params, 0), 18};
  StraightUnfoldingTerm term("straight", f.da, f.dda, left, LinearPoints::identity(f.K, 30));
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(30 + 3 * f.K, 22));
}

/// A planar boundary in the xy-plane: its osculating plane is z = 0 with normal e_z.
struct PlanarFixture : Fixture {
  Eigen::VectorXd x;
  spline::BSplineCurve curve;
  PlanarFixture() {
    x = randomVector(size, 23);
    for (int i = 0; i < n; ++i) x[offA + 3 * i + 2] = 0.0;
    curve.knots = knots;
    curve.points.resize(n, 3);
    for (int i = 0; i < n; ++i) curve.points.row(i) = x.segment<3>(offA + 3 * i).transpose();
  }
  Eigen::Vector3d tangent(int k) const { return curve.evaluate(params[k], 1).normalized(); }
  Eigen::Vector3d inPlaneNormal(int k) const { return Eigen::Vector3d::UnitZ().cross(tangent(k)); }
};

TEST(StraightUnfoldingTerm, VanishesForAStripOrthogonalToThePlaneOfItsBoundary) {
  // The strip's tangent plane contains the tangent and e_z: a cylinder over a planar curve,
  // whose boundary unfolds to a straight line.
  PlanarFixture f;
  for (int k = 0; k < f.K; ++k) {
    f.x.segment<3>(f.offLeft + 3 * k) = f.inPlaneNormal(k);
    f.x.segment<3>(f.offOsc + 3 * k) = Eigen::Vector3d::UnitZ();
  }
  StraightUnfoldingTerm term("straight", f.da, f.dda, f.left, f.osc);
  EXPECT_LT(residuals(term, f.x).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(StraightUnfoldingTerm, TiltedNormalsGiveKnownResiduals) {
  PlanarFixture f;
  const double theta = 0.3, phi = 0.2;
  // Strip tilted by θ about the tangent: only the third row, = sin θ.
  for (int k = 0; k < f.K; ++k) {
    f.x.segment<3>(f.offLeft + 3 * k) =
        std::cos(theta) * f.inPlaneNormal(k) + std::sin(theta) * Eigen::Vector3d::UnitZ();
    f.x.segment<3>(f.offOsc + 3 * k) = Eigen::Vector3d::UnitZ();
  }
  StraightUnfoldingTerm term("straight", f.da, f.dda, f.left, f.osc);
  Eigen::VectorXd r = residuals(term, f.x);
  for (int k = 0; k < f.K; ++k) {
    EXPECT_NEAR(r[3 * k], 0.0, 1e-14);
    EXPECT_NEAR(r[3 * k + 1], 0.0, 1e-14);
    EXPECT_NEAR(r[3 * k + 2], std::sin(theta), 1e-14);
  }
  // n_osc tilted by φ towards the tangent: rows sin φ, sin φ ⟨â″, t⟩, 0.
  for (int k = 0; k < f.K; ++k) {
    f.x.segment<3>(f.offLeft + 3 * k) = f.inPlaneNormal(k);
    f.x.segment<3>(f.offOsc + 3 * k) =
        std::cos(phi) * Eigen::Vector3d::UnitZ() + std::sin(phi) * f.tangent(k);
  }
  r = residuals(term, f.x);
  for (int k = 0; k < f.K; ++k) {
    const Eigen::Vector3d a2 = f.curve.evaluate(f.params[k], 2).normalized();
    EXPECT_NEAR(r[3 * k], std::sin(phi), 1e-14);
    EXPECT_NEAR(r[3 * k + 1], std::sin(phi) * a2.dot(f.tangent(k)), 1e-13);
    EXPECT_NEAR(r[3 * k + 2], 0.0, 1e-14);
  }
  EXPECT_NEAR(term.rowScales()[0], 1.0 / f.curve.evaluate(f.params[0], 1).norm(), 1e-12);
}

TEST(StraightUnfoldingTerm, RejectsMismatchedRowsAndSharedVariables) {
  Fixture f;
  EXPECT_THROW(StraightUnfoldingTerm("s", f.da, f.dda, f.left, LinearPoints::identity(2, f.offOsc)),
               std::invalid_argument);
  EXPECT_THROW(StraightUnfoldingTerm("s", f.da, f.dda, f.left, f.left), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
