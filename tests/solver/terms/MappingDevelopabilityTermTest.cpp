// MappingDevelopabilityTerm (001_… eq. 8/9) and the ExtendedCurve it evaluates C2 with.

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <cmath>
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "devsurf/spline/Basis.h"
#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/KnotVector.h"
#include "devsurf/terms/ExtendedCurve.h"
#include "devsurf/terms/MappingDevelopabilityTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

spline::BSplineCurve wavyCubic() {
  spline::BSplineCurve c;
  c.knots = spline::KnotVector::clamped(3, {0, 0, 0, 0, 0.3, 0.7, 1, 1, 1, 1}, 6);
  c.points.resize(6, 3);
  c.points << 0, 0, 0, 1, 0.5, 0.2, 2, -0.3, 0.6, 3, 0.4, 0.1, 4, 0.0, -0.3, 5, 0.2, 0.0;
  return c;
}

/// Tail sums S(i,k) = Σ_{j≥k} B_j(t_i) of a quadratic mapping with 6 coefficients.
spline::EvaluationMatrix tailSums(const std::vector<double>& params) {
  const spline::KnotVector knots = spline::KnotVector::clampedUniform(2, 6);
  const spline::EvaluationMatrix basis = spline::evaluationMatrix(knots, params, 0);
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < static_cast<int>(params.size()); ++i) {
    Eigen::VectorXd row = Eigen::VectorXd::Zero(6);
    for (spline::EvaluationMatrix::InnerIterator it(basis, i); it; ++it) row[it.col()] = it.value();
    double tail = 0.0;
    for (int k = 5; k >= 0; --k) {
      tail += row[k];
      if (tail != 0.0) entries.emplace_back(i, k, tail);
    }
  }
  spline::EvaluationMatrix s(static_cast<int>(params.size()), 6);
  s.setFromTriplets(entries.begin(), entries.end());
  return s;
}

TEST(ExtendedCurve, AgreesWithTheCurveInsideAndContinuesItsEndPolynomialsOutside) {
  const spline::BSplineCurve c = wavyCubic();
  const ExtendedCurve e(c);
  for (double u : {0.0, 0.1, 0.3, 0.5, 0.99, 1.0}) {
    const CurveJet jet = e.evaluate(u);
    EXPECT_LT((jet.point - c.evaluate(u, 0)).norm(), 1e-12) << u;
    EXPECT_LT((jet.d1 - c.evaluate(u, 1)).norm(), 1e-10) << u;
    EXPECT_LT((jet.d2 - c.evaluate(u, 2)).norm(), 1e-8) << u;
  }
  // Beyond the end: the Taylor expansion of the last span's polynomial (degree 3, exact).
  const CurveJet end = e.evaluate(1.0);
  const double h = 0.2;
  const Eigen::Vector3d d3 = (e.evaluate(0.9).d2 - e.evaluate(0.8).d2) / 0.1;  // constant on the span
  const Eigen::Vector3d taylor = end.point + h * end.d1 + h * h / 2 * end.d2 + h * h * h / 6 * d3;
  EXPECT_LT((e.evaluate(1.0 + h).point - taylor).norm(), 1e-9);
}

TEST(MappingDevelopabilityTerm, JacobianMatchesFiniteDifferences) {
  const std::vector<double> params = {0.0, 0.15, 0.4, 0.77, 1.0};
  const int samples = static_cast<int>(params.size());
  const spline::BSplineCurve c1 = wavyCubic();
  Eigen::MatrixX3d points(samples, 3), tangents(samples, 3);
  for (int i = 0; i < samples; ++i) {
    points.row(i) = c1.evaluate(params[i], 0).transpose() + Eigen::RowVector3d(0.1, 1.0, 0.3);
    tangents.row(i) = c1.evaluate(params[i], 1).transpose();
  }
  std::vector<int> normals;
  for (int i = 0; i < samples; ++i) normals.push_back(6 + 3 * i);
  auto c2 = std::make_shared<const ExtendedCurve>(wavyCubic());
  MappingDevelopabilityTerm term("developability", 0, tailSums(params), normals, points, tangents,
                                 c2);
  EXPECT_EQ(term.numResiduals(), 3 * samples);
  expectNoDuplicateEntries(term);
  Eigen::VectorXd x = randomVector(6 + 3 * samples, 11);
  expectJacobianMatches(term, x);
  // Shape parameters large enough that σ leaves [0,1] at the end: the extension is smooth too.
  x.head(6) *= 1.6;
  EXPECT_GT(term.mappedParameter(x, samples - 1), 1.0);
  expectJacobianMatches(term, x);
}

TEST(MappingDevelopabilityTerm, VanishesOnACylinderWithTheTrueMappingAndNormals) {
  // C1(t) = C2(t) + d: rulings parallel to d, normal C2′ × d.
  const std::vector<double> params = {0.0, 0.3, 0.6, 1.0};
  const spline::BSplineCurve c = wavyCubic();
  const Eigen::Vector3d d(0.2, 1.0, 0.4);
  Eigen::MatrixX3d points(4, 3), tangents(4, 3);
  Eigen::VectorXd x(6 + 12);
  // T = t: ε² are the differences of the Greville abscissae of the quadratic mapping.
  const double greville[6] = {0, 0.125, 0.375, 0.625, 0.875, 1.0};
  x[0] = 0.0;
  for (int k = 1; k < 6; ++k) x[k] = std::sqrt(greville[k] - greville[k - 1]);
  std::vector<int> normals;
  for (int i = 0; i < 4; ++i) {
    points.row(i) = (c.evaluate(params[i], 0) + d).transpose();
    tangents.row(i) = c.evaluate(params[i], 1).transpose();
    normals.push_back(6 + 3 * i);
    x.segment<3>(6 + 3 * i) = Eigen::Vector3d(c.evaluate(params[i], 1)).cross(d).normalized();
  }
  MappingDevelopabilityTerm term("developability", 0, tailSums(params), normals, points, tangents,
                                 std::make_shared<const ExtendedCurve>(c));
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(term.mappedParameter(x, i), params[i], 1e-15);
  EXPECT_LT(residuals(term, x).cwiseAbs().maxCoeff(), 1e-14);
}

}  // namespace
}  // namespace devsurf::terms
