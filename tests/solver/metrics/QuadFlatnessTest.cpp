// quadFlatness: Tang et al. 2016 Fig. 17's δ (distance of the diagonals over the mean of the two
// shortest edges).

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

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

}  // namespace
}  // namespace devsurf::metrics
