// Strips side by side with paired boundaries (000_… §4.2 "Approximation with composite
// developables", Fig. 10d; issue 15). Gaps are measured on dense samples of the curves, distances
// to the points through CGAL (reference::surfaceDistance), independently of the solver's feet.

#include <gtest/gtest.h>

#include "support/StripCovers.h"

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "devsurf/models/strip/StripCover.h"
#include "devsurf/models/strip/StripFromRegion.h"
#include "devsurf/reference/SurfaceDistance.h"

namespace devsurf::models::strip {
namespace {

using devsurf::testing::distanceToStrips;
using devsurf::testing::flatStrip;

void reverseCurves(StripDesign& s) {
  s.a.points = s.a.points.colwise().reverse().eval();
  s.b.points = s.b.points.colwise().reverse().eval();
}

/// Points on z = f(x, y) over [−1, 1]² with noise σ along z.
template <class Height>
Eigen::MatrixX3d heightField(int count, unsigned seed, double sigma, const Height& f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, sigma);
  Eigen::MatrixX3d p(count, 3);
  for (int j = 0; j < count; ++j) {
    const double x = uniform(rng), y = uniform(rng);
    p.row(j) << x, y, f(x, y) + (sigma > 0.0 ? noise(rng) : 0.0);
  }
  return p;
}


TEST(StripCover, NeighbouringBoundariesArePairedWhicheverWayTheStripsRun) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 100; ++trial) {
    // Three strips side by side across y, each turned at random: a and b exchanged, u reversed.
    std::vector<StripDesign> strips = {flatStrip(0.0, 0.3), flatStrip(0.3, 0.6), flatStrip(0.6, 0.9)};
    std::vector<bool> swapped, reversed;
    for (StripDesign& s : strips) {
      swapped.push_back(rng() % 2);
      reversed.push_back(rng() % 2);
      if (swapped.back()) std::swap(s.a, s.b);
      if (reversed.back()) reverseCurves(s);
    }
    const std::vector<BoundaryPairing> pairings = proposeBoundaryPairings(strips);
    ASSERT_EQ(pairings.size(), 2u) << "trial " << trial;
    for (const BoundaryPairing& p : pairings) {
      EXPECT_EQ(std::abs(p.first - p.second), 1);
      EXPECT_NEAR(p.distance, 0.0, 1e-9);
      // Strip i's b (before turning) meets strip i+1's a.
      const int lo = std::min(p.first, p.second), hi = std::max(p.first, p.second);
      const Curve loCurve = swapped[static_cast<std::size_t>(lo)] ? Curve::A : Curve::B;
      const Curve hiCurve = swapped[static_cast<std::size_t>(hi)] ? Curve::B : Curve::A;
      EXPECT_EQ(p.first == lo ? p.firstCurve : p.secondCurve, loCurve);
      EXPECT_EQ(p.first == hi ? p.firstCurve : p.secondCurve, hiCurve);
      EXPECT_EQ(p.reversed, reversed[static_cast<std::size_t>(lo)] != reversed[static_cast<std::size_t>(hi)]);
    }
  }
  // Strips far apart are not paired.
  EXPECT_TRUE(proposeBoundaryPairings({flatStrip(0.0, 0.3), flatStrip(2.0, 2.3)}).empty());
}

TEST(StripCover, PairingPullsTwoOffsetStripsOntoOneSharedBoundary) {
  // Two flat strips with a gap of 0.05 between b of the first and a of the second, and the
  // second shorter: the sweeps close the gap and bring the ends together.
  StripDesign first = flatStrip(0.0, 0.3), second = flatStrip(0.35, 0.65);
  second.a.points.col(0) = 0.1 + 0.8 * second.a.points.col(0).array();
  second.b.points.col(0) = 0.1 + 0.8 * second.b.points.col(0).array();
  const std::vector<BoundaryPairing> pairings = proposeBoundaryPairings({first, second});
  ASSERT_EQ(pairings.size(), 1u);
  EXPECT_GT(pairingGap({first, second}, pairings).first, 0.1);
  StripPairingOptions options;
  options.rounds = 4;
  const StripPairingResult result = pairStripBoundaries({first, second}, pairings, options);
  ASSERT_EQ(result.rounds.size(), 4u);
  const auto [gapMax, gapMean] = pairingGap(result.strips, pairings);
  EXPECT_LT(gapMax, 1e-3);
  EXPECT_LT(gapMean, 1e-4);
  EXPECT_LT(result.rounds.back().warpMaxDeg, 1e-3);
  for (const StripDesign& s : result.strips) EXPECT_TRUE(s.boundaryTargets.empty());
}

