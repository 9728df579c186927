#include "devsurf/io/FoldCurvedCreases.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <sstream>
#include <string>

namespace devsurf::io {

namespace {

constexpr double kFoldChainRadiansPerDegree = 3.14159265358979323846 / 180.0;
/// A crease whose angles spread by more than this along it (degrees) gets a note.
constexpr double kAngleSpreadNoteDeg = 5.0;

bool isLine(EdgeAssignment a) {
  return a == EdgeAssignment::Mountain || a == EdgeAssignment::Valley || a == EdgeAssignment::Boundary ||
         a == EdgeAssignment::Cut;
}

struct LineChain {
  std::vector<int> vertices;  ///< in order; a closed chain does not repeat its first
  std::vector<int> edges;
  bool closed = false;
};

std::string pointText(const Eigen::Vector2d& p) {
  std::ostringstream out;
  out.precision(4);
  out << "(" << p.x() << ", " << p.y() << ")";
  return out.str();
}

/// The last decimal the coordinates are written to: the smallest 10^-k (k ≤ 9) of which every
/// coordinate is a whole multiple, 0 when none is (full precision).
double coordinateQuantum(const Eigen::MatrixX2d& points) {
  for (int k = 0; k <= 9; ++k) {
    const double scale = std::pow(10.0, k);
    bool whole = true;
    for (Eigen::Index i = 0; i < points.size() && whole; ++i) {
      const double v = points.data()[i] * scale;
      whole = std::abs(v) < 1e12 && std::abs(v - std::round(v)) <= 1e-6;
    }
    if (whole) return 1.0 / scale;
  }
  return 0.0;
}

}  // namespace

FoldCurvedCreases foldCurvedCreases(const CreasePattern& pattern, const std::vector<int>& edgeCurves, double maxTurnDeg) {
  FoldCurvedCreases result;
  const int n = pattern.numVertices();
  if (n == 0 || pattern.edges.empty()) return result;
  const auto at = [&pattern](int v) { return Eigen::Vector2d(pattern.vertices2d.row(v).transpose()); };
  std::vector<std::vector<int>> incident(static_cast<std::size_t>(n));
  for (std::size_t e = 0; e < pattern.edges.size(); ++e)
    if (isLine(pattern.edges[e].assignment)) {
      incident[static_cast<std::size_t>(pattern.edges[e].v0)].push_back(static_cast<int>(e));
      incident[static_cast<std::size_t>(pattern.edges[e].v1)].push_back(static_cast<int>(e));
    }
  const auto other = [&pattern](int e, int v) {
    const CreaseEdge& edge = pattern.edges[static_cast<std::size_t>(e)];
    return edge.v0 == v ? edge.v1 : edge.v0;
  };
  const double cosMaxTurn = std::cos(maxTurnDeg * kFoldChainRadiansPerDegree);
  // A line runs on through v: exactly two line edges meet there, alike, turning little.
  const auto runsThrough = [&](int v) {
    const std::vector<int>& inc = incident[static_cast<std::size_t>(v)];
    if (inc.size() != 2) return false;
    if (pattern.edges[static_cast<std::size_t>(inc[0])].assignment != pattern.edges[static_cast<std::size_t>(inc[1])].assignment)
      return false;
    if (edgeCurves.size() == pattern.edges.size() &&
        edgeCurves[static_cast<std::size_t>(inc[0])] != edgeCurves[static_cast<std::size_t>(inc[1])])
      return false;
    const Eigen::Vector2d in = at(v) - at(other(inc[0], v)), out = at(other(inc[1], v)) - at(v);
    const double lengths = in.norm() * out.norm();
    return lengths > 0.0 && in.dot(out) >= cosMaxTurn * lengths;
  };

  std::vector<LineChain> chains;
  std::vector<char> used(pattern.edges.size(), 0);
  // The edge that continues the line through `cur` from `from`, claimed; -1 where the line ends.
  const auto nextEdge = [&incident, &used, &runsThrough](int cur, int from) {
    if (!runsThrough(cur)) return -1;
    const std::vector<int>& inc = incident[static_cast<std::size_t>(cur)];
    const int next = inc[0] == from ? inc[1] : inc[0];
    if (used[static_cast<std::size_t>(next)]) return -1;
    used[static_cast<std::size_t>(next)] = 1;
    return next;
  };
  for (std::size_t start = 0; start < pattern.edges.size(); ++start) {
    if (used[start] || !isLine(pattern.edges[start].assignment)) continue;
    used[start] = 1;
    const int e0 = static_cast<int>(start);
    std::deque<int> vertices{pattern.edges[start].v0, pattern.edges[start].v1};
    std::deque<int> edges{e0};
    bool closed = false;
    // Forward from v1; a walk that comes back to the first vertex closes the chain there when the
    // line runs through it (else the chain starts and ends at a corner).
    for (int cur = vertices.back(), from = e0, next; (next = nextEdge(cur, from)) >= 0; cur = vertices.back(), from = next) {
      edges.push_back(next);
      const int v = other(next, cur);
      if (v == vertices.front()) {
        closed = runsThrough(v);
        if (!closed) vertices.push_back(v);
        break;
      }
      vertices.push_back(v);
    }
    // Backward from v0, unless the walk came round.
    const bool backToStart = closed || vertices.back() == vertices.front();
    for (int cur = vertices.front(), from = e0, next; !backToStart && (next = nextEdge(cur, from)) >= 0;
         cur = vertices.front(), from = next) {
      edges.push_front(next);
      const int v = other(next, cur);
      vertices.push_front(v);
      if (v == vertices.back()) break;
    }
    chains.push_back({{vertices.begin(), vertices.end()}, {edges.begin(), edges.end()}, closed});
  }

  const double diagonal = (pattern.vertices2d.colwise().maxCoeff() - pattern.vertices2d.colwise().minCoeff()).norm();
  // A file written with few decimals (0.367 for a point on a straight crease) must not read its
  // rounding as a bend: the tolerance is at least twice the file's last decimal.
  const double straight = std::max(kStraightStrokeFraction * diagonal,
                                   std::min(2.0 * coordinateQuantum(pattern.vertices2d), 1e-3 * diagonal));
  const bool marked = edgeCurves.size() == pattern.edges.size();
  const auto bends = [&](const LineChain& c) {
    if (c.closed) return true;
    if (c.vertices.size() < 3) return false;
    const Eigen::Vector2d a = at(c.vertices.front()), b = at(c.vertices.back());
    if ((b - a).norm() == 0.0) return true;
    const Eigen::Vector2d axis = (b - a).normalized();
    double deviation = 0.0;
    for (int v : c.vertices) {
      const Eigen::Vector2d d = at(v) - a;
      deviation = std::max(deviation, std::abs(axis.x() * d.y() - axis.y() * d.x()));
    }
    return deviation > straight;
  };
  // devsurf's own export marks the edges of its curves: a chain it left unmarked is straight.
  const auto curved = [&](const LineChain& c) {
    return (!marked || edgeCurves[static_cast<std::size_t>(c.edges.front())] >= 0) && bends(c);
  };
  const bool anyCurvedCrease = std::any_of(chains.begin(), chains.end(), [&](const LineChain& c) {
    const EdgeAssignment a = pattern.edges[static_cast<std::size_t>(c.edges.front())].assignment;
    return (a == EdgeAssignment::Mountain || a == EdgeAssignment::Valley) && curved(c);
  });
  if (!anyCurvedCrease) return result;

  const std::vector<std::optional<double>> angles = exportedFoldAngles(pattern);
  for (const LineChain& c : chains) {
    CreaseStroke stroke;
    for (int v : c.vertices) stroke.points.push_back(at(v));
    stroke.closed = c.closed;
    stroke.curved = curved(c);  // decided here, with the file's rounding and marks (CreaseStrokesOptions::curvedDecided)
    stroke.assignment = pattern.edges[static_cast<std::size_t>(c.edges.front())].assignment;
    stroke.element = "crease from " + pointText(stroke.points.front()) + " to " + pointText(stroke.points.back());
    if (stroke.assignment == EdgeAssignment::Mountain || stroke.assignment == EdgeAssignment::Valley) {
      double weighted = 0.0, length = 0.0, lowest = 0.0, highest = 0.0;
      bool any = false;
      for (int e : c.edges) {
        const std::optional<double>& angle = angles[static_cast<std::size_t>(e)];
        if (!angle) continue;
        const CreaseEdge& edge = pattern.edges[static_cast<std::size_t>(e)];
        const double l = (at(edge.v1) - at(edge.v0)).norm();
        weighted += l * *angle;
        length += l;
        lowest = any ? std::min(lowest, *angle) : *angle;
        highest = any ? std::max(highest, *angle) : *angle;
        any = true;
      }
      if (any && length > 0.0) {
        stroke.foldAngle = weighted / length;
        if (highest - lowest > kAngleSpreadNoteDeg) {
          std::ostringstream note;
          note.precision(3);
          note << "its fold angle runs from " << lowest << "° to " << highest << "° along it; the fold slider's 100 % "
               << "holds their mean, " << *stroke.foldAngle << "°, all along it";
          result.notes.push_back({stroke.element, note.str()});
        }
      }
    }
    result.strokes.push_back(std::move(stroke));
  }
  const auto flat = std::count_if(pattern.edges.begin(), pattern.edges.end(),
                                  [](const CreaseEdge& e) { return e.assignment == EdgeAssignment::Flat; });
  std::ostringstream lines;
  lines << "curved creases drawn as chains of straight edges: read as " << result.strokes.size()
        << " lines (creases and outline) and laid out again";
  if (flat > 0) lines << "; the " << flat << " flat edges between them (F and U, rulings devsurf kept smooth, sides of the "
                      << "file's faces it does not list), the facets or rulings of the folded surface, are left out "
                      << "(rulings are proposed anew)";
  result.notes.push_back({"edges_vertices", lines.str()});
  if (pattern.hasFoldedState())
    result.notes.push_back({"file_frames", "the folded form is left out with the flat edges it was folded on: the sheet is "
                                           "imported flat, and the fold slider folds it to the file's fold angles"});
  return result;
}

}  // namespace devsurf::io
