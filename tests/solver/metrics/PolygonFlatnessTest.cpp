// polygonFlatness: a planar face's corners against their least-squares plane, over the mean of
// its two shortest edges.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include "devsurf/metrics/PolygonFlatness.h"

namespace devsurf::metrics {
namespace {

std::vector<int> loopOf(std::size_t n) {
  std::vector<int> loop(n);
  std::iota(loop.begin(), loop.end(), 0);
  return loop;
}

TEST(PolygonFlatness, IsTheCornersDistanceFromTheirPlaneOverTheMeanOfTheTwoShortestEdges) {
  // A saddle: (±1, 0, h) and (0, ±1, −h). The least-squares plane is z = 0 (spread h² across it
  // against 1/2 along x and y), every corner h from it; every edge √(2 + 4h²).
  const double h = 0.05;
  const std::vector<Eigen::Vector3d> saddle{{1, 0, h}, {0, 1, -h}, {-1, 0, h}, {0, -1, -h}};
  EXPECT_NEAR(polygonFlatness(saddle, loopOf(4), 1e-12), h / std::sqrt(2.0 + 4.0 * h * h), 1e-15);
}

TEST(PolygonFlatness, IsZeroForAFlatFaceRunningInAndOutAlongABridge) {
  // The face of a flat sheet around a hole: out along the bridge (100,0)→(85,40), round the hole,
  // back to the crease. Its corners (100,0), (85,40), (70,40), (70,60) have parallel diagonals.
  const std::vector<Eigen::Vector3d> face{{50, 0, 0}, {100, 0, 0}, {85, 40, 0}, {70, 40, 0}, {70, 60, 0}, {50, 100, 0}};
  EXPECT_EQ(polygonFlatness(face, loopOf(face.size()), 1e-12), 0.0);
}

TEST(PolygonFlatness, IsZeroForTrianglesAndForFacesWithEdgesOfNoLength) {
  const std::vector<Eigen::Vector3d> triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 1}};
  EXPECT_EQ(polygonFlatness(triangle, loopOf(3), 1e-12), 0.0);
  const std::vector<Eigen::Vector3d> pinched{{0, 0, 0}, {0, 0, 0}, {1, 0, 0}, {1, 0, 0}, {0, 1, 1}};
  EXPECT_EQ(polygonFlatness(pinched, loopOf(5), 1e-12), 0.0);
}

TEST(PolygonFlatness, IsZeroUpToRoundingForRandomFlatPolygonsAndGrowsWithACornerLiftedOffThePlane) {
  std::mt19937 rng(20261205);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto randomVector = [&rng, &u]() { return Eigen::Vector3d(u(rng), u(rng), u(rng)); };
  for (int trial = 0; trial < 300; ++trial) {
    const Eigen::Vector3d origin = 10.0 * randomVector();
    const Eigen::Vector3d e1 = randomVector().normalized();
    const Eigen::Vector3d e2 = e1.cross(randomVector()).normalized();
    const std::size_t n = 4 + static_cast<std::size_t>(trial % 9);
    std::vector<Eigen::Vector3d> corners;
    for (std::size_t k = 0; k < n; ++k) {  // a star-shaped, often non-convex loop
      const double angle = 2.0 * M_PI * (static_cast<double>(k) + 0.4 * u(rng)) / static_cast<double>(n);
      const double radius = 1.0 + 0.6 * u(rng);
      corners.push_back(origin + radius * (std::cos(angle) * e1 + std::sin(angle) * e2));
    }
    EXPECT_LT(polygonFlatness(corners, loopOf(n), 1e-12), 1e-12) << "trial " << trial;
    // One corner lifted by t along the normal. The least-squares plane has at most the squared
    // distances of the old plane (t² in all), so no corner is farther than t from it; it tilts
    // towards the lifted corner but cannot take it in.
    const double t = 0.01;
    corners[static_cast<std::size_t>(trial) % n] += t * e1.cross(e2);
    double shortest[2] = {1e300, 1e300};
    for (std::size_t k = 0; k < n; ++k) {
      const double l = (corners[(k + 1) % n] - corners[k]).norm();
      if (l < shortest[0]) {
        shortest[1] = shortest[0];
        shortest[0] = l;
      } else if (l < shortest[1]) {
        shortest[1] = l;
      }
    }
    const double flatness = polygonFlatness(corners, loopOf(n), 1e-12);
    const double scale = 0.5 * (shortest[0] + shortest[1]);
    EXPECT_GT(flatness, 1e-3 * t / scale) << "trial " << trial;
    EXPECT_LE(flatness, t / scale * (1.0 + 1e-9)) << "trial " << trial;
  }
}

}  // namespace
}  // namespace devsurf::metrics
