// CurvedFoldTerm (000_… eqs. 7/8, 003_… §5.2.4) and the softening multiplier (003_… §5.5).

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
#include "devsurf/spline/RationalBasis.h"
#include "devsurf/terms/CurvedFoldTerm.h"
#include "devsurf/terms/SofteningWeight.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::randomVector;
using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::residuals;

/// Crease a (6 control points) and two normal blocks laid out as [a | n1 | n2].
struct CreaseFixture {
  int n = 6;
  spline::KnotVector knots = spline::KnotVector::clampedUniform(3, 6);
  std::vector<double> params = knots.spanSamples(7);
  int K = static_cast<int>(params.size());
  int offA = 0, offN1 = 18, offN2 = 18 + 3 * K;
  int size = 18 + 6 * K;
  LinearPoints da{spline::evaluationMatrix(knots, params, 1), offA};
  LinearPoints dda{spline::evaluationMatrix(knots, params, 2), offA};
  LinearPoints n1 = LinearPoints::identity(K, offN1);
  LinearPoints n2 = LinearPoints::identity(K, offN2);
};

TEST(CurvedFoldTerm, JacobianMatchesFiniteDifferencesWithNormalVectorsBothModes) {
  CreaseFixture f;
  for (auto mode : {CurvedFoldTerm::Mode::CurvedFold, CurvedFoldTerm::Mode::Geodesic}) {
    CurvedFoldTerm term("crease", f.da, f.dda, f.n1, f.n2, mode);
    EXPECT_EQ(term.numResiduals(), 2 * f.K);
    expectNoDuplicateEntries(term);
    expectJacobianMatches(term, randomVector(f.size, 11));
  }
}

TEST(CurvedFoldTerm, JacobianMatchesFiniteDifferencesWithNormalSplinesAndMultipliers) {
  CreaseFixture f;
  const spline::KnotVector nk = spline::KnotVector::clampedUniform(3, 5);
  const int offN1 = 18, offN2 = 33;
  LinearPoints n1{spline::evaluationMatrix(nk, f.params, 0), offN1};
  LinearPoints n2{spline::evaluationMatrix(nk, f.params, 0), offN2};
  const std::vector<double> m = softeningWeights(f.params, {0.05, 0.2, 0.7, 0.95});
  CurvedFoldTerm term("crease", f.da, f.dda, n1, n2, CurvedFoldTerm::Mode::CurvedFold, m);
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(48, 12));
}

TEST(CurvedFoldTerm, JacobianMatchesFiniteDifferencesForANurbsCrease) {
  CreaseFixture f;
  Eigen::VectorXd w(6);
  w << 1.0, 0.7, 1.4, 0.9, 1.2, 1.0;
  LinearPoints da{spline::curveEvaluationMatrix(f.knots, w, f.params, 1), f.offA};
  LinearPoints dda{spline::curveEvaluationMatrix(f.knots, w, f.params, 2), f.offA};
  CurvedFoldTerm term("crease", da, dda, f.n1, f.n2, CurvedFoldTerm::Mode::Geodesic);
  expectJacobianMatches(term, randomVector(f.size, 13));
}

/// A planar crease in the xy-plane; the sheets' normals are e_z tilted by ±θ about the tangent,
/// so the two sheets are mirror images in the crease plane.
struct MirrorFixture : CreaseFixture {
  double theta = 0.4;
  Eigen::VectorXd x;
  spline::BSplineCurve curve;
  MirrorFixture() {
    x = randomVector(size, 14);
    for (int i = 0; i < n; ++i) x[offA + 3 * i + 2] = 0.0;
    curve.knots = knots;
    curve.points.resize(n, 3);
    for (int i = 0; i < n; ++i) curve.points.row(i) = x.segment<3>(offA + 3 * i).transpose();
  }
  Eigen::Vector3d inPlaneNormal(int k) const {
    const Eigen::Vector3d t = curve.evaluate(params[k], 1).normalized();
    return Eigen::Vector3d::UnitZ().cross(t);
  }
  /// n1 = R(+θ) e_z; n2 = R(−θ) e_z (orientedAlike) or −R(−θ) e_z.
  void setNormals(bool orientedAlike) {
    for (int k = 0; k < K; ++k) {
      const Eigen::Vector3d b = inPlaneNormal(k);
      const Eigen::Vector3d up = std::cos(theta) * Eigen::Vector3d::UnitZ();
      x.segment<3>(offN1 + 3 * k) = up + std::sin(theta) * b;
      x.segment<3>(offN2 + 3 * k) = (orientedAlike ? 1.0 : -1.0) * (up - std::sin(theta) * b);
    }
  }
};

