// Algorithm 1 (001_… §4), the §4 preprocessing and the §3.4 curve extension.

#include <gtest/gtest.h>

#include <cmath>

#include "QuasiStripTestCurves.h"
#include "devsurf/models/quasi_strip/SurfaceConversion.h"

namespace devsurf::models::quasi_strip {
namespace {

spline::BSplineCurve fig4Curve(double z) {
  spline::BSplineCurve c;
  c.knots = spline::KnotVector::clamped(3, {0, 0, 0, 0, 0.5, 1, 1, 1, 1}, 5);
  c.points.resize(5, 3);
  c.points << 0, 0, z, 1, 0.8, z + 0.2, 2, -0.5, z, 3, 0.6, z - 0.3, 4, 0, z;
  return c;
}

TEST(SurfaceConversion, Figure4LikeInputGivesDegreeSixPiecesAgreeingWithTheRuledSurface) {
  // Cubic curves with knots [0,0,0,0,0.5,1,1,1,1]; quadratic σ with 10 coefficients (Fig. 4).
  const spline::BSplineCurve c1 = fig4Curve(0.0), c2 = fig4Curve(1.0);
  Mapping sigma;
  sigma.degree = 2;
  sigma.knots = {0, 0, 0, 1.0 / 6, 5.0 / 18, 7.0 / 18, 0.5, 11.0 / 18, 13.0 / 18, 5.0 / 6, 1, 1, 1};
  sigma.coefficients.resize(10);
  for (int i = 0; i < 10; ++i) sigma.coefficients[i] = std::pow(i / 9.0, 1.3);
  const RuledBSplineSurface s = convertRuledSurface(c1, c2, sigma, 0.0, 1.0);
  EXPECT_EQ(s.degree, 6);
  // Pieces: σ's 8 spans split once more where σ(t) = 0.5 (C2's knot), unless it is a σ knot.
  const int pieces = (static_cast<int>(s.side0.rows()) - 1) / 6;
  EXPECT_GE(pieces, 8);
  EXPECT_EQ(s.knots.size(), s.side0.rows() + 7);
  double worst = 0.0;
  for (int i = 0; i <= 500; ++i) {
    const double t = i / 500.0;
    const double T = sigma.evaluate(t);
    for (double v : {0.0, 0.5, 1.0}) {
      const Eigen::Vector3d ruled = (1 - v) * c1.evaluate(t, 0) + v * c2.evaluate(T, 0);
      worst = std::max(worst, (s.evaluate(v, t) - ruled).norm());
    }
  }
  EXPECT_LE(worst, 1e-12);
}

TEST(SurfaceConversion, MakeCompatibleGivesOneDegreeAndOneKnotVectorWithoutChangingTheCurves) {
  const spline::BSplineCurve a = fig4Curve(0.0);
  spline::BSplineCurve b;
  b.knots = spline::KnotVector::clamped(2, {0, 0, 0, 0.3, 0.5, 1, 1, 1}, 5);
  b.points = fig4Curve(1.0).points;
  const auto [ca, cb] = makeCompatible(a, b);
  EXPECT_EQ(ca.degree(), 3);
  EXPECT_EQ(cb.degree(), 3);
  EXPECT_EQ(ca.knots.knots(), cb.knots.knots());
  for (double u : {0.0, 0.1, 0.3, 0.49, 0.5, 0.77, 1.0}) {
    EXPECT_LE((ca.evaluate(u, 0) - a.evaluate(u, 0)).norm(), 1e-13);
    EXPECT_LE((cb.evaluate(u, 0) - b.evaluate(u, 0)).norm(), 1e-13);
  }
}

TEST(SurfaceConversion, ExtendedCurveKeepsTheCurveAndContinuesItsEndSpans) {
  const spline::BSplineCurve c = fig4Curve(0.0);
  const spline::BSplineCurve e = extendCurve(c, 0.1, 0.25);
  EXPECT_DOUBLE_EQ(e.knots.domainBegin(), -0.1);
  EXPECT_DOUBLE_EQ(e.knots.domainEnd(), 1.25);
  for (double u : {0.0, 0.2, 0.5, 0.9, 1.0})
    EXPECT_LE((e.evaluate(u, 0) - c.evaluate(u, 0)).norm(), 1e-13);
  // The end span's polynomial continued: its Taylor series at 1 (degree 3, exact).
  const double h = 0.25;
  const Eigen::Vector3d taylor = c.evaluate(1.0, 0) + h * c.evaluate(1.0, 1) +
                                 h * h / 2 * c.evaluate(1.0, 2) + h * h * h / 6 * c.evaluate(1.0, 3);
  EXPECT_LE((e.evaluate(1.25, 0) - taylor).norm(), 1e-12);
  const spline::BSplineCurve unit = reparametrizeToUnit(e);
  EXPECT_LE((unit.evaluate((1.0 + 0.1) / 1.35, 0) - c.evaluate(1.0, 0)).norm(), 1e-13);
}

TEST(Mapping, ShapeParametersRoundTripAndTheIdentityIsTheGrevilleAbscissae) {
  const spline::KnotVector knots = spline::KnotVector::clampedUniform(2, 7);
  Mapping m;
  m.degree = 2;
  m.knots = knots.knots();
  m.coefficients = mappingCoefficients(shapeParameters(identityCoefficients(knots)));
  for (double t : {0.0, 0.13, 0.5, 0.91, 1.0}) {
    EXPECT_NEAR(m.evaluate(t), t, 1e-15);
    EXPECT_NEAR(m.evaluate(t, 1), 1.0, 1e-13);
    EXPECT_NEAR(m.inverse(t), t, 1e-13);
  }
  // Tail sums reproduce σ: Σ_k S(i,k) ε_k² = σ(t_i).
  const Eigen::VectorXd eps = Eigen::VectorXd::LinSpaced(7, 0.2, 0.8);
  m.coefficients = mappingCoefficients(eps);
  const std::vector<double> params = {0.0, 0.3, 0.55, 1.0};
  const spline::EvaluationMatrix s = tailSumMatrix(knots, params);
  const Eigen::VectorXd viaTails = s * eps.cwiseAbs2();
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(viaTails[i], m.evaluate(params[i]), 1e-14);
}

}  // namespace
}  // namespace devsurf::models::quasi_strip
