// A composite built from a flat drawing (the layout edits' rebuild): the spline through a curved
// stroke's points, the drawing kept, strokes with free ends found, a FOLD pattern as a drawing.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "devsurf/models/composite/CompositeFromDrawing.h"
#include "devsurf/models/composite/CompositeTopology.h"

namespace devsurf::models::composite {
namespace {

io::CreaseStroke strokeOf(std::vector<Eigen::Vector2d> points, io::EdgeAssignment a, bool curved = false) {
  io::CreaseStroke s;
  s.points = std::move(points);
  s.assignment = a;
  s.curved = curved;
  return s;
}

/// A w × h sheet's outline, four B strokes.
std::vector<io::CreaseStroke> outline(double w, double h) {
  using V = Eigen::Vector2d;
  return {strokeOf({V(0, 0), V(w, 0)}, io::EdgeAssignment::Boundary), strokeOf({V(w, 0), V(w, h)}, io::EdgeAssignment::Boundary),
          strokeOf({V(w, h), V(0, h)}, io::EdgeAssignment::Boundary), strokeOf({V(0, h), V(0, 0)}, io::EdgeAssignment::Boundary)};
}

double distanceToPolyline(const Eigen::Vector2d& p, const std::vector<Eigen::Vector2d>& line) {
  double best = INFINITY;
  for (std::size_t k = 0; k + 1 < line.size(); ++k) {
    const Eigen::Vector2d d = line[k + 1] - line[k];
    const double t = std::clamp((p - line[k]).dot(d) / d.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (line[k] + t * d - p).norm());
  }
  return best;
}

TEST(SampleThroughPoints, PassesThroughEveryPointAndKeepsCollinearPointsOnTheirLine) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 3 + trial % 6;
    std::vector<Eigen::Vector2d> points;
    for (int i = 0; i < n; ++i) points.emplace_back(10.0 * i + u(rng) * 0.2, u(rng));
    const bool closed = trial % 5 == 0;
    const std::vector<Eigen::Vector2d> samples = sampleThroughPoints(points, closed, 16);
    ASSERT_GE(static_cast<int>(samples.size()), 16 - n);
    for (const Eigen::Vector2d& p : points) {
      double nearest = INFINITY;
      for (const Eigen::Vector2d& q : samples) nearest = std::min(nearest, (p - q).norm());
      EXPECT_LT(nearest, 1e-12);  // every given point is a sample
    }
    if (!closed) {
      EXPECT_EQ(samples.front(), points.front());
      EXPECT_EQ(samples.back(), points.back());
    }
  }
  // Collinear points: the spline is their line (centripetal Catmull–Rom reproduces lines).
  const std::vector<Eigen::Vector2d> line = {{0, 0}, {3, 1}, {9, 3}, {10, 10.0 / 3.0}};
  for (const Eigen::Vector2d& q : sampleThroughPoints(line, false, 30)) EXPECT_NEAR(q.y(), q.x() / 3.0, 1e-9);
}

TEST(CompositeFromDrawing, ACurvedCreaseThroughThreeClicksBecomesCurvedFoldsAndTheDrawingIsKept) {
  std::vector<io::CreaseStroke> drawing = outline(200, 150);
  drawing.push_back(strokeOf({{60, 0}, {90, 75}, {60, 150}}, io::EdgeAssignment::Valley, true));
  drawing.back().foldAngle = 90.0;
  const DrawingComposite built = compositeFromDrawing(drawing);
  EXPECT_NO_THROW(CompositeTopology topology(built.design));
  ASSERT_EQ(built.design.drawing.size(), drawing.size());
  EXPECT_EQ(built.design.drawing.back().points.size(), 3u);  // the clicks, not the samples
  EXPECT_TRUE(built.design.drawing.back().curved);
  EXPECT_EQ(built.design.foldAmount, 0.0);
  for (bool out : built.strokeLeftOut) EXPECT_FALSE(out);
  // The S edges follow the spline through the clicks (in the flat state: z = 0, x/y on the curve).
  const std::vector<Eigen::Vector2d> spline = sampleThroughPoints(drawing.back().points, false, 200);
  int curvedEdges = 0;
  for (const CompositeEdge& e : built.design.edges) {
    if (e.type != EdgeType::Spline || e.crease != CreaseKind::Fold) continue;
    ++curvedEdges;
    for (double t = 0.0; t <= 1.0; t += 0.125) {
      const double a = e.curve.knots.domainBegin(), b = e.curve.knots.domainEnd();
      const Eigen::Vector3d p = e.curve.evaluate(a + t * (b - a));
      EXPECT_NEAR(p.z(), 0.0, 1e-9);
      EXPECT_LT(distanceToPolyline(Eigen::Vector2d(p.x(), p.y()), spline), 0.5) << "0.25 % of the sheet";
    }
  }
  EXPECT_GT(curvedEdges, 0);
}

TEST(CompositeFromDrawing, AStrokeWithAFreeEndOrATailBeyondACreaseIsFound) {
  std::vector<io::CreaseStroke> drawing = outline(200, 150);
  drawing.push_back(strokeOf({{0, 75}, {200, 75}}, io::EdgeAssignment::Valley));    // across: holds
  drawing.push_back(strokeOf({{100, 0}, {100, 100}}, io::EdgeAssignment::Mountain));  // a tail past the valley
  drawing.push_back(strokeOf({{20, 20}, {40, 40}}, io::EdgeAssignment::Valley));      // apart from everything
  const DrawingComposite built = compositeFromDrawing(drawing);
  EXPECT_FALSE(built.strokeLeftOut[4]);
  EXPECT_TRUE(built.strokeLeftOut[5]);
  EXPECT_TRUE(built.strokeLeftOut[6]);
}

TEST(CompositeFromDrawing, AFoldPatternAsADrawingBuildsTheSameFaces) {
  io::CreasePattern pattern;
  pattern.vertices2d.resize(6, 2);
  pattern.vertices2d << 0, 0, 100, 0, 100, 100, 0, 100, 50, 0, 50, 100;
  auto edge = [](int a, int b, io::EdgeAssignment s) {
    io::CreaseEdge e;
    e.v0 = a;
    e.v1 = b;
    e.assignment = s;
    return e;
  };
  using A = io::EdgeAssignment;
  pattern.edges = {edge(0, 4, A::Boundary), edge(4, 1, A::Boundary), edge(1, 2, A::Boundary), edge(2, 5, A::Boundary),
                   edge(5, 3, A::Boundary), edge(3, 0, A::Boundary), edge(4, 5, A::Valley)};
  const std::vector<io::CreaseStroke> drawing = drawingOfCreasePattern(pattern);
  ASSERT_EQ(drawing.size(), 7u);
  EXPECT_EQ(drawing[6].assignment, A::Valley);
  const DrawingComposite built = compositeFromDrawing(drawing);
  EXPECT_EQ(built.design.faces.size(), 2u);
  ASSERT_EQ(built.design.foldAngles.size(), 1u);
  EXPECT_DOUBLE_EQ(built.design.foldAngles[0].angleDeg, 180.0);  // a valley without an angle: a full fold
}

}  // namespace
}  // namespace devsurf::models::composite
