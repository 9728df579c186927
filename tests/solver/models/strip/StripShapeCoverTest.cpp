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

TEST(StripShapeCover, TrimmingCutsAStripsBandsBackToTheirPointsAndKeepsTheSharedCurveShared) {
  // Two flat strips side by side over [0, 1] × [0, 0.6] (shared curve y = 0.3); points on
  // [0.25, 0.75] × [0.1, 0.5] only, each on the band of its strip.
  RegionCover cover;
  cover.paired.strips = {devsurf::testing::flatStrip(0.0, 0.3), devsurf::testing::flatStrip(0.3, 0.6)};
  cover.pairings.push_back({0, Curve::B, 1, Curve::A, false, 0.0});
  std::vector<Eigen::RowVector3d> rows;
  cover.layout.bands.resize(2);
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 16; ++j) {
      const double x = 0.25 + 0.5 * i / 20.0, y = 0.1 + 0.4 * j / 16.0;
      cover.layout.bands[y < 0.3 ? 0 : 1].push_back(static_cast<int>(rows.size()));
      rows.emplace_back(x, y, 0.0);
    }
  Eigen::MatrixX3d points(static_cast<Eigen::Index>(rows.size()), 3);
  for (std::size_t k = 0; k < rows.size(); ++k) points.row(static_cast<Eigen::Index>(k)) = rows[k];
  trimToRegion(cover, points);
  const StripDesign& first = cover.paired.strips[0];
  const StripDesign& second = cover.paired.strips[1];
  // Along: the points' extent and one sample (1/160) of margin.
  for (const StripDesign* s : {&first, &second}) {
    const Eigen::Vector3d start = s->a.evaluate(s->a.knots.domainBegin()), stop = s->a.evaluate(s->a.knots.domainEnd());
    EXPECT_NEAR(std::min(start.x(), stop.x()), 0.25, 1.5 / 160);
    EXPECT_NEAR(std::max(start.x(), stop.x()), 0.75, 1.5 / 160);
  }
  // Across: the outer curves at the points' extent, within a sample of margin and half a sample of
  // rounding (samples 1/16 of the strip's width 0.3 apart); never inside the points.
  EXPECT_NEAR(first.a.points(0, 1), 0.1, 1.5 * 0.3 / 16);
  EXPECT_LE(first.a.points(0, 1), 0.1);
  EXPECT_NEAR(second.b.points(0, 1), 0.5, 1.5 * 0.3 / 16);
  EXPECT_GE(second.b.points(0, 1), 0.5);
  // The shared curve is still one curve: same knots, same control points.
  EXPECT_EQ(first.b.knots.knots(), second.a.knots.knots());
  EXPECT_EQ(first.b.points, second.a.points);
  EXPECT_NEAR(first.b.points(0, 1), 0.3, 1e-12);
}

}  // namespace
}  // namespace devsurf::models::strip
