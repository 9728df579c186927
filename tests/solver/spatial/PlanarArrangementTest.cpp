#include "devsurf/spatial/PlanarArrangement.h"

#include <cmath>
#include <map>
#include <random>

#include <gtest/gtest.h>

namespace devsurf::spatial {
namespace {

Eigen::MatrixX2d arrangementPoints(std::initializer_list<std::array<double, 2>> list) {
  Eigen::MatrixX2d p(static_cast<Eigen::Index>(list.size()), 2);
  Eigen::Index i = 0;
  for (const auto& xy : list) p.row(i++) << xy[0], xy[1];
  return p;
}

double totalFaceArea(const PlanarArrangement& a) {
  double sum = 0.0;
  for (const auto& f : a.faces) sum += 0.5 * loopSignedArea2(a.points, f);
  return sum;
}

/// Every segment of the result borders one face (the sheet's boundary) or two, once each way.
void expectFacesCloseUp(const PlanarArrangement& a) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& f : a.faces)
    for (std::size_t k = 0; k < f.size(); ++k) ++directed[{f[k], f[(k + 1) % f.size()]}];
  for (const auto& [edge, count] : directed) EXPECT_EQ(count, 1) << edge.first << "→" << edge.second;
  for (const auto& s : a.segments)
    EXPECT_TRUE(directed.count({s[0], s[1]}) || directed.count({s[1], s[0]})) << s[0] << "–" << s[1];
}

TEST(PlanarArrangement, ASquareWithCrossingDiagonalsHasFourTrianglesMeetingAtTheirCrossing) {
  const auto p = arrangementPoints({{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  const PlanarArrangement a = planarArrangement(p, {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 2}, {1, 3}});
  ASSERT_EQ(a.faces.size(), 4u);
  ASSERT_EQ(a.points.rows(), 5);
  EXPECT_NEAR(a.points(4, 0), 0.5, 1e-15);
  EXPECT_NEAR(a.points(4, 1), 0.5, 1e-15);
  for (const auto& f : a.faces) {
    EXPECT_EQ(f.size(), 3u);
    EXPECT_NEAR(0.5 * loopSignedArea2(a.points, f), 0.25, 1e-15);
  }
  ASSERT_EQ(a.crossings.size(), 1u);
  EXPECT_EQ(a.crossings[0], (std::array<int, 2>{4, 5}));
  EXPECT_TRUE(a.unusedSegments.empty());
  expectFacesCloseUp(a);
}

TEST(PlanarArrangement, DanglingSegmentsAndTreesHangingOffTheSheetAreLeftOut) {
  // A unit square, a crease from its middle that ends inside (two pieces, a tree), and a spur out.
  const auto p = arrangementPoints({{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5, 0.5}, {0.3, 0.5}, {2, 0}});
  const PlanarArrangement a = planarArrangement(p, {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 3}, {1, 6}});
  ASSERT_EQ(a.faces.size(), 1u);
  EXPECT_NEAR(totalFaceArea(a), 1.0, 1e-15);
  EXPECT_EQ(a.unusedSegments, (std::vector<int>{4, 5, 6}));  // 5–3 goes once 4–5 has gone
  expectFacesCloseUp(a);
}

TEST(PlanarArrangement, TJunctionsSplitTheSegmentTheyEndOn) {
  // A square with a crease from the middle of the bottom edge to the top corner: the bottom edge
  // is split at the crease's end point.
  const auto p = arrangementPoints({{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5, 0}});
  const PlanarArrangement a = planarArrangement(p, {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 2}});
  ASSERT_EQ(a.faces.size(), 2u);
  EXPECT_NEAR(totalFaceArea(a), 1.0, 1e-15);
  EXPECT_EQ(a.segments.size(), 6u);
  expectFacesCloseUp(a);
}

TEST(PlanarArrangement, OverlappingAndRepeatedSegmentsBecomeOnePiece) {
  const auto p = arrangementPoints({{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.25, 0}, {0.75, 0}});
  const PlanarArrangement a = planarArrangement(p, {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {1, 2}});
  ASSERT_EQ(a.faces.size(), 1u);
  EXPECT_EQ(a.faces[0].size(), 6u);  // the bottom edge in three pieces
  EXPECT_NEAR(totalFaceArea(a), 1.0, 1e-15);
}

