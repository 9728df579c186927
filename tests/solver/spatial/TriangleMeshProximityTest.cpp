// spatial::TriangleMeshProximity (CGAL AABB tree) against a brute-force closest-point search.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include "devsurf/spatial/TriangleMeshProximity.h"

namespace devsurf::spatial {
namespace {

/// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection §5.1.5).
Eigen::Vector3d closestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                  const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

/// A bumpy n×n grid over [0, 1]², two triangles per cell, plus a few free-floating triangles.
void bumpyMesh(Eigen::MatrixX3d& V, Eigen::MatrixX3i& T) {
  const int n = 9;
  V.resize(n * n + 6, 3);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double u = double(i) / (n - 1), v = double(j) / (n - 1);
      V.row(j * n + i) << u, v, 0.2 * std::sin(5.0 * u) * std::cos(4.0 * v);
    }
  V.row(n * n + 0) << 0.2, 0.3, 0.6;
  V.row(n * n + 1) << 0.7, 0.4, 0.5;
  V.row(n * n + 2) << 0.4, 0.9, 0.7;
  V.row(n * n + 3) << 1.2, 1.1, -0.3;
  V.row(n * n + 4) << 1.5, 0.2, -0.1;
  V.row(n * n + 5) << 1.3, 0.6, 0.4;
  T.resize(2 * (n - 1) * (n - 1) + 2, 3);
  int t = 0;
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i;
      T.row(t++) << a, a + 1, a + n + 1;
      T.row(t++) << a, a + n + 1, a + n;
    }
  T.row(t++) << n * n, n * n + 1, n * n + 2;
  T.row(t++) << n * n + 3, n * n + 4, n * n + 5;
}

TEST(TriangleMeshProximity, AgreesWithBruteForceOnRandomQueries) {
  Eigen::MatrixX3d V;
  Eigen::MatrixX3i T;
  bumpyMesh(V, T);
  const TriangleMeshProximity proximity(V, T);
  EXPECT_EQ(proximity.triangleCount(), T.rows());
  std::mt19937 rng(1301);
  std::uniform_real_distribution<double> uni(-0.5, 2.0);
  for (int q = 0; q < 400; ++q) {
    const Eigen::Vector3d p(uni(rng), uni(rng), uni(rng) - 0.75);
    double best = std::numeric_limits<double>::infinity();
    Eigen::Vector3d bestPoint = Eigen::Vector3d::Zero();
    for (int t = 0; t < T.rows(); ++t) {
      const Eigen::Vector3d c = closestOnTriangle(p, V.row(T(t, 0)), V.row(T(t, 1)), V.row(T(t, 2)));
      if ((c - p).norm() < best) {
        best = (c - p).norm();
        bestPoint = c;
      }
    }
    const ClosestPoint found = proximity.closest(p);
    ASSERT_GE(found.triangle, 0);
    ASSERT_LT(found.triangle, T.rows());
    EXPECT_NEAR((found.point - p).norm(), best, 1e-12) << "query " << q;
    EXPECT_LT((found.point - bestPoint).norm(), 1e-9) << "query " << q;
    // The reported triangle holds the point and its normal is that triangle's.
    const int t = found.triangle;
    const Eigen::Vector3d a = V.row(T(t, 0)), b = V.row(T(t, 1)), c = V.row(T(t, 2));
    EXPECT_LT((closestOnTriangle(found.point, a, b, c) - found.point).norm(), 1e-12);
    EXPECT_LT((found.normal - (b - a).cross(c - a).normalized()).norm(), 1e-15);
  }
}

TEST(TriangleMeshProximity, ProjectsOntoFaceEdgeAndCornerOfATriangle) {
  Eigen::MatrixX3d V(3, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  Eigen::MatrixX3i T(1, 3);
  T << 0, 1, 2;
  const TriangleMeshProximity proximity(V, T);
  ClosestPoint c = proximity.closest({0.25, 0.25, 2.0});
  EXPECT_EQ(c.point, Eigen::Vector3d(0.25, 0.25, 0.0));
  EXPECT_EQ(c.triangle, 0);
  EXPECT_EQ(c.normal, Eigen::Vector3d(0, 0, 1));
  c = proximity.closest({2.0, 2.0, 0.0});
  EXPECT_LT((c.point - Eigen::Vector3d(0.5, 0.5, 0.0)).norm(), 1e-15);
  c = proximity.closest({-1.0, -2.0, -1.0});
  EXPECT_LT(c.point.norm(), 1e-15);
  // A clockwise triangle faces the other way.
  T << 0, 2, 1;
  EXPECT_EQ(TriangleMeshProximity(V, T).closest({0.1, 0.1, 1.0}).normal, Eigen::Vector3d(0, 0, -1));
}

TEST(TriangleMeshProximity, RejectsBadIndicesAndDegenerateTriangles) {
  Eigen::MatrixX3d V(4, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0;
  Eigen::MatrixX3i T(2, 3);
  const auto expectThrowNaming = [&V](const Eigen::MatrixX3i& triangles, const char* what) {
    try {
      TriangleMeshProximity(V, triangles);
      ADD_FAILURE() << "no exception for " << what;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  T << 0, 1, 2, 0, 1, 4;
  expectThrowNaming(T, "triangle 1 has vertex index 4 out of range");
  T << 0, 1, 2, -1, 1, 2;
  expectThrowNaming(T, "triangle 1 has vertex index -1");
  T << 0, 1, 1, 0, 1, 2;
  expectThrowNaming(T, "triangle 0 repeats a vertex");
  T << 0, 1, 2, 0, 1, 3;  // collinear
  expectThrowNaming(T, "triangle 1 is degenerate");
  expectThrowNaming(Eigen::MatrixX3i(0, 3), "no triangles");
  T << 0, 1, 2, 0, 1, 2;
  V(3, 2) = std::numeric_limits<double>::quiet_NaN();
  expectThrowNaming(T, "not finite");
}

TEST(TriangleMeshProximity, StaysUsableAfterAMove) {
  Eigen::MatrixX3d V(3, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  Eigen::MatrixX3i T(1, 3);
  T << 0, 1, 2;
  TriangleMeshProximity first(V, T);
  const TriangleMeshProximity second(std::move(first));
  EXPECT_EQ(second.closest({0.2, 0.2, -3.0}).point, Eigen::Vector3d(0.2, 0.2, 0.0));
}

}  // namespace
}  // namespace devsurf::spatial
