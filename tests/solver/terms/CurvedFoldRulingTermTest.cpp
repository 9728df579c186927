// CurvedFoldRulingTerm: the crease condition of 000_… eqs. 7/8 with the faces' normals taken from
// the crease tangent and the faces' rulings, weighted by the crease's curvature (issue 17).

#include <gtest/gtest.h>

#include "support/CurvedEdgeFixture.h"
#include "support/TermTesting.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/Basis.h"
#include "devsurf/terms/CurvedFoldRulingTerm.h"
#include "devsurf/terms/CurvedFoldTerm.h"
#include "devsurf/terms/SofteningWeight.h"

namespace devsurf::terms {
namespace {

using TwoFaceFixture = devsurf::testing::CurvedEdgeFixture;
using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

TEST(CurvedFoldRulingTerm, JacobianMatchesFiniteDifferencesInBothModes) {
  TwoFaceFixture f;
  std::vector<double> o2 = f.ones();
  for (int k = 0; k < f.K; k += 2) o2[static_cast<std::size_t>(k)] = -1.0;
  const std::vector<double> m = softeningWeights(f.params, {0.05, 0.2, 0.7, 0.95});
  for (auto mode : {CurvedFoldRulingTerm::Mode::CurvedFold, CurvedFoldRulingTerm::Mode::Geodesic}) {
    CurvedFoldRulingTerm term("crease", f.da, f.dda, f.across(1), f.across(2), f.ones(), o2, mode, m);
    EXPECT_EQ(term.numResiduals(), f.K);
    expectNoDuplicateEntries(term);
    expectJacobianMatches(term, randomVector(54, 21));
  }
}

TEST(CurvedFoldRulingTerm, MergesAControlPointTheCreaseAndAFaceShare) {
  // b1 starts at the crease's first control point (a face whose curves meet at a vertex): that
  // point enters a′, a″ and d_1 of the first rows once, with merged weights.
  TwoFaceFixture f;
  const LinearPoints across1 = f.across(1, {{0, 0}});
  CurvedFoldRulingTerm term("crease", f.da, f.dda, across1, f.across(2), f.ones(), f.ones());
  expectNoDuplicateEntries(term);
  Eigen::VectorXd x = randomVector(54, 22);
  expectJacobianMatches(term, x);
}

/// A planar crease in the xy-plane and two faces given by free vectors across the crease, tilted
/// by ±θ about its tangent: face 1's normal is cosθ e_z + sinθ b, face 2's cosθ e_z − sinθ b
/// (b = e_z × t): mirror images in the crease's plane, the curved fold of eq. 7.
struct MirrorSheets {
  int n = 6;
  spline::KnotVector knots = spline::KnotVector::clampedUniform(3, 6);
  std::vector<double> params = knots.spanSamples(7);
  int K = static_cast<int>(params.size());
  int offSide1 = 18, offSide2 = 18 + 3 * K;
  double theta = 0.4;
  Eigen::VectorXd x;
  spline::BSplineCurve curve;
  LinearPoints da{spline::evaluationMatrix(knots, params, 1), 0};
  LinearPoints dda{spline::evaluationMatrix(knots, params, 2), 0};
  LinearPoints side1 = LinearPoints::identity(K, offSide1), side2 = LinearPoints::identity(K, offSide2);

