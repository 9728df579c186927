// Least-squares approximation of a curve in another spline space, and Greville abscissae.

#include <gtest/gtest.h>

#include <random>

#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::spline {
namespace {

BSplineCurve randomCurve(std::mt19937& rng, int n, int degree) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  BSplineCurve c;
  c.knots = KnotVector::clampedUniform(degree, n);
  c.points.resize(n, 3);
  for (int i = 0; i < n; ++i) c.points.row(i) << i + 0.3 * u(rng), u(rng), u(rng);
  return c;
}

double maxGap(const BSplineCurve& a, const BSplineCurve& b) {
  double gap = 0.0;
  for (int k = 0; k <= 200; ++k) {
    const double t = a.knots.domainBegin() + (a.knots.domainEnd() - a.knots.domainBegin()) * k / 200.0;
    gap = std::max(gap, (a.evaluate(t) - b.evaluate(t)).norm());
  }
  return gap;
}

TEST(ApproximateInSpace, ASpaceThatContainsTheCurveReproducesItAndKeepsItsEnds) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 100; ++trial) {
    const int degree = 2 + trial % 3, n = degree + 1 + trial % 7;
    const BSplineCurve c = randomCurve(rng, n, degree);
    // A refined space contains the curve: inserting knots is exact, approximating must be too.
    const BSplineCurve refined = refineKnots(c, {0.13, 0.5, 0.77});
    const BSplineCurve again = approximateInSpace(c, refined.knots);
    EXPECT_LT(maxGap(c, again), 1e-10) << trial;
    EXPECT_EQ(again.points.row(0), c.points.row(0));
    EXPECT_EQ(again.points.row(again.points.rows() - 1), c.points.row(n - 1));
  }
}

TEST(ApproximateInSpace, OneKnotFewerGivesTheBestCurveOfTheSmallerSpace) {
  std::mt19937 rng(12);
  const BSplineCurve c = randomCurve(rng, 9, 3);
  std::vector<double> t = c.knots.knots();
  t.erase(t.begin() + 6);  // an interior knot
  const KnotVector smaller = KnotVector::clamped(3, t, 8);
  const BSplineCurve approx = approximateInSpace(c, smaller, 40);
  // Least squares: no perturbation of an interior control point brings the samples closer.
  auto error = [&c](const BSplineCurve& a) {
    double sum = 0.0;
    for (int k = 0; k < 400; ++k) {
      const double u = (k + 0.5) / 400.0 * c.knots.domainEnd();
      sum += (a.evaluate(u) - c.evaluate(u)).squaredNorm();
    }
    return sum;
  };
  const double best = error(approx);
  for (int i = 1; i + 1 < approx.points.rows(); ++i)
    for (int d = 0; d < 3; ++d) {
      BSplineCurve moved = approx;
      moved.points(i, d) += 1e-3;
      EXPECT_GT(error(moved), best * (1.0 - 1e-9)) << i << "," << d;
    }
  EXPECT_THROW(approximateInSpace(c, KnotVector::clampedUniform(2, 8)), std::invalid_argument);  // another degree
}

TEST(GrevilleAbscissae, ClampedUniformCubicPointsSitAtTheirAverages) {
  const std::vector<double> g = grevilleAbscissae(KnotVector::clampedUniform(3, 4));
  ASSERT_EQ(g.size(), 4u);
  const double end = KnotVector::clampedUniform(3, 4).domainEnd();
  EXPECT_NEAR(g[0], 0.0, 1e-15);
  EXPECT_NEAR(g[1], end / 3.0, 1e-15);
  EXPECT_NEAR(g[2], 2.0 * end / 3.0, 1e-15);
  EXPECT_NEAR(g[3], end, 1e-15);
}

}  // namespace
}  // namespace devsurf::spline
