#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "support/ExpectError.h"

#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/KnotVector.h"

namespace devsurf::spline {
namespace {

/// Largest distance between the two curves at 200 parameters spread over a's domain.
double maxDeviation(const BSplineCurve& a, const BSplineCurve& b, int derivative = 0) {
  double worst = 0.0;
  for (double u : a.knots.uniformSamples(200)) {
    worst = std::max(worst, (a.evaluate(u, derivative) - b.evaluate(u, derivative)).norm());
  }
  return worst;
}

BSplineCurve nonUniformCubic() {
  const KnotVector kv =
      KnotVector::clamped(3, {0, 0, 0, 0, 0.15, 0.4, 0.4, 0.8, 1, 1, 1, 1}, 8);
  Eigen::MatrixXd pts(8, 3);
  pts << 0, 0, 0, 1, 2, 0, 2, 2, 1, 3, 0, 1, 4, -1, 0, 5, 1, 2, 6, 0, 0, 7, 1, 1;
  return BSplineCurve{kv, pts, {}};
}

BSplineCurve rationalCubic() {
  BSplineCurve c = nonUniformCubic();
  c.weights.resize(8);
  c.weights << 1, 0.5, 2, 1.5, 0.7, 3, 1, 0.9;
  return c;
}

/// Random clamped curve of degree p on a knot vector with interior multiplicities 1..p.
BSplineCurve randomClampedCurve(int p, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coord(-1.0, 1.0);
  std::uniform_int_distribution<int> mult(1, p);
  std::vector<double> knots(static_cast<size_t>(p + 1), -0.5);
  double u = -0.5;
  for (int k = 0; k < 4; ++k) {
    u += 0.1 + 0.5 * (coord(rng) + 1.0);
    const int m = mult(rng);
    for (int i = 0; i < m; ++i) knots.push_back(u);
  }
  u += 0.3;
  for (int i = 0; i <= p; ++i) knots.push_back(u);
  const int n = static_cast<int>(knots.size()) - p - 1;
  Eigen::MatrixXd pts(n, 2);
  for (int i = 0; i < n; ++i) pts.row(i) << coord(rng), coord(rng);
  return BSplineCurve{KnotVector::clamped(p, knots, n), pts, {}};
}

using devsurf::testing::expectThrowMentioning;

// ---- Bézier --------------------------------------------------------------------------------

TEST(Bezier, DeCasteljauMatchesTheBernsteinForm) {
  const Eigen::MatrixXd pts = Eigen::MatrixXd::Random(5, 3);
  for (double t : {0.0, 0.2, 0.5, 0.77, 1.0}) {
    Eigen::VectorXd expected = Eigen::VectorXd::Zero(3);
    const double binom[] = {1, 4, 6, 4, 1};
    for (int i = 0; i <= 4; ++i) {
      expected += binom[i] * std::pow(t, i) * std::pow(1 - t, 4 - i) * pts.row(i).transpose();
    }
    EXPECT_LT((evaluateBezier(pts, t) - expected).norm(), 1e-14);
  }
}

TEST(Bezier, DegreeElevationLeavesTheCurveUnchanged) {
  const Eigen::MatrixXd pts = Eigen::MatrixXd::Random(4, 3);
  for (int t : {0, 1, 2, 5}) {
    const Eigen::MatrixXd up = elevateBezierDegree(pts, t);
    ASSERT_EQ(up.rows(), 4 + t);
    ASSERT_EQ(up.cols(), 3);
    EXPECT_EQ((up.row(0) - pts.row(0)).norm(), 0.0);
    EXPECT_EQ((up.row(3 + t) - pts.row(3)).norm(), 0.0);
    for (int k = 0; k <= 200; ++k) {
      const double s = k / 200.0;
      EXPECT_LT((evaluateBezier(up, s) - evaluateBezier(pts, s)).norm(), 1e-12);
    }
  }
}

TEST(Bezier, CompositionEqualsTheCurveOfTheReparametrization) {
  const Eigen::MatrixXd pts = Eigen::MatrixXd::Random(4, 3);  // cubic
  Eigen::VectorXd phi(3);                                     // quadratic into [0,1]
  phi << 0.1, 0.9, 0.4;
  const Eigen::MatrixXd composed = composeBezier(pts, phi);
  ASSERT_EQ(composed.rows(), 3 * 2 + 1);
  ASSERT_EQ(composed.cols(), 3);
  const Eigen::MatrixXd phiPoints = phi;  // φ itself as a 1-D Bézier curve
  for (int k = 0; k <= 200; ++k) {
    const double t = k / 200.0;
    const double s = evaluateBezier(phiPoints, t)(0);
    EXPECT_LT((evaluateBezier(composed, t) - evaluateBezier(pts, s)).norm(), 1e-12);
  }
}

TEST(Bezier, CompositionWithTheIdentityIsTheCurve) {
  const Eigen::MatrixXd pts = Eigen::MatrixXd::Random(5, 2);
  Eigen::VectorXd identity(2);
  identity << 0, 1;
  EXPECT_LT((composeBezier(pts, identity) - pts).cwiseAbs().maxCoeff(), 1e-15);
  // A constant reparametrization collapses the curve to one point.
  const Eigen::MatrixXd point = composeBezier(pts, Eigen::VectorXd::Constant(1, 0.3));
  ASSERT_EQ(point.rows(), 1);
  EXPECT_LT((point.row(0).transpose() - evaluateBezier(pts, 0.3)).norm(), 1e-15);
}

TEST(Bezier, HigherDegreeCompositionStaysExact) {
  const Eigen::MatrixXd pts = Eigen::MatrixXd::Random(6, 2);  // quintic
  Eigen::VectorXd phi(4);                                     // cubic
  phi << 0.0, 0.7, 0.2, 1.0;
  const Eigen::MatrixXd composed = composeBezier(pts, phi);
  ASSERT_EQ(composed.rows(), 16);
  for (int k = 0; k <= 200; ++k) {
    const double t = k / 200.0;
    const double s = evaluateBezier(Eigen::MatrixXd(phi), t)(0);
    EXPECT_LT((evaluateBezier(composed, t) - evaluateBezier(pts, s)).norm(), 1e-12);
  }
}

// ---- knot insertion and refinement ---------------------------------------------------------

TEST(KnotInsertion, InsertingAKnotLeavesTheCurveUnchanged) {
  const BSplineCurve c = nonUniformCubic();
  for (double u : {0.05, 0.15, 0.4, 0.6, 0.99}) {
    const int before = c.knots.multiplicity(u);
    for (int times = 1; before + times <= 3; ++times) {
      const BSplineCurve r = insertKnot(c, u, times);
      EXPECT_EQ(r.knots.numControlPoints(), 8 + times);
      EXPECT_EQ(r.knots.multiplicity(u), before + times);
      EXPECT_EQ(r.degree(), 3);
      EXPECT_LT(maxDeviation(c, r), 1e-12) << "u = " << u << ", times = " << times;
      EXPECT_LT(maxDeviation(c, r, 1), 1e-10) << "u = " << u << ", times = " << times;
    }
  }
}

TEST(KnotInsertion, RationalCurvesAreInsertedInHomogeneousCoordinates) {
  const BSplineCurve c = rationalCubic();
  for (double u : {0.2, 0.6, 0.9}) {
    const BSplineCurve r = insertKnot(c, u, 2);
    EXPECT_TRUE(r.isRational());
    EXPECT_EQ(r.weights.size(), 10);
    EXPECT_LT(maxDeviation(c, r), 1e-12) << "u = " << u;
  }
  const BSplineCurve r = insertKnot(c, 0.4);  // onto the existing double knot
  EXPECT_EQ(r.knots.multiplicity(0.4), 3);
  EXPECT_LT(maxDeviation(c, r), 1e-12);
  EXPECT_LT(maxDeviation(c, r, 1), 1e-10);
}

TEST(KnotInsertion, RefinementLeavesTheCurveUnchanged) {
  for (const BSplineCurve& c : {nonUniformCubic(), rationalCubic()}) {
    const std::vector<double> extra = {0.05, 0.1, 0.1, 0.4, 0.5, 0.5, 0.5, 0.95};
    const BSplineCurve r = refineKnots(c, extra);
    EXPECT_EQ(r.knots.numControlPoints(), 8 + 8);
    EXPECT_EQ(r.knots.multiplicity(0.5), 3);
    EXPECT_EQ(r.knots.multiplicity(0.4), 3);
    EXPECT_LT(maxDeviation(c, r), 1e-12);
  }
}

TEST(KnotInsertion, RestrictingToAnIntervalKeepsTheCurvesPointsAtTheirParameters) {
  // Random curves of degrees 1–5 on knots with repeated interior knots, random intervals (ends on
  // knots, at the domain's ends, anywhere), and a rational cubic.
  std::mt19937 rng(515);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 300; ++trial) {
    const BSplineCurve c = trial % 50 == 49 ? rationalCubic() : randomClampedCurve(1 + trial % 5, 100u + trial);
    const double begin = c.knots.domainBegin(), end = c.knots.domainEnd();
    const std::vector<double>& t = c.knots.knots();
    double u0 = begin + (end - begin) * unit(rng), u1 = begin + (end - begin) * unit(rng);
    if (trial % 4 == 1) u0 = t[static_cast<std::size_t>(c.degree() + 1 + trial % 3)];  // on a knot
    if (trial % 7 == 2) u0 = begin;
    if (trial % 5 == 3) u1 = end;
    if (u0 > u1) std::swap(u0, u1);
    if (!(u1 - u0 > 1e-6)) continue;
    const BSplineCurve r = restrictToInterval(c, u0, u1);
    EXPECT_EQ(r.knots.domainBegin(), u0);
    EXPECT_EQ(r.knots.domainEnd(), u1);
    EXPECT_EQ(r.isRational(), c.isRational());
    for (int k = 0; k <= 40; ++k) {
      const double u = u0 + (u1 - u0) * k / 40.0;
      EXPECT_LT((r.evaluate(u) - c.evaluate(u)).norm(), 1e-12) << "trial " << trial << ", u " << u;
    }
    EXPECT_LT((r.points.row(0).transpose() - c.evaluate(u0)).norm(), 1e-12) << "the first control point is c(u0)";
  }
  const BSplineCurve c = randomClampedCurve(3, 7);
  const BSplineCurve whole = restrictToInterval(c, c.knots.domainBegin(), c.knots.domainEnd());
  EXPECT_EQ(whole.points, c.points);
  expectThrowMentioning([&c] { restrictToInterval(c, 0.3, 0.3); }, "u0 < u1");
  expectThrowMentioning([&c] { restrictToInterval(c, c.knots.domainBegin() - 1.0, 0.3); }, "u0 < u1");
}

TEST(KnotInsertion, RejectsBadRequestsWithAClearMessage) {
  const BSplineCurve c = nonUniformCubic();
  expectThrowMentioning([&] { insertKnot(c, 1.5); }, "outside the domain");
  expectThrowMentioning([&] { insertKnot(c, 0.4, 2); }, "would become 4, more than the degree 3");
  expectThrowMentioning([&] { insertKnot(c, 1.0); }, "more than the degree");
  BSplineCurve periodic{KnotVector::periodicUniform(3, 5), Eigen::MatrixXd::Zero(5, 2), {}};
  expectThrowMentioning([&] { insertKnot(periodic, 0.5); }, "only clamped curves");
  EXPECT_EQ(insertKnot(c, 0.3, 0).points, c.points);
}

// ---- Bézier pieces -------------------------------------------------------------------------

TEST(BezierPieces, EachPieceEvaluatesLikeTheCurveOnItsInterval) {
  for (const BSplineCurve& c :
       {nonUniformCubic(), randomClampedCurve(2, 3), randomClampedCurve(4, 11),
        BSplineCurve{KnotVector::clampedUniform(3, 4), Eigen::MatrixXd::Random(4, 2), {}}}) {
    const std::vector<BezierPiece> pieces = bezierPieces(c);
    const std::vector<double> bp = c.knots.breakpoints();
    ASSERT_EQ(pieces.size(), bp.size() - 1);
    for (size_t i = 0; i < pieces.size(); ++i) {
      const BezierPiece& piece = pieces[i];
      EXPECT_EQ(piece.begin, bp[i]);
      EXPECT_EQ(piece.end, bp[i + 1]);
      ASSERT_EQ(piece.points.rows(), c.degree() + 1);
      for (int k = 0; k <= 50; ++k) {
        const double s = k / 50.0;
        const double u = piece.begin + s * (piece.end - piece.begin);
        EXPECT_LT((evaluateBezier(piece.points, s) - c.evaluate(u)).norm(), 1e-12)
            << "piece " << i << ", s = " << s;
      }
    }
  }
}

TEST(BezierPieces, RejectsRationalAndPeriodicCurves) {
  expectThrowMentioning([] { bezierPieces(rationalCubic()); }, "only non-rational curves");
  BSplineCurve periodic{KnotVector::periodicUniform(3, 5), Eigen::MatrixXd::Zero(5, 2), {}};
  expectThrowMentioning([&] { bezierPieces(periodic); }, "only clamped curves");
}

// ---- degree elevation ----------------------------------------------------------------------

TEST(DegreeElevation, ElevatedSplineIsTheSameCurveWithHigherMultiplicities) {
  std::vector<BSplineCurve> curves = {
      nonUniformCubic(),
      BSplineCurve{KnotVector::clampedUniform(1, 5), Eigen::MatrixXd::Random(5, 2), {}},
      BSplineCurve{KnotVector::clampedUniform(2, 3), Eigen::MatrixXd::Random(3, 2), {}},
  };
  for (int p = 1; p <= 5; ++p) {
    for (unsigned seed = 0; seed < 4; ++seed) curves.push_back(randomClampedCurve(p, 100 * p + seed));
  }
  for (const BSplineCurve& c : curves) {
    const std::vector<double> bp = c.knots.breakpoints();
    for (int t : {1, 2, 3}) {
      const BSplineCurve e = elevateDegree(c, t);
      EXPECT_EQ(e.degree(), c.degree() + t);
      // Every distinct knot gains t copies.
      EXPECT_EQ(e.knots.numControlPoints(),
                c.knots.numControlPoints() + t * (static_cast<int>(bp.size()) - 1));
      EXPECT_EQ(e.knots.breakpoints(), bp);
      for (double b : bp) {
        EXPECT_EQ(e.knots.multiplicity(b), c.knots.multiplicity(b) + t) << "knot " << b;
      }
      EXPECT_LT(maxDeviation(c, e), 1e-12) << "degree " << c.degree() << ", t = " << t;
    }
  }
}

TEST(DegreeElevation, ZeroElevationIsTheIdentityAndBadInputIsRejected) {
  const BSplineCurve c = nonUniformCubic();
  EXPECT_EQ(elevateDegree(c, 0).points, c.points);
  expectThrowMentioning([&] { elevateDegree(c, -1); }, "t must be >= 0");
  expectThrowMentioning([] { elevateDegree(rationalCubic(), 1); }, "only non-rational curves");
  BSplineCurve periodic{KnotVector::periodicUniform(3, 5), Eigen::MatrixXd::Zero(5, 2), {}};
  expectThrowMentioning([&] { elevateDegree(periodic, 1); }, "only clamped curves");
  expectThrowMentioning([&] { elevateBezierDegree(c.points, -2); }, "t must be >= 0");
}

}  // namespace
}  // namespace devsurf::spline
