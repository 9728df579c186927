#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/Basis.h"
#include "devsurf/spline/BasisTable.h"
#include "devsurf/spline/KnotVector.h"

namespace devsurf::spline {
namespace {

std::vector<KnotVector> sampleKnotVectors() {
  return {
      KnotVector::clampedUniform(3, 8),
      KnotVector::clampedUniform(1, 2),
      KnotVector::clamped(3, {-2, -2, -2, -2, -1.3, 0.1, 0.1, 0.7, 2.5, 2.5, 2.5, 2.5}, 8),
      KnotVector::periodicUniform(3, 7),
      KnotVector::periodicUniform(2, 3),  // small n: every control point is used in each span
      KnotVector::periodicUniform(4, 5),
  };
}

std::vector<double> denseParams(const KnotVector& kv) {
  std::vector<double> params = kv.uniformSamples(101);
  for (double u : kv.knots()) {
    if (u >= kv.domainBegin() && u <= kv.domainEnd()) params.push_back(u);
  }
  return params;
}

TEST(BSplineBasis, PartitionOfUnityHoldsOnEveryParameter) {
  for (const KnotVector& kv : sampleKnotVectors()) {
    const std::vector<double> params = denseParams(kv);
    const EvaluationMatrix n0 = evaluationMatrix(kv, params, 0);
    ASSERT_EQ(n0.rows(), static_cast<Eigen::Index>(params.size()));
    ASSERT_EQ(n0.cols(), kv.numControlPoints());
    const Eigen::VectorXd sums = n0 * Eigen::VectorXd::Ones(kv.numControlPoints());
    for (Eigen::Index k = 0; k < sums.size(); ++k) EXPECT_NEAR(sums(k), 1.0, 1e-14);
    for (int k = 0; k < n0.outerSize(); ++k) {
      for (EvaluationMatrix::InnerIterator it(n0, k); it; ++it) EXPECT_GE(it.value(), -1e-15);
    }
  }
}

TEST(BSplineBasis, DerivativesOfThePartitionOfUnitySumToZero) {
  for (const KnotVector& kv : sampleKnotVectors()) {
    const std::vector<double> params = denseParams(kv);
    for (int d = 1; d <= kv.degree() + 1; ++d) {
      const EvaluationMatrix nd = evaluationMatrix(kv, params, d);
      const Eigen::VectorXd sums = nd * Eigen::VectorXd::Ones(kv.numControlPoints());
      const double scale = std::max(1.0, Eigen::MatrixXd(nd).cwiseAbs().maxCoeff());
      for (Eigen::Index k = 0; k < sums.size(); ++k) EXPECT_NEAR(sums(k), 0.0, 1e-12 * scale);
    }
  }
}

TEST(BSplineBasis, DerivativesBeyondTheDegreeAreZero) {
  const KnotVector kv = KnotVector::clampedUniform(2, 5);
  const BasisValues b = basisFunctions(kv, 0.4, 4);
  ASSERT_EQ(b.values.rows(), 5);
  ASSERT_EQ(b.values.cols(), 3);
  EXPECT_EQ(b.values.bottomRows(2).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(b.values.row(2).cwiseAbs().maxCoeff(), 0.0);
}

TEST(BSplineBasis, BasisFunctionsMatchTheNurbsBookExample) {
  // The NURBS Book Ex2.3: U = {0,0,0,1,2,3,4,4,5,5,5}, p = 2, u = 5/2.
  const KnotVector kv = KnotVector::clamped(2, {0, 0, 0, 1, 2, 3, 4, 4, 5, 5, 5}, 8);
  const BasisValues b = basisFunctions(kv, 2.5, 2);
  EXPECT_EQ(b.span, 4);
  EXPECT_EQ(b.controlIndex, (std::vector<int>{2, 3, 4}));
  EXPECT_NEAR(b.values(0, 0), 1.0 / 8, 1e-15);
  EXPECT_NEAR(b.values(0, 1), 6.0 / 8, 1e-15);
  EXPECT_NEAR(b.values(0, 2), 1.0 / 8, 1e-15);
  EXPECT_NEAR(b.values(1, 0), -0.5, 1e-15);
  EXPECT_NEAR(b.values(1, 1), 0.0, 1e-15);
  EXPECT_NEAR(b.values(1, 2), 0.5, 1e-15);
  EXPECT_NEAR(b.values(2, 0), 1.0, 1e-15);
  EXPECT_NEAR(b.values(2, 1), -2.0, 1e-15);
  EXPECT_NEAR(b.values(2, 2), 1.0, 1e-15);
}

TEST(BSplineBasis, PeriodicControlIndicesWrapAround) {
  const KnotVector kv = KnotVector::periodicUniform(3, 5);
  const BasisValues b = basisFunctions(kv, 0.95, 0);
  EXPECT_EQ(b.span, 7);
  EXPECT_EQ(b.controlIndex, (std::vector<int>{4, 0, 1, 2}));
}

TEST(BSplineBasis, EvaluationMatrixDerivativeRowsMatchCentralDifferences) {
  const double h = 1e-6;
  for (const KnotVector& kv : sampleKnotVectors()) {
    const std::vector<double> params = kv.spanSamples(7);  // never on a knot
    std::vector<double> plus;
    std::vector<double> minus;
    for (double u : params) {
      plus.push_back(u + h);
      minus.push_back(u - h);
    }
    for (int d = 1; d <= 2; ++d) {
      const Eigen::MatrixXd exact = Eigen::MatrixXd(evaluationMatrix(kv, params, d));
      const Eigen::MatrixXd fd = (Eigen::MatrixXd(evaluationMatrix(kv, plus, d - 1)) -
                                  Eigen::MatrixXd(evaluationMatrix(kv, minus, d - 1))) /
                                 (2 * h);
      const double scale = std::max(1.0, exact.cwiseAbs().maxCoeff());
      EXPECT_LT((exact - fd).cwiseAbs().maxCoeff(), 1e-6 * scale)
          << "degree " << kv.degree() << ", derivative " << d;
    }
  }
}

TEST(BSplineBasis, EvaluationMatrixTimesControlPointsIsTheCurve) {
  const KnotVector kv = KnotVector::periodicUniform(3, 6);
  BSplineCurve curve{kv, Eigen::MatrixXd::Random(6, 3), {}};
  const std::vector<double> params = kv.uniformSamples(37);
  for (int d = 0; d <= 4; ++d) {
    const Eigen::MatrixXd viaMatrix = evaluationMatrix(kv, params, d) * curve.points;
    const Eigen::MatrixXd direct = curve.evaluate(params, d);
    EXPECT_LT((viaMatrix - direct).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(BSplineBasis, EvaluationMatrixSumsSlotsSharingAControlPoint) {
  // Periodic, degree 2 with only 3 control points: each row equals the unwrapped basis values
  // folded onto the columns slot mod n.
  const KnotVector kv = KnotVector::periodicUniform(2, 3);
  const std::vector<double> params = kv.uniformSamples(11);
  const Eigen::MatrixXd m = Eigen::MatrixXd(evaluationMatrix(kv, params, 0));
  for (size_t k = 0; k < params.size(); ++k) {
    const BasisValues b = basisFunctions(kv, params[k], 0);
    Eigen::VectorXd folded = Eigen::VectorXd::Zero(3);
    for (int j = 0; j <= 2; ++j) folded(b.controlIndex[j]) += b.values(0, j);
    EXPECT_LT((m.row(static_cast<Eigen::Index>(k)).transpose() - folded).cwiseAbs().maxCoeff(),
              1e-15);
  }
}

TEST(BSplineBasis, BasisFunctionsIntoCallerStorageAgreeWithBasisFunctions) {
  std::vector<KnotVector> kvs = sampleKnotVectors();
  kvs.push_back(KnotVector::clampedUniform(17, 20));  // beyond the stack capacity: the heap path
  for (const KnotVector& kv : kvs) {
    const int p = kv.degree();
    for (int derivatives : {0, 1, 2, p + 1}) {
      Eigen::MatrixXd values(derivatives + 1, p + 1);
      for (double u : denseParams(kv)) {
        const BasisValues reference = basisFunctions(kv, u, derivatives);
        const int span = basisFunctionsInto(kv, u, derivatives, values);
        ASSERT_EQ(span, reference.span) << "p = " << p << ", u = " << u;
        EXPECT_LE((values - reference.values).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + reference.values.cwiseAbs().maxCoeff()))
            << "p = " << p << ", u = " << u << ", derivatives = " << derivatives;
        for (int j = 0; j <= p; ++j) EXPECT_EQ(kv.controlIndex(span - p + j), reference.controlIndex[j]);
      }
    }
    // Partition of unity on the heap path too (no reference needed).
    Eigen::MatrixXd values(1, p + 1);
    basisFunctionsInto(kv, 0.37 * kv.domainBegin() + 0.63 * kv.domainEnd(), 0, values);
    EXPECT_NEAR(values.sum(), 1.0, 1e-12) << "p = " << p;
  }
}

TEST(BSplineBasis, BasisFunctionsIntoRejectsWronglySizedStorage) {
  const KnotVector kv = KnotVector::clampedUniform(3, 8);
  Eigen::MatrixXd values(2, 3);  // should be 2 x 4 for one derivative of a cubic
  EXPECT_THROW(basisFunctionsInto(kv, 0.5, 1, values), std::invalid_argument);
  EXPECT_THROW(basisFunctionsInto(kv, 0.5, -1, values), std::invalid_argument);
}

TEST(BasisTable, EvaluatesCurvesAtItsParametersAsTheCurvesDo) {
  for (const KnotVector& kv : sampleKnotVectors()) {
    Eigen::MatrixXd points(kv.numControlPoints(), 3);
    for (Eigen::Index i = 0; i < points.rows(); ++i) points.row(i) << std::cos(1.3 * i), std::sin(0.7 * i), 0.1 * i * i;
    const BSplineCurve curve{kv, points, {}};
    const std::vector<double> params = denseParams(kv);
    const int upTo = kv.degree() + 1;  // one beyond the degree: zero
    const BasisTable table(kv, params, upTo);
    ASSERT_EQ(table.size(), static_cast<int>(params.size()));
    EXPECT_TRUE(table.fits(curve));
    Eigen::MatrixXd tabled(3, upTo + 1), direct(3, upTo + 1);
    for (int k = 0; k < table.size(); ++k) {
      table.evaluate(k, points, upTo, tabled);
      curve.derivatives(params[static_cast<std::size_t>(k)], upTo, direct);
      EXPECT_LE((tabled - direct).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + direct.cwiseAbs().maxCoeff()))
          << "degree " << kv.degree() << ", u = " << params[static_cast<std::size_t>(k)];
    }
    BSplineCurve rational = curve;
    rational.weights = Eigen::VectorXd::Ones(kv.numControlPoints());
    EXPECT_FALSE(table.fits(rational));
  }
  EXPECT_THROW(BasisTable(KnotVector::clampedUniform(3, 8), {0.5}, -1), std::invalid_argument);
}

TEST(BSplineBasis, RejectsNegativeDerivativeOrders) {
  const KnotVector kv = KnotVector::clampedUniform(2, 4);
  EXPECT_THROW(basisFunctions(kv, 0.5, -1), std::invalid_argument);
  EXPECT_THROW(evaluationMatrix(kv, {0.5}, -1), std::invalid_argument);
}

// ---- de Boor points ------------------------------------------------------------------------

Eigen::MatrixXd deBoorPoints(const BSplineCurve& c, double u, int level) {
  return deBoorPointMatrix(c.knots, u, level) * c.points;
}

BSplineCurve twistedCubic() {
  // Samples of a non-planar curve as control points on non-uniform knots.
  const KnotVector kv =
      KnotVector::clamped(3, {0, 0, 0, 0, 0.15, 0.4, 0.4, 0.8, 1, 1, 1, 1}, 8);
  Eigen::MatrixXd pts(8, 3);
  for (int i = 0; i < 8; ++i) {
    const double s = i / 7.0;
    pts.row(i) << s, s * s + 0.1 * std::sin(5 * s), s * s * s - 0.3 * std::cos(4 * s);
  }
  return BSplineCurve{kv, pts, {}};
}

TEST(DeBoorPoints, LevelZeroIsTheCurvePoint) {
  const BSplineCurve c = twistedCubic();
  for (double u : c.knots.uniformSamples(41)) {
    const Eigen::MatrixXd d = deBoorPoints(c, u, 0);
    ASSERT_EQ(d.rows(), 1);
    EXPECT_LT((d.row(0).transpose() - c.evaluate(u)).norm(), 1e-14);
  }
}

TEST(DeBoorPoints, LevelDegreeIsTheSpanControlPoints) {
  const BSplineCurve c = twistedCubic();
  const double u = 0.5;
  const int s = c.knots.spanIndex(u);
  const Eigen::MatrixXd d = deBoorPoints(c, u, 3);
  EXPECT_EQ((d - c.points.middleRows(s - 3, 4)).cwiseAbs().maxCoeff(), 0.0);
}

TEST(DeBoorPoints, LevelOnePointsSpanTheTangentLine) {
  const BSplineCurve c = twistedCubic();
  const std::vector<double>& t = c.knots.knots();
  std::vector<double> params = c.knots.uniformSamples(41);
  params.push_back(0.4);  // on the double knot
  for (double u : params) {
    const Eigen::MatrixXd d = deBoorPoints(c, u, 1);
    ASSERT_EQ(d.rows(), 2);
    const Eigen::Vector3d d0 = d.row(0).transpose();
    const Eigen::Vector3d d1 = d.row(1).transpose();
    const Eigen::Vector3d point = c.evaluate(u);
    const Eigen::Vector3d tangent = c.evaluate(u, 1);
    // c(u) lies on the segment: c = (1 − α) d0 + α d1 with α = (u − t_s)/(t_{s+1} − t_s).
    const int s = c.knots.spanIndex(u);
    const double alpha = (u - t[s]) / (t[s + 1] - t[s]);
    EXPECT_LT((point - ((1 - alpha) * d0 + alpha * d1)).norm(), 1e-14);
    // c'(u) = p (d1 − d0) / (t_{s+1} − t_s), in particular parallel to d1 − d0.
    EXPECT_LT((tangent - 3 * (d1 - d0) / (t[s + 1] - t[s])).norm(), 1e-12 * tangent.norm());
    EXPECT_LT((d1 - d0).normalized().cross(tangent.normalized()).norm(), 1e-12);
  }
}

TEST(DeBoorPoints, LevelTwoPointsSpanTheOsculatingPlane) {
  const BSplineCurve c = twistedCubic();
  for (double u : c.knots.spanSamples(5)) {
    const Eigen::MatrixXd d = deBoorPoints(c, u, 2);
    ASSERT_EQ(d.rows(), 3);
    const Eigen::Vector3d d0 = d.row(0).transpose();
    const Eigen::Vector3d d1 = d.row(1).transpose();
    const Eigen::Vector3d d2 = d.row(2).transpose();
    const Eigen::Vector3d normal = (d1 - d0).cross(d2 - d0).normalized();
    const Eigen::Vector3d c1 = c.evaluate(u, 1);
    const Eigen::Vector3d c2 = c.evaluate(u, 2);
    ASSERT_GT(c1.cross(c2).norm(), 1e-6);  // the osculating plane is well defined here
    EXPECT_LT(std::abs(normal.dot(c.evaluate(u) - d0)), 1e-13);
    EXPECT_LT(std::abs(normal.dot(c1)), 1e-12 * c1.norm());
    EXPECT_LT(std::abs(normal.dot(c2)), 1e-12 * c2.norm());
    EXPECT_GT(std::abs(normal.dot(c.evaluate(u, 3))), 1e-6);  // non-planar: torsion left
  }
}

TEST(DeBoorPoints, RowsAreAffineCombinationsWithWrappedColumns) {
  const KnotVector kv = KnotVector::periodicUniform(3, 4);
  for (double u : {0.0, 0.1, 0.7, 0.99, 1.0}) {
    for (int level = 0; level <= 3; ++level) {
      const EvaluationMatrix d = deBoorPointMatrix(kv, u, level);
      ASSERT_EQ(d.rows(), level + 1);
      ASSERT_EQ(d.cols(), 4);
      const Eigen::VectorXd sums = d * Eigen::VectorXd::Ones(4);
      for (int r = 0; r <= level; ++r) EXPECT_NEAR(sums(r), 1.0, 1e-14);
    }
  }
  EXPECT_THROW(deBoorPointMatrix(kv, 0.5, 4), std::invalid_argument);
  EXPECT_THROW(deBoorPointMatrix(kv, 0.5, -1), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::spline
