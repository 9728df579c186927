// RulingNormalMatchTerm: NormalMatchTerm's smooth-transition rows with each face's normal taken
// from its tangent plane (t × d) instead of a free normal (issue 17).

#include <gtest/gtest.h>

#include "support/CurvedEdgeFixture.h"
#include "support/TermTesting.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/Basis.h"
#include "devsurf/terms/NormalMatchTerm.h"
#include "devsurf/terms/RulingNormalMatchTerm.h"

namespace devsurf::terms {
namespace {

using SmoothEdgeFixture = devsurf::testing::CurvedEdgeFixture;
using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

TEST(RulingNormalMatchTerm, JacobianMatchesFiniteDifferencesAcrossACurvedEdge) {
  SmoothEdgeFixture f;
  std::vector<double> o1(static_cast<std::size_t>(f.K), 1.0), o2(static_cast<std::size_t>(f.K), -1.0);
  for (int k = 0; k < f.K; k += 3) o1[static_cast<std::size_t>(k)] = -1.0;
  RulingNormalMatchTerm term("smooth", f.da, f.across(1), f.da, f.across(2), o1, o2);
  EXPECT_EQ(term.numResiduals(), 3 * f.K);
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(54, 41));
}

/// One row over six points: Σ weight · point.
LinearPoints pointRow(const std::vector<std::pair<int, double>>& entries) {
  spline::EvaluationMatrix m(1, 6);
  for (const auto& [column, weight] : entries) m.insert(0, column) = weight;
  m.makeCompressed();
  return {m, 0};
}

/// Two faces meeting at the ruling from point 0 to point 1: face 1's tangents are points 2 and 3,
/// face 2's points 4 and 5 (t_i = a′ + b′ of face i), d = p1 − p0 on both sides; one pair.
RulingNormalMatchTerm sharedRulingTerm() {
  const LinearPoints ruling = pointRow({{0, -1.0}, {1, 1.0}});
  return RulingNormalMatchTerm("smooth", pointRow({{2, 1.0}, {3, 1.0}}), ruling, pointRow({{4, 1.0}, {5, 1.0}}), ruling,
                               {1.0}, {-1.0});
}

TEST(RulingNormalMatchTerm, JacobianMatchesFiniteDifferencesAtASharedRuling) {
  RulingNormalMatchTerm term = sharedRulingTerm();
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(18, 42));
}

TEST(RulingNormalMatchTerm, RefusesMismatchedRowsAndOrientationsOtherThanPlusOrMinusOne) {
  SmoothEdgeFixture f;
  const std::vector<double> plus(static_cast<std::size_t>(f.K), 1.0);
  const LinearPoints shorter{spline::evaluationMatrix(f.knots, {0.5}, 1), 0};
  EXPECT_THROW(RulingNormalMatchTerm("smooth", f.da, f.across(1), shorter, f.across(2), plus, plus), std::invalid_argument);
  std::vector<double> half = plus;
  half[1] = 0.5;
  EXPECT_THROW(RulingNormalMatchTerm("smooth", f.da, f.across(1), f.da, f.across(2), plus, half), std::invalid_argument);
}

/// A planar curve in the xy-plane and two faces given by free vectors across it, face 1 with
/// normal n1 = cosα e_z + sinα b and face 2 continuing beyond the curve with normal
/// n2 = cosβ e_z + sinβ b (b = e_z × t): one tangent plane when α = β, a fold of α − β otherwise.
struct HingedSheets {
  spline::KnotVector knots = spline::KnotVector::clampedUniform(3, 6);
  std::vector<double> params = knots.spanSamples(7);
  int K = static_cast<int>(params.size());
  int offSide1 = 18, offSide2 = 18 + 3 * K;
  spline::BSplineCurve curve;
  Eigen::VectorXd x;
  LinearPoints da{spline::evaluationMatrix(knots, params, 1), 0};
  LinearPoints side1 = LinearPoints::identity(K, offSide1), side2 = LinearPoints::identity(K, offSide2);

  HingedSheets(double alpha, double beta) {
    x = randomVector(18 + 6 * K, 43);
    for (int i = 0; i < 6; ++i) x[3 * i + 2] = 0.0;
    curve.knots = knots;
    curve.points.resize(6, 3);
    for (int i = 0; i < 6; ++i) curve.points.row(i) = x.segment<3>(3 * i).transpose();
    for (int k = 0; k < K; ++k) {
      const Eigen::Vector3d t = tangent(k);
      // Face 1 lies on one side: across n1 × t, so t × (n1 × t) = n1. Face 2 on the other side:
      // across t × n2 (pointing away from face 1), so t × (t × n2) = −n2: orientation −1.
      x.segment<3>(offSide1 + 3 * k) = 0.7 * normal(k, alpha).cross(t);
      x.segment<3>(offSide2 + 3 * k) = 1.4 * t.cross(normal(k, beta));
    }
  }
  Eigen::Vector3d tangent(int k) const { return curve.evaluate(params[k], 1).normalized(); }
  Eigen::Vector3d normal(int k, double angle) const {
    return std::cos(angle) * Eigen::Vector3d::UnitZ() + std::sin(angle) * Eigen::Vector3d::UnitZ().cross(tangent(k));
  }
};

