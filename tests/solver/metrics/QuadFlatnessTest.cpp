// quadFlatness: Tang et al. 2016 Fig. 17's δ (distance of the diagonals over the mean of the two
// shortest edges).

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "devsurf/metrics/QuadFlatness.h"

namespace devsurf::metrics {
namespace {

TEST(QuadFlatness, IsZeroForAPlanarQuad) {
  EXPECT_EQ(quadFlatness({0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}, 1e-12), 0.0);
}

TEST(QuadFlatness, IsTheDiagonalDistanceOverTheMeanOfTheTwoShortestEdges) {
  // Unit square with one corner lifted by h: the diagonals (0,0,0)–(1,1,h) and (1,0,0)–(0,1,0)
  // are h/√(4 + 2h²) apart (their common normal is (−h, −h, 2)); for the edges 1, 1, √(1+h²),
  // √(1+h²) the two shortest are 1 and 1.
  const double h = 0.1;
  const Eigen::Vector3d p0(0, 0, 0), p1(1, 0, 0), p2(1, 1, h), p3(0, 1, 0);
  const Eigen::Vector3d d1 = p2 - p0, d2 = p3 - p1, c = d1.cross(d2);
  const double distance = std::abs((p1 - p0).dot(c)) / c.norm();
  EXPECT_NEAR(quadFlatness(p0, p1, p2, p3, 1e-12), distance / 1.0, 1e-15);
  EXPECT_NEAR(distance, h / std::sqrt(4.0 + 2.0 * h * h), 1e-15);
}

TEST(QuadFlatness, IsZeroForAQuadWithADegenerateSide) {
  EXPECT_EQ(quadFlatness({0, 0, 0}, {1, 0, 0}, {0, 1, 1}, {0, 0, 0}, 1e-12), 0.0);
}

TEST(QuadFlatness, IsZeroForFourCornersOfAFlatPolygonWhoseDiagonalsAreParallel) {
  // Four consecutive corners of a flat sheet's face that runs around a hole through a bridge:
  // the diagonals (100,0)→(70,40) and (85,40)→(70,60) are parallel, 12 apart.
  EXPECT_EQ(quadFlatness({100, 0, 0}, {85, 40, 0}, {70, 40, 0}, {70, 60, 0}, 1e-12), 0.0);
}

TEST(QuadFlatness, IsZeroForSmallQuadsWithParallelDiagonalsFarFromTheOrigin) {
  // Corners ~1000 from the origin, diagonals ~1e-3 long: their differences carry rounding errors
  // ~1e-13, which turn an exact cross product of zero into a tiny one in a random direction.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 500; ++trial) {
    const Eigen::Vector3d origin(1000.0 + u(rng), -1000.0 + u(rng), 1000.0 + u(rng));
    const Eigen::Vector3d e1 = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    const Eigen::Vector3d e2 = e1.cross(Eigen::Vector3d(u(rng), u(rng), u(rng))).normalized();
    const double h = 1e-3;
    const Eigen::Vector3d v = h * (u(rng) * e1 + u(rng) * e2);
    const Eigen::Vector3d p0 = origin + h * (u(rng) * e1 + u(rng) * e2), p1 = origin + h * (u(rng) * e1 + u(rng) * e2);
    const Eigen::Vector3d p2 = p0 + (1.0 + 0.5 * u(rng)) * v, p3 = p1 + (1.0 + 0.5 * u(rng)) * v;
    EXPECT_LT(quadFlatness(p0, p1, p2, p3, 1e-15), 1e-6) << "trial " << trial;
  }
}

TEST(QuadFlatness, IsZeroUpToRoundingForRandomCoplanarCornersAndTheDiagonalDistanceForALiftedOne) {
  std::mt19937 rng(20261205);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto randomVector = [&rng, &u]() { return Eigen::Vector3d(u(rng), u(rng), u(rng)); };
  for (int trial = 0; trial < 500; ++trial) {
    const Eigen::Vector3d origin = 10.0 * randomVector();
    const Eigen::Vector3d e1 = randomVector().normalized();
    const Eigen::Vector3d e2 = e1.cross(randomVector()).normalized();
    const auto inPlane = [&origin, &e1, &e2](double x, double y) { return Eigen::Vector3d(origin + x * e1 + y * e2); };
    Eigen::Vector3d p[4];
    if (trial % 2 == 0) {
      for (Eigen::Vector3d& q : p) q = inPlane(u(rng), u(rng));
    } else {  // parallel diagonals: p2 − p0 ∥ p3 − p1
      const Eigen::Vector3d v = inPlane(u(rng), u(rng)) - origin;
      p[0] = inPlane(u(rng), u(rng));
      p[1] = inPlane(u(rng), u(rng));
      p[2] = p[0] + (0.5 + std::abs(u(rng))) * v;
      p[3] = p[1] + (0.5 + std::abs(u(rng))) * v;
    }
    EXPECT_LT(quadFlatness(p[0], p[1], p[2], p[3], 1e-12), 1e-9) << "trial " << trial;
    if (trial % 2 == 0) {  // one corner lifted off the plane: the diagonals' distance, recomputed
      const Eigen::Vector3d lifted = p[2] + 0.1 * e1.cross(e2);
      const Eigen::Vector3d d1 = lifted - p[0], d2 = p[3] - p[1], c = d1.cross(d2);
      if (c.norm() < 1e-3) continue;  // nearly parallel diagonals: their distance is ill-conditioned
      double e[4] = {(p[1] - p[0]).norm(), (lifted - p[1]).norm(), (p[3] - lifted).norm(), (p[0] - p[3]).norm()};
      std::sort(e, e + 4);
      EXPECT_NEAR(quadFlatness(p[0], p[1], lifted, p[3], 1e-12),
                  std::abs((p[1] - p[0]).dot(c)) / c.norm() / (0.5 * (e[0] + e[1])), 1e-9)
          << "trial " << trial;
    }
  }
}

}  // namespace
}  // namespace devsurf::metrics