TEST(PlanarArrangement, AnIslandInsideTheSheetIsCountedAndLeftOut) {
  const auto p = arrangementPoints({{0, 0}, {4, 0}, {4, 4}, {0, 4}, {1, 1}, {2, 1}, {2, 2}});
  const PlanarArrangement a = planarArrangement(p, {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 4}});
  EXPECT_EQ(a.islands, 1);
  ASSERT_EQ(a.faces.size(), 1u);
  EXPECT_NEAR(totalFaceArea(a), 16.0, 1e-12);
  EXPECT_EQ(a.unusedSegments, (std::vector<int>{4, 5, 6}));
}

TEST(PlanarArrangement, PointsCloserThanTheToleranceAreMerged) {
  const auto p = arrangementPoints({{0, 0}, {1, 0}, {1, 1}, {0, 1}, {1 + 1e-13, 1e-13}});
  const PlanarArrangement a = planarArrangement(p, {{0, 1}, {4, 2}, {2, 3}, {3, 0}});
  EXPECT_EQ(a.mergedInto[4], 1);
  ASSERT_EQ(a.faces.size(), 1u);
  EXPECT_EQ(a.faces[0].size(), 4u);
}

TEST(PlanarArrangement, RejectsIdsOutOfRangeAndNonFinitePoints) {
  const auto p = arrangementPoints({{0, 0}, {1, 0}, {1, 1}});
  EXPECT_THROW(planarArrangement(p, {{0, 3}}), std::invalid_argument);
  Eigen::MatrixX2d bad = p;
  bad(1, 0) = std::nan("");
  EXPECT_THROW(planarArrangement(bad, {{0, 1}}), std::invalid_argument);
}

// Property over seeded random crease patterns: chords between random points on the boundary of a
// 2 × 1 sheet. Euler's formula for the connected plane graph (V − E + F = 1 bounded faces), the
// faces tile the sheet (their areas sum to 2) and every segment borders a face on each side once.
TEST(PlanarArrangement, RandomChordsTileTheSheetAndSatisfyEulersFormula) {
  std::mt19937 rng(20261203);
  std::uniform_real_distribution<double> along(0.0, 6.0);
  auto boundaryPoint = [](double s) -> std::array<double, 2> {
    if (s < 2) return {s, 0};
    if (s < 3) return {2, s - 2};
    if (s < 5) return {2 - (s - 3), 1};
    return {0, 1 - (s - 5)};
  };
  for (int trial = 0; trial < 200; ++trial) {
    const int chords = 1 + trial % 12;
    std::vector<std::array<double, 2>> pts{{0, 0}, {2, 0}, {2, 1}, {0, 1}};
    std::vector<std::array<int, 2>> segments{{0, 1}, {1, 2}, {2, 3}, {3, 0}};
    for (int c = 0; c < chords; ++c) {
      pts.push_back(boundaryPoint(along(rng)));
      pts.push_back(boundaryPoint(along(rng)));
      segments.push_back({static_cast<int>(pts.size()) - 2, static_cast<int>(pts.size()) - 1});
    }
    // The sheet's sides are split where chords end on them (T-junctions) by the arrangement.
    Eigen::MatrixX2d p(static_cast<Eigen::Index>(pts.size()), 2);
    for (std::size_t i = 0; i < pts.size(); ++i) p.row(static_cast<Eigen::Index>(i)) << pts[i][0], pts[i][1];
    const PlanarArrangement a = planarArrangement(p, segments);
    EXPECT_NEAR(totalFaceArea(a), 2.0, 1e-9) << "trial " << trial;
    std::vector<bool> usedPoint(a.points.rows(), false);
    for (const auto& s : a.segments) usedPoint[s[0]] = usedPoint[s[1]] = true;
    const long vertices = std::count(usedPoint.begin(), usedPoint.end(), true);
    EXPECT_EQ(vertices - static_cast<long>(a.segments.size()) + static_cast<long>(a.faces.size()), 1) << "trial " << trial;
    expectFacesCloseUp(a);
    for (const auto& f : a.faces) EXPECT_GT(loopSignedArea2(a.points, f), 0.0);
  }
}

}  // namespace
}  // namespace devsurf::spatial
