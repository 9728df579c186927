// CurveTangentLineDistanceTerm (000_… §4.2: boundaries of neighbouring strips kept on each other's
// tangent lines).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include "devsurf/spline/Basis.h"
#include "devsurf/terms/CurveTangentLineDistanceTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

/// Samples of a clamped uniform cubic with n control points at K parameters, block at `offset`.
LinearPoints curveSamples(int n, int K, int offset) {
  const spline::KnotVector knots = spline::KnotVector::clampedUniform(3, n);
  std::vector<double> u;
  for (int k = 0; k < K; ++k)
    u.push_back(knots.domainBegin() + (knots.domainEnd() - knots.domainBegin()) * k / (K - 1));
  return {spline::evaluationMatrix(knots, u, 0), offset};
}

/// A quarter circle of radius R in the xy-plane at height z, N points.
std::vector<Eigen::Vector3d> arc(int N, double R, double z) {
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < N; ++i) {
    const double t = 0.5 * M_PI * i / (N - 1);
    p.emplace_back(R * std::cos(t), R * std::sin(t), z);
  }
  return p;
}

TEST(CurveTangentLineDistanceTerm, JacobianMatchesFiniteDifferencesWithFeetHeldFixed) {
  CurveTangentLineDistanceTerm pinned("pair", curveSamples(6, 9, 3), arc(40, 1.0, 0.2), true);
  EXPECT_EQ(pinned.numResiduals(), 2 * 9 + 6);
  expectNoDuplicateEntries(pinned);
  expectJacobianMatches(pinned, randomVector(3 + 18, 71));
  CurveTangentLineDistanceTerm free("pair", curveSamples(5, 4, 0), {{0, 0, 0}, {1, 0.5, 0}, {2, 0, 1}}, false);
  EXPECT_EQ(free.numResiduals(), 8);
  expectJacobianMatches(free, randomVector(15, 72));
}

TEST(CurveTangentLineDistanceTerm, MeasuresTheDistanceFromTheTangentLineAtTheFoot) {
  // One free point (the identity "curve"): offsets across a straight polyline along x are measured
  // exactly, sliding along it costs nothing.
  CurveTangentLineDistanceTerm term("pair", LinearPoints::identity(1, 0), {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, false);
  Eigen::VectorXd x(3);
  x << 0.7, 0.3, -0.4;
  const Eigen::VectorXd r = residuals(term, x);
  EXPECT_NEAR(r.norm(), 0.5, 1e-14);
  EXPECT_NEAR((term.footPoint(0) - Eigen::Vector3d(0.7, 0, 0)).norm(), 0.0, 1e-14);
  x << 1.9, 0.0, 0.0;
  EXPECT_NEAR(residuals(term, x).norm(), 0.0, 1e-14);
}

TEST(CurveTangentLineDistanceTerm, VanishesOnlyWhenTheCurveLiesOnThePolylineAndEndsAtItsEnds) {
  // A cubic whose control points lie on a straight line is that line: zero rows with pinned ends
  // when it spans the polyline exactly, non-zero end rows when it is shorter.
  const int n = 5;
  const LinearPoints samples = curveSamples(n, 12, 0);
  const std::vector<Eigen::Vector3d> line = {{0, 0, 0}, {0.5, 0.5, 0.5}, {1, 1, 1}};
  Eigen::VectorXd x(3 * n);
  for (int i = 0; i < n; ++i) x.segment<3>(3 * i) = Eigen::Vector3d::Constant(double(i) / (n - 1));
  CurveTangentLineDistanceTerm term("pair", samples, line, true);
  EXPECT_LT(residuals(term, x).cwiseAbs().maxCoeff(), 1e-14);
  x *= 0.8;  // same line, shorter: on every tangent line, but the far end is 0.2·√3 short
  const Eigen::VectorXd r = residuals(term, x);
  EXPECT_LT(r.head(24).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_NEAR(r.tail(3).norm(), 0.2 * std::sqrt(3.0), 1e-14);
}

TEST(CurveTangentLineDistanceTerm, RefusesDegeneratePolylines) {
  EXPECT_THROW(CurveTangentLineDistanceTerm("p", LinearPoints::identity(1, 0), {{0, 0, 0}}, false),
               std::invalid_argument);
  EXPECT_THROW(CurveTangentLineDistanceTerm("p", LinearPoints::identity(1, 0), {{0, 0, 0}, {0, 0, 0}}, false),
               std::invalid_argument);
  EXPECT_THROW(CurveTangentLineDistanceTerm("p", LinearPoints::identity(1, 0), {{0, 0, 0}, {NAN, 0, 0}}, false),
               std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