TEST(CurvedFoldTerm, VanishesOnMirrorSheetsAndMeasuresTheGeodesicDefect) {
  MirrorFixture f;
  f.setNormals(true);
  CurvedFoldTerm fold("fold", f.da, f.dda, f.n1, f.n2, CurvedFoldTerm::Mode::CurvedFold);
  EXPECT_LT(residuals(fold, f.x).cwiseAbs().maxCoeff(), 1e-14);

  // Same configuration, geodesic mode: n1 − n2 = 2 sinθ b lies in the osculating plane. The
  // tangent row still vanishes (b ⟂ a′); the curvature row is 2 sinθ ⟨a″, b⟩/|a″|, computed here
  // from the curve directly.
  CurvedFoldTerm geodesic("geodesic", f.da, f.dda, f.n1, f.n2, CurvedFoldTerm::Mode::Geodesic);
  const Eigen::VectorXd r = residuals(geodesic, f.x);
  double largest = 0.0;
  for (int k = 0; k < f.K; ++k) {
    const Eigen::Vector3d a2 = f.curve.evaluate(f.params[k], 2);
    const double expected = 2.0 * std::sin(f.theta) * a2.normalized().dot(f.inPlaneNormal(k));
    EXPECT_NEAR(r[2 * k], 0.0, 1e-14);
    EXPECT_NEAR(r[2 * k + 1], expected, 1e-12);
    largest = std::max(largest, std::abs(expected));
  }
  EXPECT_GT(largest, 0.1);  // the configuration really violates eq. 8
}

TEST(CurvedFoldTerm, GeodesicVanishesWhenOneSheetIsOrientedOppositely) {
  MirrorFixture f;
  f.setNormals(false);  // n1 − n2 = 2 cosθ e_z ⟂ osculating plane
  CurvedFoldTerm geodesic("geodesic", f.da, f.dda, f.n1, f.n2, CurvedFoldTerm::Mode::Geodesic);
  EXPECT_LT(residuals(geodesic, f.x).cwiseAbs().maxCoeff(), 1e-14);
  CurvedFoldTerm fold("fold", f.da, f.dda, f.n1, f.n2, CurvedFoldTerm::Mode::CurvedFold);
  EXPECT_GT(residuals(fold, f.x).cwiseAbs().maxCoeff(), 0.1);
}

