#include "devsurf/spatial/PolygonTriangulation.h"

#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace devsurf::spatial {
namespace {

double signedTriangleArea(const Eigen::MatrixX2d& p, const std::array<int, 3>& t) {
  const Eigen::Vector2d a = p.row(t[0]), b = p.row(t[1]), c = p.row(t[2]);
  return 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
}

double shoelaceArea(const Eigen::MatrixX2d& p) {
  double twice = 0.0;
  for (Eigen::Index k = 0; k < p.rows(); ++k) {
    const Eigen::Index j = (k + 1) % p.rows();
    twice += p(k, 0) * p(j, 1) - p(j, 0) * p(k, 1);
  }
  return 0.5 * twice;
}

TEST(PolygonTriangulation, AnLShapeIsCutIntoFourTrianglesThatStayInside) {
  // An L whose first corner sees only part of it: a fan from there would leave the shape.
  Eigen::MatrixX2d l(6, 2);
  l << 2, 2, 1, 2, 1, 1, 0, 1, 0, 0, 2, 0;
  EXPECT_FALSE(isConvexPolygon(l));
  const auto triangles = triangulateSimplePolygon(l);
  ASSERT_EQ(triangles.size(), 4u);
  double sum = 0.0;
  for (const auto& t : triangles) {
    EXPECT_GT(signedTriangleArea(l, t), 0.0);
    sum += signedTriangleArea(l, t);
  }
  EXPECT_NEAR(sum, 3.0, 1e-15);
}

TEST(PolygonTriangulation, ConvexityIsReadFromTheTurns) {
  Eigen::MatrixX2d square(5, 2);
  square << 0, 0, 1, 0, 2, 0, 2, 2, 0, 2;  // a straight corner is still convex
  EXPECT_TRUE(isConvexPolygon(square));
  Eigen::MatrixX2d dart(4, 2);
  dart << 0, 0, 2, 1, 0, 2, 0.5, 1;
  EXPECT_FALSE(isConvexPolygon(dart));
}

TEST(PolygonTriangulation, APlanarPolygonInSpaceKeepsItsShapeAndTurnInItsPlane) {
  Eigen::MatrixX3d tilted(4, 3);
  tilted << 0, 0, 0, 2, 0, 2, 2, 1, 2, 0, 1, 0;  // a 2√2 × 1 rectangle tilted 45° about y
  const Eigen::MatrixX2d flat = polygonInItsPlane(tilted);
  EXPECT_NEAR(shoelaceArea(flat), 2.0 * std::sqrt(2.0), 1e-12);
  for (int k = 0; k < 4; ++k)
    EXPECT_NEAR((flat.row(k) - flat.row((k + 1) % 4)).norm(), (tilted.row(k) - tilted.row((k + 1) % 4)).norm(), 1e-12);
}

TEST(PolygonTriangulation, RejectsFewerThanThreeCorners) {
  EXPECT_THROW(triangulateSimplePolygon(Eigen::MatrixX2d(2, 2)), std::invalid_argument);
}

// Property over 300 seeded random star-shaped polygons (4–40 corners, radii 0.2–1, some with
// collinear runs), either orientation: n − 2 triangles, none turning against the polygon, whose
// areas add up to the polygon's (shoelace).
TEST(PolygonTriangulation, RandomStarShapedPolygonsAreCoveredExactly) {
  std::mt19937 rng(20261205);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 300; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const int n = 4 + trial % 37;
    Eigen::MatrixX2d p(n, 2);
    for (int k = 0; k < n; ++k) {
      const double angle = 2 * M_PI * (k + 0.4 * u(rng)) / n;
      const double r = trial % 5 == 0 && k % 3 == 1 ? -1.0 : 0.2 + 0.8 * u(rng);
      p.row(k) << r * std::cos(angle), r * std::sin(angle);
    }
    // Collinear runs: some corners moved onto the chord of their neighbours.
    for (int k = 0; k < n; ++k)
      if (trial % 5 == 0 && p(k, 0) * p(k, 0) + p(k, 1) * p(k, 1) > 0.99)
        p.row(k) = 0.5 * (p.row((k + n - 1) % n) + p.row((k + 1) % n));
    if (trial % 2 == 1) p = p.colwise().reverse().eval();
    const double area = shoelaceArea(p);
    const auto triangles = triangulateSimplePolygon(p);
    ASSERT_EQ(static_cast<int>(triangles.size()), n - 2);
    double sum = 0.0;
    for (const auto& t : triangles) {
      const double a = signedTriangleArea(p, t);
      EXPECT_GE(a * (area > 0 ? 1.0 : -1.0), -1e-15);
      sum += a;
    }
    EXPECT_NEAR(sum, area, 1e-12);
  }
}

}  // namespace
}  // namespace devsurf::spatial
