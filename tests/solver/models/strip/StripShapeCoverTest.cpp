// A whole closed shape covered region by region (000_… Fig. 10e): models::strip::coverShapeByRegions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <vector>

#include "devsurf/models/strip/StripShapeCover.h"
#include "support/StripCovers.h"

namespace devsurf::models::strip {
namespace {

/// Points on a closed can — the side of a cylinder of radius r and height h about z, and its two
/// discs — with their outward normals; part[j] is 0 for the side, 1 for the bottom, 2 for the top.
void closedCan(int count, double r, double h, unsigned seed, Eigen::MatrixX3d& points, Eigen::MatrixX3d& normals,
               std::vector<int>& part) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double side = 2.0 * M_PI * r * h, disc = M_PI * r * r;
  points.resize(count, 3);
  normals.resize(count, 3);
  part.assign(static_cast<std::size_t>(count), 0);
  for (int j = 0; j < count; ++j) {
    const double pick = unit(random) * (side + 2.0 * disc), angle = 2.0 * M_PI * unit(random);
    if (pick < side) {
      points.row(j) << r * std::cos(angle), r * std::sin(angle), h * (unit(random) - 0.5);
      normals.row(j) << std::cos(angle), std::sin(angle), 0.0;
    } else {
      const double rho = r * std::sqrt(unit(random));
      const bool top = pick > side + disc;
      points.row(j) << rho * std::cos(angle), rho * std::sin(angle), top ? 0.5 * h : -0.5 * h;
      normals.row(j) << 0.0, 0.0, top ? 1.0 : -1.0;
      part[static_cast<std::size_t>(j)] = top ? 2 : 1;
    }
  }
}

TEST(StripShapeCover, AClosedCanIsCoveredRegionByRegionWithEveryRegionOnOnePartAndDevelopable) {
  // A can's side is a cylinder and its ends are discs: every region of it is developable, so
  // every region is covered, by strips within the fabrication thresholds of the composite presets.
  Eigen::MatrixX3d points, normals;
  std::vector<int> part;
  closedCan(12000, 1.0, 2.0, 11, points, normals, part);
  ShapeCoverOptions options;
  options.regions = 6;
  options.region.strips = 3;
  const ShapeCover cover = coverShapeByRegions(points, normals, options);
  ASSERT_EQ(cover.label.size(), part.size());
  int covered = 0;
  std::vector<StripDesign> strips;
  for (std::size_t r = 0; r < cover.regions.size(); ++r) {
    const ShapeRegionCover& region = cover.regions[r];
    // A region lies on one part of the can: a cluster of normals does not mix a disc and the side.
    std::set<int> parts;
    for (const int j : region.points) parts.insert(part[static_cast<std::size_t>(j)]);
    EXPECT_EQ(parts.size(), 1u) << "region " << r;
    ASSERT_TRUE(region.covered) << "region " << r << ": " << region.skipped;
    ++covered;
    EXPECT_LE(region.cover.paired.rounds.back().warpMaxDeg, 0.05) << "region " << r;
    strips.insert(strips.end(), region.cover.paired.strips.begin(), region.cover.paired.strips.end());
  }
  EXPECT_GE(covered, 6);
  // Distances from every point of the can to the strips (a second computation: the strips
  // sampled as triangles, CGAL's AABB tree).
  const double diagonal = (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm();
  const reference::SurfaceDistance d = devsurf::testing::distanceToStrips(points, strips, 0.01 * diagonal);
  std::printf("closed can, %zu regions of 3 strips: RMS %.3g %% max %.3g %% of the diagonal, %.1f %% within 1 %%\n",
              cover.regions.size(), 100 * d.rmsDistance / diagonal, 100 * d.maxDistance / diagonal, 100 * d.coverage);
  EXPECT_LE(d.rmsDistance, 0.01 * diagonal);
  EXPECT_GE(d.coverage, 0.9);
}

TEST(StripShapeCover, TwoPlatesFacingOneWayAreTwoRegionsEvenWhenTheSegmentationAsksForOne) {
  // One cluster of normals in two pieces: each piece is covered on its own.
  std::mt19937 random(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Eigen::MatrixX3d points(2000, 3), normals(2000, 3);
  for (int j = 0; j < 2000; ++j) {
    points.row(j) << unit(random) + (j < 1000 ? 0.0 : 3.0), unit(random), 0.0;
    normals.row(j) << 0.0, 0.0, 1.0;
  }
  ShapeCoverOptions options;
  options.regions = 1;
  options.region.strips = 2;
  const ShapeCover cover = coverShapeByRegions(points, normals, options);
  ASSERT_EQ(cover.regions.size(), 2u);
  for (const ShapeRegionCover& region : cover.regions) {
    ASSERT_TRUE(region.covered) << region.skipped;
    EXPECT_EQ(region.points.size(), 1000u);
    for (const int j : region.points) EXPECT_EQ(j < 1000, region.points.front() < 1000);
  }
}

TEST(StripShapeCover, ARegionTooSmallForItsStripsIsReportedAndTheOthersAreCovered) {
  // A large plate and a small one far away: the small one cannot hold 6 points per band.
  std::mt19937 random(9);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Eigen::MatrixX3d points(1020, 3), normals(1020, 3);
  for (int j = 0; j < 1020; ++j) {
    points.row(j) << (j < 1000 ? unit(random) : 5.0 + 0.01 * unit(random)), unit(random), 0.0;
    normals.row(j) << 0.0, 0.0, 1.0;
  }
  ShapeCoverOptions options;
  options.regions = 1;
  options.region.strips = 4;
  const ShapeCover cover = coverShapeByRegions(points, normals, options);
  ASSERT_EQ(cover.regions.size(), 2u);
  int covered = 0;
  for (const ShapeRegionCover& region : cover.regions) {
    covered += region.covered;
    if (!region.covered) {
      EXPECT_EQ(region.points.size(), 20u);
      EXPECT_FALSE(region.skipped.empty());
    }
  }
  EXPECT_EQ(covered, 1);
  EXPECT_THROW(coverShapeByRegions(points, Eigen::MatrixX3d(3, 3), options), std::invalid_argument);
  options.regions = 0;
  EXPECT_THROW(coverShapeByRegions(points, normals, options), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::models::strip