TEST(StripCover, ACylinderRegionCoveredByThreeStripsKeepsTheFitOfEachAndClosesTheGaps) {
  // z = 0.6·√(1 − x²/1.44)… a cylinder of radius 1.2 about the y axis, σ = 0.1 % of its size.
  const double sigma = 1e-3 * 2.0 * std::sqrt(3.0);
  const Eigen::MatrixX3d points = heightField(6000, 3, sigma, [](double x, double) {
    return std::sqrt(1.44 - x * x);
  });
  RegionCoverOptions options;
  options.strips = 3;
  const RegionCover cover = coverRegion(points, Eigen::MatrixX3d(0, 3), options);
  ASSERT_EQ(cover.paired.strips.size(), 3u);
  ASSERT_EQ(cover.pairings.size(), 2u);
  // The first sweep opens the shared curves (each strip moves towards its band alone), the later
  // ones close them again.
  const double before = cover.paired.rounds.front().gapMax;
  const auto [after, mean] = pairingGap(cover.paired.strips, cover.pairings);
  // Only the region's rectangle is covered: measure over its points.
  const Eigen::MatrixX3d region = devsurf::testing::coveredPoints(points, cover.layout);
  const reference::SurfaceDistance d = distanceToStrips(region, cover.paired.strips, 3.0 * sigma);
  std::printf("cylinder, 3 strips: gap %.3g → %.3g (mean %.3g), RMS %.3g σ, max %.3g σ, coverage %.4f, warp %.3g°\n",
              before, after, mean, d.rmsDistance / sigma, d.maxDistance / sigma, d.coverage,
              cover.paired.rounds.back().warpMaxDeg);
  EXPECT_LT(after, 0.1 * before);
  EXPECT_LT(after, 2.0 * sigma);
  EXPECT_LE(d.rmsDistance, 2.0 * sigma);
  EXPECT_GE(d.coverage, 0.95);
  EXPECT_LE(cover.paired.rounds.back().warpMaxDeg, 0.05);
}

TEST(StripCover, ADoublyCurvedRegionIsCoveredCloserByFourStripsThanByOne) {
  // A sphere cap of radius 2: one developable cannot follow it; four strips side by side can
  // follow it more closely, each bending along its band.
  const Eigen::MatrixX3d points = heightField(8000, 4, 0.0, [](double x, double y) {
    return std::sqrt(4.0 - x * x - y * y);
  });
  RegionCoverOptions one, four;
  one.strips = 1;
  four.strips = 4;
  const RegionCover single = coverRegion(points, Eigen::MatrixX3d(0, 3), one);
  const RegionCover cover = coverRegion(points, Eigen::MatrixX3d(0, 3), four);
  ASSERT_EQ(cover.pairings.size(), 3u);
  const Eigen::MatrixX3d region = devsurf::testing::coveredPoints(points, cover.layout);
  const double diagonal = (region.colwise().maxCoeff() - region.colwise().minCoeff()).norm();
  const reference::SurfaceDistance d1 = distanceToStrips(region, single.paired.strips, 1e-3 * diagonal);
  const reference::SurfaceDistance d4 = distanceToStrips(region, cover.paired.strips, 1e-3 * diagonal);
  const auto [gap, mean] = pairingGap(cover.paired.strips, cover.pairings);
  std::printf("sphere cap: 1 strip RMS %.3g %%, 4 strips RMS %.3g %% max %.3g %% of the diagonal, gap %.3g %% "
              "(mean %.3g %%), warp %.3g°\n",
              100 * d1.rmsDistance / diagonal, 100 * d4.rmsDistance / diagonal, 100 * d4.maxDistance / diagonal,
              100 * gap / diagonal, 100 * mean / diagonal, cover.paired.rounds.back().warpMaxDeg);
  EXPECT_LT(d4.rmsDistance, 0.5 * d1.rmsDistance);
  EXPECT_LT(gap, 1e-3 * diagonal);
  EXPECT_LE(cover.paired.rounds.back().warpMaxDeg, 0.05);
}

TEST(StripCover, BadPairingsAndRegionsAreRefusedNamingThePart) {
  const std::vector<StripDesign> strips = {flatStrip(0.0, 0.3), flatStrip(0.3, 0.6)};
  EXPECT_THROW(pairStripBoundaries(strips, {{0, Curve::B, 2, Curve::A}}), std::invalid_argument);
  EXPECT_THROW(pairStripBoundaries(strips, {{0, Curve::B, 0, Curve::A}}), std::invalid_argument);
  EXPECT_THROW(pairStripBoundaries(strips, {{0, Curve::B, 1, Curve::A}, {1, Curve::A, 0, Curve::A}}),
               std::invalid_argument);
  EXPECT_THROW(proposeBoundaryPairings(strips, 0.0), std::invalid_argument);
  EXPECT_THROW(regionLayout(Eigen::MatrixX3d::Random(10, 3), 4), std::invalid_argument);
  EXPECT_THROW(regionLayout(Eigen::MatrixX3d::Random(100, 3), 0), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::models::strip