TEST(RulingNormalMatchTerm, VanishesOnOneTangentPlaneAndMeasuresAFoldAsTheNormalsDifference) {
  const double alpha = 0.3;
  const HingedSheets smooth(alpha, alpha);
  const std::vector<double> plus(static_cast<std::size_t>(smooth.K), 1.0), minus(static_cast<std::size_t>(smooth.K), -1.0);
  RulingNormalMatchTerm flat("smooth", smooth.da, smooth.side1, smooth.da, smooth.side2, plus, minus);
  EXPECT_LT(residuals(flat, smooth.x).cwiseAbs().maxCoeff(), 1e-14);
  // Folded by 0.5 rad: every pair's rows are n1 − n2, of length 2 sin(0.25), computed here.
  const HingedSheets folded(alpha, alpha - 0.5);
  RulingNormalMatchTerm fold("smooth", folded.da, folded.side1, folded.da, folded.side2, plus, minus);
  const Eigen::VectorXd r = residuals(fold, folded.x);
  for (int k = 0; k < folded.K; ++k) {
    const Eigen::Vector3d expected = folded.normal(k, alpha) - folded.normal(k, alpha - 0.5);
    EXPECT_LT((r.segment<3>(3 * k) - expected).norm(), 1e-13) << "pair " << k;
    EXPECT_NEAR(r.segment<3>(3 * k).norm(), 2.0 * std::sin(0.25), 1e-13);
  }
}

TEST(RulingNormalMatchTerm, EqualsNormalMatchTermWhenTheFreeNormalsAreTheFaces) {
  // NormalMatchTerm over free normals set to the faces' normals gives the same rows, at any fold.
  const HingedSheets s(0.2, -0.6);
  const int offN1 = 18 + 6 * s.K, offN2 = offN1 + 3 * s.K;
  Eigen::VectorXd withNormals(offN2 + 3 * s.K);
  withNormals.head(s.x.size()) = s.x;
  for (int k = 0; k < s.K; ++k) {
    withNormals.segment<3>(offN1 + 3 * k) = s.normal(k, 0.2);
    withNormals.segment<3>(offN2 + 3 * k) = s.normal(k, -0.6);
  }
  const std::vector<double> plus(static_cast<std::size_t>(s.K), 1.0), minus(static_cast<std::size_t>(s.K), -1.0);
  RulingNormalMatchTerm ruling("smooth", s.da, s.side1, s.da, s.side2, plus, minus);
  NormalMatchTerm free("smooth", LinearPoints::identity(s.K, offN1), LinearPoints::identity(s.K, offN2));
  const Eigen::VectorXd rr = residuals(ruling, withNormals), rf = residuals(free, withNormals);
  EXPECT_LT((rr - rf).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_GT(rr.cwiseAbs().maxCoeff(), 0.3);
}

TEST(RulingNormalMatchTerm, ADegeneratePairGivesZeroRowsAndAZeroJacobian) {
  // A ruling of no length (p1 = p0), then face 1's tangent along the ruling (t1 ∥ d): no plane.
  RulingNormalMatchTerm term = sharedRulingTerm();
  std::vector<engine::JacobianEntry> entries;
  term.jacobianStructure(entries);
  for (int degenerate = 0; degenerate < 2; ++degenerate) {
    Eigen::VectorXd x = randomVector(18, 44);
    if (degenerate == 0) {
      x.segment<3>(3) = x.segment<3>(0);
    } else {
      x.segment<3>(0).setZero();
      x.segment<3>(3) << 1.0, 2.0, 3.0;
      x.segment<3>(6) << 0.5, 1.0, 1.5;
      x.segment<3>(9) << 0.5, 1.0, 1.5;
    }
    Eigen::VectorXd r(term.numResiduals());
    std::vector<double> J(entries.size(), 1.0);
    term.evaluate(x, r.data(), J.data());
    EXPECT_EQ(r.cwiseAbs().maxCoeff(), 0.0) << "case " << degenerate;
    for (double v : J) EXPECT_EQ(v, 0.0);
  }
}

}  // namespace
}  // namespace devsurf::terms
