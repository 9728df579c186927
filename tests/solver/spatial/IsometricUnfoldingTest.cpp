#include "devsurf/spatial/IsometricUnfolding.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

namespace devsurf::spatial {
namespace {

/// A grid of U × V points p(i, j) as quads (i, i+1) × (j, j+1), counter-clockwise seen from
/// the side dp/di × dp/dj points to.
struct Grid {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::vector<int>> quads;
};

template <class Point>
Grid grid(int U, int V, const Point& point) {
  Grid g;
  for (int i = 0; i < U; ++i)
    for (int j = 0; j < V; ++j) g.points.push_back(point(i, j));
  for (int i = 0; i + 1 < U; ++i)
    for (int j = 0; j + 1 < V; ++j) {
      const int a = i * V + j;
      g.quads.push_back({a, a + V, a + V + 1, a + 1});
    }
  return g;
}

double signedArea(const FlatLayout& layout, const std::vector<int>& poly) {
  double area = 0.0;
  for (std::size_t c = 0; c < poly.size(); ++c) {
    const Eigen::Vector2d p = layout.vertices.row(poly[c]), q = layout.vertices.row(poly[(c + 1) % poly.size()]);
    area += 0.5 * (p.x() * q.y() - q.x() * p.y());
  }
  return area;
}

TEST(IsometricUnfolding, ACylinderPatchUnrollsToARectangleOfItsChordsTimesItsHeight) {
  const double r = 0.8, angle = 2.0, h = 0.5;
  const int U = 21, V = 4;
  const Grid g = grid(U, V, [&](int i, int j) {
    const double t = angle * i / (U - 1.0);
    return Eigen::Vector3d(r * std::cos(t), r * std::sin(t), h * j / (V - 1.0));
  });
  const FlatLayout layout = unfoldPieces(g.points, g.quads, std::vector<int>(g.quads.size(), 0));
  ASSERT_EQ(layout.pieces, 1);
  ASSERT_EQ(layout.vertices.rows(), U * V);
  const double chord = 2.0 * r * std::sin(angle / (U - 1.0) / 2.0);
  const Eigen::Vector2d extent = layout.vertices.colwise().maxCoeff() - layout.vertices.colwise().minCoeff();
  EXPECT_NEAR(extent.x(), (U - 1) * chord, 1e-12);  // the longest direction along x
  EXPECT_NEAR(extent.y(), h, 1e-12);
  EXPECT_NEAR(layout.vertices.colwise().minCoeff().norm(), 0.0, 1e-12);  // starts at the origin
  double area = 0.0;
  for (const std::vector<int>& q : layout.polygons) {
    ASSERT_EQ(q.size(), 4u);
    const double a = signedArea(layout, q);
    EXPECT_GT(a, 0.0) << "the quads stay counter-clockwise";
    area += a;
  }
  EXPECT_NEAR(area, (U - 1) * chord * h, 1e-12);
  EXPECT_LT(layout.lengthErrorMax, 1e-12);
}

TEST(IsometricUnfolding, AConeKeepsEveryPointsDistanceFromTheApex) {
  // Rulings from the apex at the origin to a circle of the cone z = 0.6·ρ; points along each
  // ruling at distances 1 … 2 from the apex (the apex itself is not part of the sheet).
  const int U = 16, V = 5;
  const double slope = std::atan(0.6);
  const Grid g = grid(U, V, [&](int i, int j) {
    const double t = 1.7 * i / (U - 1.0), d = 1.0 + j / (V - 1.0);
    return Eigen::Vector3d(d * std::cos(slope) * std::cos(t), d * std::cos(slope) * std::sin(t), d * std::sin(slope));
  });
  const FlatLayout layout = unfoldPieces(g.points, g.quads, std::vector<int>(g.quads.size(), 0));
  ASSERT_EQ(layout.pieces, 1);
  // The apex's image: where the first and the last ruling of the pattern meet.
  auto flat = [&layout](int point) {
    for (Eigen::Index v = 0; v < layout.vertices.rows(); ++v)
      if (layout.pointOfVertex[static_cast<std::size_t>(v)] == point) return Eigen::Vector2d(layout.vertices.row(v));
    return Eigen::Vector2d(NAN, NAN);
  };
  const Eigen::Vector2d a0 = flat(0), a1 = flat(V - 1), b0 = flat((U - 1) * V), b1 = flat((U - 1) * V + V - 1);
  const Eigen::Vector2d da = a1 - a0, db = b1 - b0;
  const double s = ((b0 - a0).x() * db.y() - (b0 - a0).y() * db.x()) / (da.x() * db.y() - da.y() * db.x());
  const Eigen::Vector2d apex = a0 + s * da;
  for (int p = 0; p < U * V; ++p) EXPECT_NEAR((flat(p) - apex).norm(), g.points[static_cast<std::size_t>(p)].norm(), 1e-12);
  EXPECT_LT(layout.lengthErrorMax, 1e-12);
}

TEST(IsometricUnfolding, PiecesAreStackedApartAndSharedPointsCopiedIntoEach) {
  // Two unit squares sharing the edge 1–2 in 3D, at a right angle, cut into two pieces.
  const std::vector<Eigen::Vector3d> points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {1, 0, 1}, {1, 1, 1}};
  const std::vector<std::vector<int>> quads = {{0, 1, 2, 3}, {1, 4, 5, 2}};
  const FlatLayout layout = unfoldPieces(points, quads, {7, 3});
  ASSERT_EQ(layout.pieces, 2);
  ASSERT_EQ(layout.vertices.rows(), 8) << "points 1 and 2 have one copy per piece";
  // Pieces in the order of their ids: 3 (the second quad) at the bottom, 7 above it.
  double top0 = -1e9, bottom1 = 1e9;
  for (const int v : layout.polygons[1]) top0 = std::max(top0, layout.vertices(v, 1));
  for (const int v : layout.polygons[0]) bottom1 = std::min(bottom1, layout.vertices(v, 1));
  EXPECT_NEAR(bottom1 - top0, 0.15, 1e-12) << "a gap of 15 % of the lower piece's height";
  for (int k = 0; k < 2; ++k) EXPECT_NEAR(signedArea(layout, layout.polygons[static_cast<std::size_t>(k)]), 1.0, 1e-12);
  int copiesOfPoint1 = 0;
  for (const int p : layout.pointOfVertex) copiesOfPoint1 += p == 1;
  EXPECT_EQ(copiesOfPoint1, 2);
}

TEST(IsometricUnfolding, PolygonsMeetingAtAPointOnlyArePiecesOfTheirOwn) {
  const std::vector<std::vector<int>> polygons = {{0, 1, 2, 3}, {2, 4, 5, 6}, {1, 7, 8, 2}, {9, 10, 11}};
  EXPECT_EQ(edgeConnectedPieces(polygons), (std::vector<int>{0, 1, 0, 2}));
}

TEST(IsometricUnfolding, PointsWithinTheToleranceAreWeldedIntoTheLowestIdOfTheirChain) {
  Eigen::MatrixX3d points(5, 3);
  points << 0, 0, 0,  //
      1, 0, 0,        //
      0, 0, 0.6e-6,   // within 1e-6 of point 0
      1, 0, 2e-6,     // 2e-6 from point 1: apart
      0, 0, 1.2e-6;   // 1.2e-6 from point 0, 0.6e-6 from point 2: chained to 0
  EXPECT_EQ(weldedPointIds(points, 1e-6), (std::vector<int>{0, 1, 0, 3, 0}));
  EXPECT_THROW(weldedPointIds(points, -1.0), std::invalid_argument);
}

TEST(IsometricUnfolding, BadInputIsRefusedNamingWhatIsWrong) {
  const std::vector<Eigen::Vector3d> points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  EXPECT_THROW(unfoldPieces(points, {{0, 1, 2}}, {}), std::invalid_argument);
  try {
    unfoldPieces(points, {{0, 1, 5}}, {0});
    FAIL() << "an id out of range is refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("point id 5"), std::string::npos) << e.what();
  }
  EXPECT_THROW(unfoldPieces({{0, 0, 0}, {0, 0, 0}, {0, 1, 0}}, {{0, 1, 2}}, {0}), std::invalid_argument);
  EXPECT_THROW(unfoldPieces({{0, 0, 0}, {NAN, 0, 0}, {0, 1, 0}}, {{0, 1, 2}}, {0}), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::spatial
