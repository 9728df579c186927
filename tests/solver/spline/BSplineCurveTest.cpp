#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "support/ExpectError.h"

#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/Basis.h"
#include "devsurf/spline/KnotVector.h"

namespace devsurf::spline {
namespace {

double f(double u) { return u * u * u - 2 * u * u + u + 1; }
double df(double u) { return 3 * u * u - 4 * u + 1; }
double d2f(double u) { return 6 * u - 4; }

/// Fits a clamped cubic to f by collocation at uniformly spaced parameters; since f is a cubic
/// polynomial, the spline reproduces it exactly.
BSplineCurve cubicThroughPolynomial(const KnotVector& kv) {
  const int n = kv.numControlPoints();
  const std::vector<double> params = kv.uniformSamples(n);
  const Eigen::MatrixXd a = Eigen::MatrixXd(evaluationMatrix(kv, params, 0));
  Eigen::VectorXd rhs(n);
  for (int k = 0; k < n; ++k) rhs(k) = f(params[k]);
  const Eigen::VectorXd coeffs = a.partialPivLu().solve(rhs);
  return BSplineCurve{kv, coeffs, {}};
}

TEST(BSplineCurve, ClampedCubicReproducesACubicPolynomialWithDerivatives) {
  for (const KnotVector& kv :
       {KnotVector::clampedUniform(3, 7),
        KnotVector::clamped(3, {0, 0, 0, 0, 0.1, 0.45, 0.45, 0.7, 1, 1, 1, 1}, 8)}) {
    const BSplineCurve c = cubicThroughPolynomial(kv);
    for (double u : kv.uniformSamples(201)) {
      EXPECT_NEAR(c.evaluate(u)(0), f(u), 1e-12) << "u = " << u;
      EXPECT_NEAR(c.evaluate(u, 1)(0), df(u), 1e-12) << "u = " << u;
      EXPECT_NEAR(c.evaluate(u, 2)(0), d2f(u), 1e-11) << "u = " << u;
      EXPECT_NEAR(c.evaluate(u, 3)(0), 6.0, 1e-10) << "u = " << u;
      EXPECT_EQ(c.evaluate(u, 4)(0), 0.0);
    }
  }
}

TEST(BSplineCurve, GrevilleAbscissaeGiveLinearPrecision) {
  const KnotVector kv = KnotVector::clamped(3, {0, 0, 0, 0, 0.2, 0.3, 0.75, 1, 1, 1, 1}, 7);
  Eigen::MatrixXd pts(7, 1);
  for (int i = 0; i < 7; ++i) {
    pts(i, 0) = (kv.knots()[i + 1] + kv.knots()[i + 2] + kv.knots()[i + 3]) / 3.0;
  }
  const BSplineCurve c{kv, pts, {}};
  for (double u : kv.uniformSamples(101)) {
    EXPECT_NEAR(c.evaluate(u)(0), u, 1e-15);
    EXPECT_NEAR(c.evaluate(u, 1)(0), 1.0, 1e-13);
  }
}

TEST(BSplineCurve, EndpointsOfAClampedCurveAreTheEndControlPoints) {
  const KnotVector kv = KnotVector::clamped(2, {1, 1, 1, 2, 4, 4, 4}, 4);
  const BSplineCurve c{kv, Eigen::MatrixXd::Random(4, 2), {}};
  EXPECT_LT((c.evaluate(1.0) - c.points.row(0).transpose()).norm(), 1e-15);
  EXPECT_LT((c.evaluate(4.0) - c.points.row(3).transpose()).norm(), 1e-15);
  // Parameters outside the domain are clamped into it.
  EXPECT_LT((c.evaluate(7.0) - c.points.row(3).transpose()).norm(), 1e-15);
}

TEST(BSplineCurve, VectorEvaluationStacksPointEvaluations) {
  const KnotVector kv = KnotVector::clampedUniform(3, 6);
  const BSplineCurve c{kv, Eigen::MatrixXd::Random(6, 3), Eigen::VectorXd::Constant(6, 0.5) +
                                                              Eigen::VectorXd::Random(6).cwiseAbs()};
  const std::vector<double> params = kv.uniformSamples(13);
  for (int d = 0; d <= 2; ++d) {
    const Eigen::MatrixXd all = c.evaluate(params, d);
    ASSERT_EQ(all.rows(), 13);
    ASSERT_EQ(all.cols(), 3);
    for (int k = 0; k < 13; ++k) {
      EXPECT_EQ((all.row(k).transpose() - c.evaluate(params[k], d)).norm(), 0.0);
    }
  }
}

TEST(BSplineCurve, VectorEvaluationOfAPolynomialCurveStacksPointEvaluationsForEveryDegree) {
  // The polynomial path of evaluate(params) writes each row from one basis evaluation; it must
  // give what evaluate(u) gives, for degrees 1…5, derivatives up to p + 1 (zero) and 2D/3D points.
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> coordinate(-2.0, 2.0);
  for (int p = 1; p <= 5; ++p)
    for (int dim : {2, 3}) {
      const int n = p + 1 + p % 3;
      const KnotVector kv = KnotVector::clampedUniform(p, n);
      Eigen::MatrixXd points(n, dim);
      for (Eigen::Index i = 0; i < points.size(); ++i) points.data()[i] = coordinate(rng);
      const BSplineCurve c{kv, points, Eigen::VectorXd()};
      const std::vector<double> params = kv.uniformSamples(17);
      for (int d = 0; d <= p + 1; ++d) {
        const Eigen::MatrixXd all = c.evaluate(params, d);
        ASSERT_EQ(all.rows(), 17);
        ASSERT_EQ(all.cols(), dim);
        for (int k = 0; k < 17; ++k) {
          const Eigen::VectorXd one = c.evaluate(params[k], d);
          EXPECT_LE((all.row(k).transpose() - one).norm(), 1e-12 * (1.0 + one.norm()))
              << "degree " << p << ", derivative " << d << ", sample " << k;
        }
      }
    }
}

BSplineCurve quarterCircle() {
  Eigen::MatrixXd pts(3, 2);
  pts << 1, 0, 1, 1, 0, 1;
  Eigen::VectorXd w(3);
  w << 1, std::sqrt(2.0) / 2, 1;
  return BSplineCurve{KnotVector::clampedUniform(2, 3), pts, w};
}

TEST(NurbsCurve, QuadraticRationalArcTracesAQuarterCircleExactly) {
  const BSplineCurve c = quarterCircle();
  EXPECT_TRUE(c.isRational());
  for (double u : c.knots.uniformSamples(201)) {
    const Eigen::VectorXd p = c.evaluate(u);
    EXPECT_NEAR(p.norm(), 1.0, 1e-14) << "u = " << u;
    EXPECT_GE(p(0), -1e-15);
    EXPECT_GE(p(1), -1e-15);
    // The tangent is perpendicular to the radius.
    const Eigen::VectorXd d1 = c.evaluate(u, 1);
    EXPECT_NEAR(p.dot(d1), 0.0, 1e-13 * d1.norm());
  }
  EXPECT_LT((c.evaluate(0.0) - Eigen::Vector2d(1, 0)).norm(), 1e-15);
  EXPECT_LT((c.evaluate(1.0) - Eigen::Vector2d(0, 1)).norm(), 1e-15);
}

TEST(BSplineCurve, DerivativesFromOneBasisEvaluationMatchEvaluate) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coordinate(-2.0, 2.0);
  auto randomPoints = [&rng, &coordinate](int n, int dim) {
    Eigen::MatrixXd p(n, dim);
    for (Eigen::Index i = 0; i < p.size(); ++i) p.data()[i] = coordinate(rng);
    return p;
  };
  std::vector<BSplineCurve> curves = {
      {KnotVector::clamped(3, {0, 0, 0, 0, 0.3, 0.5, 0.5, 1, 1, 1, 1}, 7), randomPoints(7, 3), {}},
      {KnotVector::periodicUniform(3, 7), randomPoints(7, 3), {}},
      {KnotVector::clampedUniform(17, 19), randomPoints(19, 3), {}},  // degree beyond the stack path
      quarterCircle(),                                                 // rational
  };
  for (const BSplineCurve& c : curves) {
    for (int upTo : {0, 1, 2, c.degree() + 1}) {
      Eigen::MatrixXd out(c.dimension(), upTo + 1);
      for (double u : c.knots.uniformSamples(37)) {
        c.derivatives(u, upTo, out);
        for (int k = 0; k <= upTo; ++k) {
          const Eigen::VectorXd expected = c.evaluate(u, k);
          EXPECT_LE((out.col(k) - expected).norm(), 1e-11 * (1.0 + expected.norm()))
              << "degree " << c.degree() << ", derivative " << k << ", u = " << u;
        }
      }
    }
  }
  Eigen::MatrixXd wrong(3, 1);
  EXPECT_THROW(curves[0].derivatives(0.5, 1, wrong), std::invalid_argument);
}

TEST(BSplineCurve, DerivativesOfAPairMatchEachCurveWhetherOrNotTheKnotsAreShared) {
  Eigen::MatrixXd a(7, 3), b(7, 3), c(8, 3);
  for (int i = 0; i < 7; ++i) {
    a.row(i) << i, std::sin(i), 0.1 * i * i;
    b.row(i) << i, 1.0 + std::cos(i), -0.2 * i;
  }
  for (int i = 0; i < 8; ++i) c.row(i) << i, 2.0, std::sin(0.5 * i);
  const KnotVector shared = KnotVector::clamped(3, {0, 0, 0, 0, 0.3, 0.5, 0.5, 1, 1, 1, 1}, 7);
  const BSplineCurve first{shared, a, {}}, second{shared, b, {}};
  const BSplineCurve other{KnotVector::clampedUniform(3, 8), c, {}};  // another knot vector
  for (const auto& [p, q] : {std::pair{first, second}, std::pair{first, other}}) {
    const CurvePair pair(p, q);
    EXPECT_EQ(pair.sharesBasis(), p.knots.knots() == q.knots.knots());
    Eigen::Matrix<double, 3, 3> outP, outQ;
    for (double u : shared.uniformSamples(23)) {
      pair.derivatives(u, 2, outP, outQ);
      for (int k = 0; k <= 2; ++k) {
        EXPECT_LE((outP.col(k) - p.evaluate(u, k)).norm(), 1e-12 * (1.0 + outP.col(k).norm()));
        EXPECT_LE((outQ.col(k) - q.evaluate(u, k)).norm(), 1e-12 * (1.0 + outQ.col(k).norm()));
      }
    }
  }
}

TEST(NurbsCurve, RationalDerivativesMatchFiniteDifferences) {
  // A non-uniform cubic NURBS in 3D, plus the circle arc; derivatives up to 4 (beyond the
  // degree of the arc, where the rational curve still bends).
  const KnotVector kv = KnotVector::clamped(3, {0, 0, 0, 0, 0.3, 0.5, 0.5, 1, 1, 1, 1}, 7);
  Eigen::MatrixXd pts(7, 3);
  pts << 0, 0, 0, 1, 2, 0, 2, 2, 1, 3, 0, 1, 4, -1, 0, 5, 1, 2, 6, 0, 0;
  Eigen::VectorXd w(7);
  w << 1, 0.5, 2, 1.5, 0.7, 3, 1;
  const double h = 1e-5;
  for (const BSplineCurve& c : {BSplineCurve{kv, pts, w}, quarterCircle()}) {
    for (double u : c.knots.spanSamples(6)) {
      for (int d = 1; d <= 4; ++d) {
        const Eigen::VectorXd exact = c.evaluate(u, d);
        const Eigen::VectorXd fd = (c.evaluate(u + h, d - 1) - c.evaluate(u - h, d - 1)) / (2 * h);
        EXPECT_LT((exact - fd).norm(), 1e-6 * std::max(1.0, exact.norm()))
            << "u = " << u << ", derivative " << d;
      }
    }
  }
}

TEST(NurbsCurve, EqualWeightsGiveThePolynomialCurve) {
  const KnotVector kv = KnotVector::clampedUniform(3, 6);
  const Eigen::MatrixXd pts = Eigen::MatrixXd::Random(6, 2);
  const BSplineCurve poly{kv, pts, {}};
  const BSplineCurve rat{kv, pts, Eigen::VectorXd::Constant(6, 2.5)};
  for (double u : kv.uniformSamples(31)) {
    for (int d = 0; d <= 3; ++d) {
      EXPECT_LT((poly.evaluate(u, d) - rat.evaluate(u, d)).norm(), 1e-12);
    }
  }
}

TEST(PeriodicCurve, IsClosedWithMatchingDerivativesUpToDegreeMinusOne) {
  for (int p = 1; p <= 4; ++p) {
    for (int n : {p + 1, p + 3}) {
      const KnotVector kv = KnotVector::periodicUniform(p, n);
      Eigen::MatrixXd pts(n, 2);
      for (int i = 0; i < n; ++i) {
        const double a = 2 * std::acos(-1.0) * i / n;
        pts.row(i) << std::cos(a) * (1 + 0.3 * i), std::sin(a);
      }
      for (const BSplineCurve& c :
           {BSplineCurve{kv, pts, {}},
            BSplineCurve{kv, pts, Eigen::VectorXd::LinSpaced(n, 0.5, 2.0)}}) {
        for (int d = 0; d <= p - 1; ++d) {
          const Eigen::VectorXd a = c.evaluate(0.0, d);
          const Eigen::VectorXd b = c.evaluate(1.0, d);
          EXPECT_LT((a - b).norm(), 1e-12 * std::max(1.0, a.norm()))
              << "degree " << p << ", n " << n << ", derivative " << d;
        }
      }
    }
  }
}

TEST(PeriodicCurve, EvaluationIsContinuousAcrossEveryKnot) {
  const KnotVector kv = KnotVector::periodicUniform(3, 5);
  const BSplineCurve c{kv, Eigen::MatrixXd::Random(5, 3), {}};
  for (double knot : kv.breakpoints()) {
    for (int d = 0; d <= 2; ++d) {
      const double lo = std::max(knot - 1e-9, 0.0);
      const double hi = std::min(knot + 1e-9, 1.0);
      EXPECT_LT((c.evaluate(lo, d) - c.evaluate(hi, d)).norm(), 1e-5);
    }
  }
}

using devsurf::testing::expectThrowMentioning;

TEST(BSplineCurve, EvaluationRejectsInconsistentParts) {
  const KnotVector kv = KnotVector::clampedUniform(2, 4);
  expectThrowMentioning([&] { BSplineCurve{kv, Eigen::MatrixXd::Zero(3, 2), {}}.evaluate(0.5); },
                "expected 4 control points");
  expectThrowMentioning(
      [&] { BSplineCurve{kv, Eigen::MatrixXd::Zero(4, 2), Eigen::VectorXd::Ones(3)}.evaluate(0.5); },
      "weights must be empty or hold one value per control point");
  expectThrowMentioning(
      [&] {
        BSplineCurve{kv, Eigen::MatrixXd::Zero(4, 2), -Eigen::VectorXd::Ones(4)}.evaluate(0.5);
      },
      "weights must be positive");
  expectThrowMentioning([&] { BSplineCurve{kv, Eigen::MatrixXd::Zero(4, 2), {}}.evaluate(0.5, -1); },
                "derivative must be >= 0");
  expectThrowMentioning([] { BSplineCurve{}.evaluate(0.0); }, "knot vector is empty");
  expectThrowMentioning(
      [&] {
        BSplineCurve{kv, Eigen::MatrixXd::Zero(4, 2), Eigen::VectorXd::Zero(4)}.validate();
      },
      "weights must be finite and positive");
}

}  // namespace
}  // namespace devsurf::spline
