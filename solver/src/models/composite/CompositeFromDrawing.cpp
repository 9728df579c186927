#include "devsurf/models/composite/CompositeFromDrawing.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "devsurf/models/composite/CompositeFromCreasePattern.h"

namespace devsurf::models::composite {

namespace {

/// Centripetal Catmull–Rom (α = ½) on the span p1 → p2 with neighbours p0, p3, at t ∈ [0, 1]
/// (Barry–Goldman's pyramid; coincident knots are nudged apart).
Eigen::Vector2d catmullRomPoint(const Eigen::Vector2d& p0, const Eigen::Vector2d& p1, const Eigen::Vector2d& p2,
                                const Eigen::Vector2d& p3, double t) {
  auto knotStep = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return std::max(std::sqrt((b - a).norm()), 1e-12); };
  const double t0 = 0.0;
  const double t1 = t0 + knotStep(p0, p1);
  const double t2 = t1 + knotStep(p1, p2);
  const double t3 = t2 + knotStep(p2, p3);
  const double u = t1 + t * (t2 - t1);
  const Eigen::Vector2d a1 = (t1 - u) / (t1 - t0) * p0 + (u - t0) / (t1 - t0) * p1;
  const Eigen::Vector2d a2 = (t2 - u) / (t2 - t1) * p1 + (u - t1) / (t2 - t1) * p2;
  const Eigen::Vector2d a3 = (t3 - u) / (t3 - t2) * p2 + (u - t2) / (t3 - t2) * p3;
  const Eigen::Vector2d b1 = (t2 - u) / (t2 - t0) * a1 + (u - t0) / (t2 - t0) * a2;
  const Eigen::Vector2d b2 = (t3 - u) / (t3 - t1) * a2 + (u - t1) / (t3 - t1) * a3;
  return (t2 - u) / (t2 - t1) * b1 + (u - t1) / (t2 - t1) * b2;
}

}  // namespace

std::vector<Eigen::Vector2d> sampleThroughPoints(const std::vector<Eigen::Vector2d>& points, bool closed, int segments) {
  assert(points.size() >= 2 && "a stroke has at least two points");
  const int n = static_cast<int>(points.size());
  const int spans = closed ? n : n - 1;
  auto at = [&points, n, closed](int i) -> Eigen::Vector2d {
    if (closed) return points[static_cast<std::size_t>(((i % n) + n) % n)];
    if (i < 0) return 2.0 * points[0] - points[1];  // reflected end neighbours: a natural end
    if (i >= n) return 2.0 * points[static_cast<std::size_t>(n - 1)] - points[static_cast<std::size_t>(n - 2)];
    return points[static_cast<std::size_t>(i)];
  };
  double total = 0.0;
  std::vector<double> chord(static_cast<std::size_t>(spans));
  for (int s = 0; s < spans; ++s) total += chord[static_cast<std::size_t>(s)] = (at(s + 1) - at(s)).norm();
  std::vector<Eigen::Vector2d> out;
  for (int s = 0; s < spans; ++s) {
    const double share = total > 0.0 ? chord[static_cast<std::size_t>(s)] / total : 1.0 / spans;
    const int pieces = std::max(1, static_cast<int>(std::lround(share * segments)));
    for (int k = 0; k < pieces; ++k)
      out.push_back(k == 0 ? at(s) : catmullRomPoint(at(s - 1), at(s), at(s + 1), at(s + 2), static_cast<double>(k) / pieces));
  }
  if (!closed) out.push_back(points.back());
  return out;
}

DrawingComposite compositeFromDrawing(std::vector<io::CreaseStroke> drawing, const DrawingOptions& options) {
  if (drawing.empty()) throw std::invalid_argument("drawing: no strokes (draw the sheet's outline)");
  std::vector<io::CreaseStroke> sampled;
  sampled.reserve(drawing.size());
  for (std::size_t i = 0; i < drawing.size(); ++i) {
    io::CreaseStroke& stroke = drawing[i];
    stroke.element = "drawing.strokes[" + std::to_string(i) + "]";
    if (stroke.points.size() < 2 || (stroke.closed && stroke.points.size() < 3))
      throw std::invalid_argument(stroke.element + ".points: a stroke needs at least 2 points (3 when closed)");
    io::CreaseStroke s = stroke;
    const int count = static_cast<int>(stroke.points.size());
    if (stroke.curved && count <= options.curveSegments)
      s.points = sampleThroughPoints(stroke.points, stroke.closed, std::max(options.curveSegments, 2 * count));
    sampled.push_back(std::move(s));
  }
  io::StrokePattern pattern = io::creasePatternFromStrokes(sampled, options.strokes);
  DrawingComposite result;
  result.strokeLeftOut = pattern.strokeLeftOut;
  result.notes = pattern.notes;
  CreasePatternComposite built = compositeFromCreasePattern(pattern.pattern);
  result.notes.insert(result.notes.end(), built.notes.begin(), built.notes.end());
  result.design = std::move(built.design);
  result.design.foldAmount = 0.0;  // a drawing is flat: the fold slider starts at 0 %, targets or not
  for (std::size_t i = 0; i < drawing.size(); ++i) drawing[i].curved = pattern.strokeCurved[i];
  result.design.drawing = std::move(drawing);
  return result;
}

std::vector<io::CreaseStroke> drawingOfCreasePattern(const io::CreasePattern& pattern) {
  std::vector<io::CreaseStroke> strokes;
  strokes.reserve(pattern.edges.size());
  for (const io::CreaseEdge& e : pattern.edges) {
    io::CreaseStroke s;
    s.points = {pattern.vertices2d.row(e.v0).transpose(), pattern.vertices2d.row(e.v1).transpose()};
    s.assignment = e.assignment;
    s.foldAngle = e.foldAngle;
    strokes.push_back(std::move(s));
  }
  return strokes;
}

}  // namespace devsurf::models::composite