TEST(CurvedFoldTerm, StraightCreaseHasKnownValues) {
  // A Bézier crease with equally spaced collinear control points is a(u) = (2u, 0, 0): a″ = 0
  // (scale 1, row 0) and the tangent row is ⟨e_x, n1 ± n2⟩.
  const spline::KnotVector knots = spline::KnotVector::clampedUniform(3, 4);
  const std::vector<double> params{0.1, 0.5, 0.9};
  Eigen::VectorXd x(12 + 6);
  for (int i = 0; i < 4; ++i) x.segment<3>(3 * i) = Eigen::Vector3d(2.0 * i / 3.0, 0, 0);
  x.segment<3>(12) = Eigen::Vector3d::UnitY();  // n1, one shared vector for all parameters
  x.segment<3>(15) = Eigen::Vector3d::UnitX();  // n2
  Eigen::SparseMatrix<double, Eigen::RowMajor> ones(3, 1);
  for (int k = 0; k < 3; ++k) ones.insert(k, 0) = 1.0;
  ones.makeCompressed();
  LinearPoints da{spline::evaluationMatrix(knots, params, 1), 0};
  LinearPoints dda{spline::evaluationMatrix(knots, params, 2), 0};
  LinearPoints n1{ones, 12}, n2{ones, 15};
  CurvedFoldTerm fold("fold", da, dda, n1, n2, CurvedFoldTerm::Mode::CurvedFold, {1.0, 0.5, 0.0});
  Eigen::VectorXd r = residuals(fold, x);
  EXPECT_NEAR(r[0], 1.0, 1e-14);
  EXPECT_NEAR(r[2], 0.5, 1e-14);
  EXPECT_NEAR(r[4], 0.0, 1e-14);
  EXPECT_NEAR(r[1], 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(fold.rowScales()[1], 1.0);  // a″ = 0: no normalization
  EXPECT_NEAR(fold.rowScales()[0], 0.5, 1e-14);
  CurvedFoldTerm geodesic("geodesic", da, dda, n1, n2, CurvedFoldTerm::Mode::Geodesic);
  r = residuals(geodesic, x);
  EXPECT_NEAR(r[0], -1.0, 1e-14);
  EXPECT_NEAR(r[4], -1.0, 1e-14);
}

TEST(CurvedFoldTerm, RowsAreScaleInvariantAndMultipliersScaleThem) {
  MirrorFixture f;
  f.setNormals(false);
  const std::vector<double> m = softeningWeights(f.params, {0.0, 0.3, 0.6, 1.0});
  CurvedFoldTerm plain("fold", f.da, f.dda, f.n1, f.n2);
  CurvedFoldTerm softened("fold", f.da, f.dda, f.n1, f.n2, CurvedFoldTerm::Mode::CurvedFold, m);
  const Eigen::VectorXd r = residuals(plain, f.x);
  const Eigen::VectorXd rs = residuals(softened, f.x);
  for (int k = 0; k < f.K; ++k) {
    EXPECT_DOUBLE_EQ(rs[2 * k], m[k] * r[2 * k]);
    EXPECT_DOUBLE_EQ(rs[2 * k + 1], m[k] * r[2 * k + 1]);
  }
  Eigen::VectorXd big = f.x;
  big.head(3 * f.n) *= 1000.0;  // the crease only
  EXPECT_LT((residuals(plain, big) - r).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(CurvedFoldTerm, RejectsSharedVariablesAndMismatchedRows) {
  CreaseFixture f;
  EXPECT_THROW(CurvedFoldTerm("crease", f.da, f.dda, f.n1, f.n1), std::invalid_argument);
  EXPECT_THROW(CurvedFoldTerm("crease", f.da, f.dda, f.n1, LinearPoints::identity(2, f.offN2)),
               std::invalid_argument);
  EXPECT_THROW(CurvedFoldTerm("crease", f.da, f.dda, f.n1, f.n2, CurvedFoldTerm::Mode::CurvedFold,
                              {1.0, 2.0}),
               std::invalid_argument);
}

TEST(SofteningWeight, IsThePiecewiseLinearTrapezoid) {
  const SofteningBreakpoints xi{0.1, 0.3, 0.6, 0.8};
  EXPECT_DOUBLE_EQ(softeningWeight(0.0, xi), 0.0);
  EXPECT_DOUBLE_EQ(softeningWeight(0.1, xi), 0.0);
  EXPECT_DOUBLE_EQ(softeningWeight(0.2, xi), 0.5);
  EXPECT_DOUBLE_EQ(softeningWeight(0.3, xi), 1.0);
  EXPECT_DOUBLE_EQ(softeningWeight(0.45, xi), 1.0);
  EXPECT_DOUBLE_EQ(softeningWeight(0.6, xi), 1.0);
  EXPECT_NEAR(softeningWeight(0.75, xi), 0.25, 1e-15);
  EXPECT_DOUBLE_EQ(softeningWeight(0.8, xi), 0.0);
  EXPECT_DOUBLE_EQ(softeningWeight(1.0, xi), 0.0);
  for (double u : {0.0, 0.3, 1.0}) EXPECT_DOUBLE_EQ(softeningWeight(u, {0.0, 0.0, 1.0, 1.0}), 1.0);
  EXPECT_DOUBLE_EQ(softeningWeight(0.5, {0.5, 0.5, 0.5, 0.5}), 1.0);  // jumps take 1
  EXPECT_DOUBLE_EQ(softeningWeight(0.4, {0.5, 0.5, 0.5, 0.5}), 0.0);
  EXPECT_THROW(softeningWeight(0.5, {0.3, 0.2, 0.6, 0.8}), std::invalid_argument);
  EXPECT_THROW(softeningWeight(0.5, {0.1, 0.2, 0.6, 1.2}), std::invalid_argument);
  // Parameters are normalized by the domain first.
  const std::vector<double> w = softeningWeights({2.0, 2.4, 3.0}, xi, 2.0, 4.0);
  EXPECT_DOUBLE_EQ(w[0], 0.0);
  EXPECT_DOUBLE_EQ(w[1], 0.5);
  EXPECT_DOUBLE_EQ(w[2], 1.0);
}

}  // namespace
}  // namespace devsurf::terms