  MirrorSheets() {
    x = randomVector(18 + 6 * K, 23);
    for (int i = 0; i < n; ++i) x[3 * i + 2] = 0.0;
    curve.knots = knots;
    curve.points.resize(n, 3);
    for (int i = 0; i < n; ++i) curve.points.row(i) = x.segment<3>(3 * i).transpose();
    for (int k = 0; k < K; ++k) {
      const Eigen::Vector3d t = tangent(k);
      // Across face 1: n1 × t, so t × (n1 × t) = n1; across face 2: t × n2, so t × (t × n2) = −n2.
      x.segment<3>(offSide1 + 3 * k) = 0.8 * normal(k, +1).cross(t);
      x.segment<3>(offSide2 + 3 * k) = 1.3 * t.cross(normal(k, -1));
    }
  }
  Eigen::Vector3d tangent(int k) const { return curve.evaluate(params[k], 1).normalized(); }
  Eigen::Vector3d inPlaneNormal(int k) const { return Eigen::Vector3d::UnitZ().cross(tangent(k)); }
  Eigen::Vector3d normal(int k, double side) const {
    return std::cos(theta) * Eigen::Vector3d::UnitZ() + side * std::sin(theta) * inPlaneNormal(k);
  }
};

TEST(CurvedFoldRulingTerm, VanishesOnMirrorSheetsAndMeasuresTheirGeodesicDefect) {
  MirrorSheets s;
  const std::vector<double> plus(static_cast<std::size_t>(s.K), 1.0), minus(static_cast<std::size_t>(s.K), -1.0);
  CurvedFoldRulingTerm fold("fold", s.da, s.dda, s.side1, s.side2, plus, minus);
  EXPECT_LT(residuals(fold, s.x).cwiseAbs().maxCoeff(), 1e-14);

  // Geodesic mode: n1 − n2 = 2 sinθ b; the row is 2 sinθ ⟨a″, b⟩ / (|a′|² max(κ, κ_ref)), κ the
  // curvature |a′ × a″| / |a′|³ and κ_ref its 90th percentile over the parameters, all computed
  // here from the curve.
  CurvedFoldRulingTerm geodesic("geodesic", s.da, s.dda, s.side1, s.side2, plus, minus,
                                CurvedFoldRulingTerm::Mode::Geodesic);
  const Eigen::VectorXd r = residuals(geodesic, s.x);
  std::vector<double> kappa;
  for (int k = 0; k < s.K; ++k) {
    const Eigen::Vector3d a1 = s.curve.evaluate(s.params[k], 1), a2 = s.curve.evaluate(s.params[k], 2);
    kappa.push_back(a1.cross(a2).norm() / std::pow(a1.norm(), 3));
  }
  std::vector<double> sorted = kappa;
  std::sort(sorted.begin(), sorted.end());
  const double reference = sorted[static_cast<std::size_t>(0.9 * (s.K - 1))];
  EXPECT_LT(reference, sorted.back());  // some rows above it, some below
  EXPECT_GT(reference, sorted.front());
  double largest = 0.0;
  for (int k = 0; k < s.K; ++k) {
    const Eigen::Vector3d a1 = s.curve.evaluate(s.params[k], 1), a2 = s.curve.evaluate(s.params[k], 2);
    const double scale = 1.0 / (a1.squaredNorm() * std::max(kappa[static_cast<std::size_t>(k)], reference));
    const double expected = 2.0 * std::sin(s.theta) * a2.dot(s.inPlaneNormal(k)) * scale;
    EXPECT_NEAR(r[k], expected, 1e-12);
    EXPECT_NEAR(geodesic.rowScales()[static_cast<std::size_t>(k)], scale, 1e-12 * scale);
    largest = std::max(largest, std::abs(expected));
  }
  EXPECT_GT(largest, 0.1);  // the configuration really violates eq. 8
}

TEST(CurvedFoldRulingTerm, EqualsTheFreeNormalTermsCurvatureRowWhenTheNormalsAreTheFaces) {
  // CurvedFoldTerm with free normals set to the faces' normals: its curvature row and this term's
  // row are one number, at any fold of the faces (not only at a solution).
  MirrorSheets s;
  Eigen::VectorXd x = s.x;
  for (int k = 0; k < s.K; ++k)  // tilt face 2 away from the mirror position
    x.segment<3>(s.offSide2 + 3 * k) = 1.3 * s.tangent(k).cross(Eigen::Vector3d(0.3, -0.2, 1.0).normalized());
  const int offN1 = 18 + 6 * s.K, offN2 = offN1 + 3 * s.K;
  Eigen::VectorXd withNormals(offN2 + 3 * s.K);
  withNormals.head(x.size()) = x;
  for (int k = 0; k < s.K; ++k) {
    const Eigen::Vector3d t = s.curve.evaluate(s.params[k], 1);
    withNormals.segment<3>(offN1 + 3 * k) = t.cross(x.segment<3>(s.offSide1 + 3 * k)).normalized();
    withNormals.segment<3>(offN2 + 3 * k) = -t.cross(x.segment<3>(s.offSide2 + 3 * k)).normalized();
  }
  for (auto mode : {CurvedFoldRulingTerm::Mode::CurvedFold, CurvedFoldRulingTerm::Mode::Geodesic}) {
    const std::vector<double> plus(static_cast<std::size_t>(s.K), 1.0), minus(static_cast<std::size_t>(s.K), -1.0);
    CurvedFoldRulingTerm ruling("ruling", s.da, s.dda, s.side1, s.side2, plus, minus, mode);
    CurvedFoldTerm free("free", s.da, s.dda, LinearPoints::identity(s.K, offN1), LinearPoints::identity(s.K, offN2),
                        mode);
    const Eigen::VectorXd rr = residuals(ruling, withNormals), rf = residuals(free, withNormals);
    double largest = 0.0;
    for (int k = 0; k < s.K; ++k) {
      // The same ⟨a″, n1 ± n2⟩, each under its own row scale.
      const double ownScale = ruling.rowScales()[static_cast<std::size_t>(k)];
      const double freeScale = free.rowScales()[static_cast<std::size_t>(2 * k + 1)];
      EXPECT_NEAR(rr[k] / ownScale, rf[2 * k + 1] / freeScale, 1e-12) << "parameter " << k;
      EXPECT_NEAR(rf[2 * k], 0.0, 1e-13);  // the tangent row the ruling term leaves out
      largest = std::max(largest, std::abs(rr[k]));
    }
    EXPECT_GT(largest, 0.05);
  }
}

TEST(CurvedFoldRulingTerm, OrientationDecidesBetweenFoldAndGeodesic) {
  // Face 2 oriented the other way: n1 − (−n2)… the fold row measures, the geodesic one vanishes.
  MirrorSheets s;
  const std::vector<double> plus(static_cast<std::size_t>(s.K), 1.0);
  CurvedFoldRulingTerm fold("fold", s.da, s.dda, s.side1, s.side2, plus, plus);
  EXPECT_GT(residuals(fold, s.x).cwiseAbs().maxCoeff(), 0.1);
  CurvedFoldRulingTerm geodesic("geodesic", s.da, s.dda, s.side1, s.side2, plus, plus,
                                CurvedFoldRulingTerm::Mode::Geodesic);
  EXPECT_LT(residuals(geodesic, s.x).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(CurvedFoldRulingTerm, RowsAreScaleInvariantAndIndependentOfTheRulingsLengths) {
  MirrorSheets s;
  Eigen::VectorXd x = s.x;
  for (int k = 0; k < s.K; ++k) x.segment<3>(s.offSide2 + 3 * k) = s.tangent(k).cross(Eigen::Vector3d(0.1, 0.4, 1.0));
  const std::vector<double> plus(static_cast<std::size_t>(s.K), 1.0), minus(static_cast<std::size_t>(s.K), -1.0);
  CurvedFoldRulingTerm term("fold", s.da, s.dda, s.side1, s.side2, plus, minus);
  const Eigen::VectorXd r = residuals(term, x);
  EXPECT_GT(r.cwiseAbs().maxCoeff(), 0.05);
  Eigen::VectorXd scaled = x;
  scaled.head(18) *= 1000.0;
  scaled.segment(s.offSide1, 3 * s.K) *= 0.01;
  EXPECT_LT((residuals(term, scaled) - r).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(CurvedFoldRulingTerm, ARowWithAVanishingSideIsZeroNotUndefined) {
  MirrorSheets s;
  Eigen::VectorXd x = s.x;
  x.segment<3>(s.offSide1 + 3 * 2).setZero();                                  // no ruling
  x.segment<3>(s.offSide2 + 3 * 4) = 2.0 * s.curve.evaluate(s.params[4], 1);  // along the crease
  const std::vector<double> plus(static_cast<std::size_t>(s.K), 1.0), minus(static_cast<std::size_t>(s.K), -1.0);
  CurvedFoldRulingTerm term("fold", s.da, s.dda, s.side1, s.side2, plus, minus, CurvedFoldRulingTerm::Mode::Geodesic);
  term.linearizeAt(x);
  std::vector<engine::JacobianEntry> entries;
  term.jacobianStructure(entries);
  Eigen::VectorXd r(term.numResiduals());
  std::vector<double> J(entries.size(), 1.0);
  term.evaluate(x, r.data(), J.data());
  EXPECT_TRUE(r.allFinite());
  EXPECT_EQ(r[2], 0.0);
  EXPECT_EQ(r[4], 0.0);
  EXPECT_GT(std::abs(r[3]), 1e-3);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    EXPECT_TRUE(std::isfinite(J[i]));
    if (entries[i].row == 2 || entries[i].row == 4) {
      EXPECT_EQ(J[i], 0.0);
    }
  }
}

TEST(CurvedFoldRulingTerm, RejectsMismatchedRowsAndOrientations) {
  TwoFaceFixture f;
  const LinearPoints a1 = f.across(1), a2 = f.across(2);
  EXPECT_THROW(CurvedFoldRulingTerm("c", f.da, f.dda, a1, LinearPoints::identity(2, 54), f.ones(), f.ones()),
               std::invalid_argument);
  EXPECT_THROW(CurvedFoldRulingTerm("c", f.da, f.dda, a1, a2, f.ones(), {1.0}), std::invalid_argument);
  std::vector<double> bad = f.ones();
  bad[1] = 0.5;
  EXPECT_THROW(CurvedFoldRulingTerm("c", f.da, f.dda, a1, a2, f.ones(), bad), std::invalid_argument);
  EXPECT_THROW(CurvedFoldRulingTerm("c", f.da, f.dda, a1, a2, f.ones(), f.ones(), CurvedFoldRulingTerm::Mode::CurvedFold,
                                    {1.0, 2.0}),
               std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
