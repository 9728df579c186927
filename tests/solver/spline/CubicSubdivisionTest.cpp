// The subdivision rule of 004_… eq. 8 against the B-spline toolkit: the refined control points
// define the same curve (surface) on the refined knots, and k rounds converge to it.
#include "devsurf/spline/CubicSubdivision.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::spline {
namespace {

Eigen::MatrixXd randomPoints(int count, int dim, std::mt19937& rng) {
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  Eigen::MatrixXd p(count, dim);
  for (int i = 0; i < count; ++i)
    for (int d = 0; d < dim; ++d) p(i, d) = coordinate(rng) + 0.7 * i * (d == 0);
  return p;
}

BSplineCurve cubic(const Eigen::MatrixXd& points) {
  return BSplineCurve{KnotVector::clampedUniform(3, static_cast<int>(points.rows())), points, {}};
}

/// The bicubic clamped uniform B-spline surface of a rows × columns net (point (r, c) at row
/// r·columns + c) at (u along a row, v across rows), by curves: each row at u, then those at v.
Eigen::Vector3d surfacePoint(const Eigen::MatrixXd& net, int rows, int columns, double u, double v) {
  Eigen::MatrixXd atU(rows, 3);
  for (int r = 0; r < rows; ++r) atU.row(r) = cubic(net.middleRows(static_cast<Eigen::Index>(r) * columns, columns)).evaluate(u).transpose();
  return cubic(atU).evaluate(v);
}

double greville(int i, int count) {
  const KnotVector knots = KnotVector::clampedUniform(3, count);
  return (knots.knots()[i + 1] + knots.knots()[i + 2] + knots.knots()[i + 3]) / 3.0;
}

TEST(CubicSubdivision, HasTheStencilsOfEquation8AtTheEndsAndLaneRiesenfeldInside) {
  const Eigen::MatrixXd a = Eigen::MatrixXd(cubicSubdivisionMatrix(9)) * 16.0;
  ASSERT_EQ(a.rows(), 15);
  ASSERT_EQ(a.cols(), 9);
  auto row = [&a](int i, std::vector<double> expected, int first) {
    for (int j = 0; j < a.cols(); ++j) {
      const double e = j >= first && j < first + static_cast<int>(expected.size()) ? expected[j - first] : 0.0;
      EXPECT_NEAR(a(i, j), e, 1e-13) << "row " << i << ", column " << j;
    }
  };
  row(0, {16}, 0);
  row(1, {8, 8}, 0);
  row(2, {12, 4}, 1);
  row(3, {3, 11, 2}, 1);
  for (int j = 2; j <= 5; ++j) {
    row(2 * j, {8, 8}, j);             // edge points
    if (j < 5) row(2 * j + 1, {2, 12, 2}, j);  // vertex points
  }
  // The other end mirrors the first.
  row(14, {16}, 8);
  row(13, {8, 8}, 7);
  row(12, {4, 12}, 6);
  row(11, {2, 11, 3}, 5);
}

TEST(CubicSubdivision, RowsSumToOneForEveryPolygonLength) {
  for (int count = 4; count <= 20; ++count) {
    const Eigen::SparseMatrix<double> a = cubicSubdivisionMatrix(count);
    ASSERT_EQ(a.rows(), 2 * count - 3);
    const Eigen::VectorXd sums = a * Eigen::VectorXd::Ones(count);
    EXPECT_LT((sums.array() - 1.0).abs().maxCoeff(), 1e-14) << count << " points";
  }
}

TEST(CubicSubdivision, TheRefinedPolygonDefinesTheSameCurveOnTheRefinedKnots) {
  std::mt19937 rng(14);
  for (int count = 4; count <= 14; ++count) {
    const Eigen::MatrixXd p = randomPoints(count, 3, rng);
    const Eigen::MatrixXd q = cubicSubdivisionMatrix(count) * p;
    const BSplineCurve before = cubic(p), after = cubic(q);
    double worst = 0.0;
    for (int s = 0; s <= 200; ++s) worst = std::max(worst, (before.evaluate(s / 200.0) - after.evaluate(s / 200.0)).norm());
    EXPECT_LT(worst, 1e-13) << count << " points";
    // And the toolkit's own knot refinement (Boehm, NURBS Book A5.4) gives the same points.
    std::vector<double> midpoints;
    for (int s = 0; s < count - 3; ++s) midpoints.push_back((s + 0.5) / (count - 3));
    EXPECT_LT((refineKnots(before, midpoints).points - q).cwiseAbs().maxCoeff(), 1e-13) << count << " points";
  }
}

TEST(CubicSubdivision, KRoundsOfAGridAreTheSameBicubicSurfaceAndConvergeToIt) {
  std::mt19937 rng(15);
  const int rows = 5, columns = 7;
  Eigen::MatrixXd net(rows * columns, 3);
  std::uniform_real_distribution<double> height(-0.5, 0.5);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < columns; ++c) net.row(r * columns + c) << c, 1.3 * r, height(rng);
  double previousGap = 0.0;
  for (int k = 0; k <= 6; ++k) {
    const Eigen::SparseMatrix<double> s = cubicGridSubdivisionMatrix(rows, columns, k);
    const int R = cubicSubdividedCount(rows, k), C = cubicSubdividedCount(columns, k);
    ASSERT_EQ(s.rows(), R * C);
    ASSERT_EQ(s.cols(), rows * columns);
    const Eigen::MatrixXd refined = s * net;
    // The same surface: refined net on refined knots = the original net on its knots.
    std::uniform_real_distribution<double> parameter(0.0, 1.0);
    for (int trial = 0; trial < 20; ++trial) {
      const double u = parameter(rng), v = parameter(rng);
      EXPECT_LT((surfacePoint(refined, R, C, u, v) - surfacePoint(net, rows, columns, u, v)).norm(), 1e-12)
          << k << " rounds at (" << u << ", " << v << ")";
    }
    // The net converges to the surface: its points lie ever closer to the surface points at
    // their Greville abscissae (control polygons of B-splines: O(h²), so ÷4 per round).
    double gap = 0.0;
    for (int r = 0; r < R; ++r)
      for (int c = 0; c < C; ++c)
        gap = std::max(gap, (refined.row(r * C + c).transpose() - surfacePoint(net, rows, columns, greville(c, C), greville(r, R))).norm());
    if (k > 0) EXPECT_LT(gap, 0.45 * previousGap) << "round " << k;
    if (k >= 3) {  // past the first rounds: O(h²), a quarter per round
      EXPECT_LT(gap, 0.3 * previousGap) << "round " << k;
      EXPECT_GT(gap, 0.2 * previousGap) << "round " << k << ": quadratic, not faster";
    }
    previousGap = gap;
  }
  EXPECT_LT(previousGap, 5e-4);  // measured 3.2e-4 after 6 rounds (0.45 before any)
}

TEST(CubicSubdivision, RefusesPolygonsTooShortForACubic) {
  EXPECT_THROW(cubicSubdivisionMatrix(3), std::invalid_argument);
  EXPECT_THROW(cubicGridSubdivisionMatrix(4, 3, 1), std::invalid_argument);
  EXPECT_THROW(cubicGridSubdivisionMatrix(4, 4, -1), std::invalid_argument);
  EXPECT_THROW(cubicSubdividedCount(5, 40), std::invalid_argument);
  EXPECT_EQ(cubicSubdividedCount(5, 2), 11);
}

}  // namespace
}  // namespace devsurf::spline
