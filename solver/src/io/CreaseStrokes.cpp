#include "devsurf/io/CreaseStrokes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

#include "devsurf/spatial/PlanarArrangement.h"

namespace devsurf::io {

namespace {

/// The diagonal of the strokes' bounding box (strokes not empty).
double strokesDiagonal(const std::vector<CreaseStroke>& strokes) {
  Eigen::Vector2d lo = strokes[0].points[0], hi = lo;
  for (const CreaseStroke& s : strokes)
    for (const Eigen::Vector2d& p : s.points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  return (hi - lo).norm();
}

}  // namespace

std::vector<ImportNote> absorbEndJogs(std::vector<CreaseStroke>& strokes, double jogFraction) {
  std::vector<ImportNote> notes;
  if (strokes.empty()) return notes;
  const double jog = jogFraction * strokesDiagonal(strokes);
  auto length = [](const CreaseStroke& s) {
    double l = 0.0;
    for (std::size_t k = 1; k < s.points.size(); ++k) l += (s.points[k] - s.points[k - 1]).norm();
    return l;
  };
  std::vector<bool> dropped(strokes.size(), false);
  for (std::size_t i = 0; i < strokes.size(); ++i) {
    const CreaseStroke& piece = strokes[i];
    if (piece.closed || piece.element.empty() || piece.points.size() < 2 || length(piece) > jog) continue;
    // A neighbour of the same path that this piece ends: it shares one of the piece's end points,
    // and the piece's other end touches nothing else of the path (the path starts or ends there).
    for (std::size_t j = 0; j < strokes.size(); ++j) {
      CreaseStroke& next = strokes[j];
      if (j == i || dropped[j] || next.closed || next.element != piece.element || length(next) <= jog) continue;
      for (const bool nextFront : {true, false}) {
        Eigen::Vector2d& joint = nextFront ? next.points.front() : next.points.back();
        const bool atPieceFront = joint == piece.points.front(), atPieceBack = joint == piece.points.back();
        if (!atPieceFront && !atPieceBack) continue;
        const Eigen::Vector2d far = atPieceFront ? piece.points.back() : piece.points.front();
        // The jog is the path's first or last piece: its far end touches nothing else of the
        // element, and its joint only this neighbour (a compound path's other subpaths may meet
        // there too: then it is a crease of its own, not a jog).
        int touchFar = 0, touchJoint = 0;
        for (std::size_t k = 0; k < strokes.size(); ++k) {
          if (k == i || dropped[k] || strokes[k].element != piece.element) continue;
          for (const Eigen::Vector2d& endPoint : {strokes[k].points.front(), strokes[k].points.back()}) {
            touchFar += endPoint == far;
            touchJoint += endPoint == joint;
          }
        }
        if (touchFar > 0 || touchJoint != 1) continue;
        std::ostringstream note;
        note.precision(3);
        note << "a jog of " << length(piece) << " at (" << far.x() << ", " << far.y() << ") where the path "
             << (nextFront ? "starts" : "ends") << "; smoothed into the stroke";
        notes.push_back({piece.element, note.str()});
        joint = far;
        dropped[i] = true;
        break;
      }
      if (dropped[i]) break;
    }
  }
  std::vector<CreaseStroke> kept;
  for (std::size_t i = 0; i < strokes.size(); ++i)
    if (!dropped[i]) kept.push_back(std::move(strokes[i]));
  strokes = std::move(kept);
  return notes;
}

std::vector<ImportNote> splitIntoStraightRuns(std::vector<CreaseStroke>& strokes, double mergeFraction) {
  std::vector<ImportNote> notes;
  if (strokes.empty()) return notes;
  const double diagonal = strokesDiagonal(strokes);
  const double merge = mergeFraction * diagonal, straight = kStraightStrokeFraction * diagonal;
  const auto isStraight = [straight](const std::vector<Eigen::Vector2d>& points) {
    const Eigen::Vector2d a = points.front(), b = points.back();
    if ((b - a).norm() == 0.0) return false;
    const Eigen::Vector2d axis = (b - a).normalized();
    for (const Eigen::Vector2d& p : points)
      if (std::abs(axis.x() * (p - a).y() - axis.y() * (p - a).x()) > straight) return false;
    return true;
  };
  std::vector<std::array<Eigen::Vector2d, 2>> ends;  // every open stroke's ends, read before any stroke moves
  for (const CreaseStroke& s : strokes)
    if (!s.closed && !s.points.empty()) ends.push_back({s.points.front(), s.points.back()});
  std::vector<CreaseStroke> result;
  for (std::size_t i = 0; i < strokes.size(); ++i) {
    CreaseStroke& stroke = strokes[i];
    if (stroke.closed || stroke.points.size() < 3 || isStraight(stroke.points)) {
      result.push_back(std::move(stroke));
      continue;
    }
    // Inner points where another stroke ends.
    std::vector<std::size_t> cuts;
    for (std::size_t k = 1; k + 1 < stroke.points.size(); ++k) {
      const bool endsHere = std::any_of(ends.begin(), ends.end(), [&stroke, k, merge](const auto& e) {
        return (e[0] - stroke.points[k]).norm() <= merge || (e[1] - stroke.points[k]).norm() <= merge;
      });
      if (endsHere) cuts.push_back(k);
    }
    std::vector<std::vector<Eigen::Vector2d>> parts;
    std::size_t from = 0;
    cuts.push_back(stroke.points.size() - 1);
    for (std::size_t cut : cuts) {
      parts.emplace_back(stroke.points.begin() + static_cast<std::ptrdiff_t>(from),
                         stroke.points.begin() + static_cast<std::ptrdiff_t>(cut) + 1);
      from = cut;
    }
    const bool allStraight = parts.size() > 1 && std::all_of(parts.begin(), parts.end(), isStraight);
    if (!allStraight) {
      result.push_back(std::move(stroke));
      continue;
    }
    notes.push_back({stroke.element, "not one curve but " + std::to_string(parts.size()) +
                                         " straight lines meeting at the ends of other strokes (at a small angle); read "
                                         "as those lines"});
    for (std::vector<Eigen::Vector2d>& part : parts) {
      CreaseStroke piece = stroke;
      piece.points = {part.front(), part.back()};
      result.push_back(std::move(piece));
    }
  }
  strokes = std::move(result);
  return notes;
}

std::vector<ImportNote> snapNearlyMeetingEnds(std::vector<CreaseStroke>& strokes, double mergeFraction, double snapFraction) {
  std::vector<ImportNote> notes;
  if (strokes.empty()) return notes;
  const double diagonal = strokesDiagonal(strokes);
  const double merge = mergeFraction * diagonal, snap = snapFraction * diagonal;
  if (!(snap > merge)) return notes;
  auto length = [](const CreaseStroke& s) {
    double l = 0.0;
    for (std::size_t k = 1; k < s.points.size(); ++k) l += (s.points[k] - s.points[k - 1]).norm();
    return l;
  };
  for (std::size_t i = 0; i < strokes.size(); ++i) {
    CreaseStroke& stroke = strokes[i];
    if (stroke.closed || stroke.points.size() < 2 || length(stroke) <= 2.0 * snap) continue;
    for (const bool front : {true, false}) {
      Eigen::Vector2d& end = front ? stroke.points.front() : stroke.points.back();
      double nearestLine = std::numeric_limits<double>::infinity();
      Eigen::Vector2d atLine = end;
      std::size_t onStroke = strokes.size();
      for (std::size_t j = 0; j < strokes.size(); ++j) {
        if (j == i) continue;
        const std::vector<Eigen::Vector2d>& q = strokes[j].points;
        const std::size_t n = q.size(), pieces = strokes[j].closed ? n : n - 1;
        for (std::size_t k = 0; k < pieces; ++k) {
          const Eigen::Vector2d a = q[k], d = q[(k + 1) % n] - a;
          const double t = d.squaredNorm() > 0.0 ? std::clamp((end - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
          const double gap = (a + t * d - end).norm();
          if (gap < nearestLine) {
            nearestLine = gap;
            atLine = a + t * d;
            onStroke = j;
          }
        }
      }
      if (onStroke == strokes.size() || nearestLine <= merge || nearestLine > snap) continue;  // meets, or is free
      // Onto the nearest point of that stroke's line; onto its vertex when the foot is that vertex
      // up to the merge tolerance (no sliver beside it).
      Eigen::Vector2d to = atLine;
      for (const Eigen::Vector2d& point : strokes[onStroke].points)
        if ((point - atLine).norm() <= merge) to = point;
      std::ostringstream note;
      note.precision(3);
      note << "its " << (front ? "start" : "end") << " at (" << end.x() << ", " << end.y() << ") was " << nearestLine
           << " from " << strokes[onStroke].element << "; joined to it";
      notes.push_back({stroke.element, note.str()});
      end = to;
    }
  }
  return notes;
}

StrokePattern creasePatternFromStrokes(std::vector<CreaseStroke> strokes, const CreaseStrokesOptions& options) {
  const bool svg = options.source == "SVG";
  const std::string prefix = options.source + ": ", noteElement = svg ? "svg" : "edges_vertices";
  if (strokes.empty())
    throw std::invalid_argument(prefix + (svg ? "no strokes in a crease colour (black, red, blue, green, yellow, magenta)" : "no lines"));
  StrokePattern result;
  const double diagonal = strokesDiagonal(strokes);
  if (!(diagonal > 0.0)) throw std::invalid_argument(prefix + "the drawing has no extent");
  // A stroke no longer than the merge tolerance is a point: given to the arrangement it would
  // still split what it touches (a vertex left on the outline, its faces degenerate there), and
  // as a "curve" it would make every straight stroke be cut into pieces.
  std::vector<bool> pointLike(strokes.size(), false);
  for (std::size_t i = 0; i < strokes.size(); ++i) {
    const CreaseStroke& stroke = strokes[i];
    double length = 0.0;
    for (std::size_t k = 1; k < stroke.points.size(); ++k) length += (stroke.points[k] - stroke.points[k - 1]).norm();
    if (stroke.closed && stroke.points.size() > 1) length += (stroke.points.front() - stroke.points.back()).norm();
    pointLike[i] = length <= options.mergeFraction * diagonal;
  }
  for (std::size_t i = 0; i < strokes.size(); ++i) {
    CreaseStroke& s = strokes[i];
    if (pointLike[i]) {
      s.curved = false;
      continue;
    }
    if (s.closed) {
      s.curved = true;
      continue;
    }
    if (options.curvedDecided) continue;
    const Eigen::Vector2d a = s.points.front(), b = s.points.back();
    const Eigen::Vector2d axis = (b - a).norm() > 0 ? Eigen::Vector2d((b - a).normalized()) : Eigen::Vector2d::UnitX();
    double deviation = 0.0;
    for (const Eigen::Vector2d& p : s.points) deviation = std::max(deviation, std::abs(axis.x() * (p - a).y() - axis.y() * (p - a).x()));
    s.curved = deviation > kStraightStrokeFraction * diagonal || (b - a).norm() == 0.0;
  }
  const bool anyCurved = std::any_of(strokes.begin(), strokes.end(), [](const CreaseStroke& s) { return s.curved; });
  result.strokes = static_cast<int>(strokes.size());
  for (const CreaseStroke& s : strokes) result.strokeCurved.push_back(s.curved);
  result.curvedStrokes = static_cast<int>(std::count_if(strokes.begin(), strokes.end(), [](const CreaseStroke& s) { return s.curved; }));

  // Segments of every stroke; straight strokes cut into pieces where rulings may need points.
  std::vector<Eigen::Vector2d> points;
  std::vector<std::array<int, 2>> segments;
  std::vector<int> strokeOfSegment;
  for (std::size_t s = 0; s < strokes.size(); ++s) {
    const CreaseStroke& stroke = strokes[s];
    if (pointLike[s]) continue;
    std::vector<Eigen::Vector2d> pts = stroke.points;
    if (!stroke.curved && anyCurved && options.straightPieces > 1) {
      pts.clear();
      for (int k = 0; k <= options.straightPieces; ++k)
        pts.push_back(stroke.points.front() + (stroke.points.back() - stroke.points.front()) * k / options.straightPieces);
    } else if (!stroke.curved) {
      pts = {stroke.points.front(), stroke.points.back()};
    }
    const int first = static_cast<int>(points.size());
    points.insert(points.end(), pts.begin(), pts.end());
    const int count = static_cast<int>(pts.size());
    for (int k = 0; k + 1 < count; ++k) {
      segments.push_back({first + k, first + k + 1});
      strokeOfSegment.push_back(static_cast<int>(s));
    }
    if (stroke.closed && count >= 3) {
      segments.push_back({first + count - 1, first});
      strokeOfSegment.push_back(static_cast<int>(s));
    }
    if (static_cast<int>(segments.size()) > options.maxSegments)
      throw std::length_error(prefix + "more than " + std::to_string(options.maxSegments) + " segments after " +
                              (svg ? "sampling the curves" : "laying out its lines again (straight lines cut into pieces)"));
  }
  Eigen::MatrixX2d pointMatrix(static_cast<Eigen::Index>(points.size()), 2);
  for (std::size_t k = 0; k < points.size(); ++k) pointMatrix.row(static_cast<Eigen::Index>(k)) = points[k].transpose();
  spatial::PlanarArrangementOptions arrangementOptions;
  arrangementOptions.tolerance = options.mergeFraction * diagonal;
  arrangementOptions.bridgeIslands = true;
  spatial::PlanarArrangement arrangement = spatial::planarArrangement(pointMatrix, segments, arrangementOptions);
  {
    // Where lines end or meet (a point on one line only, between two of its pieces, is no corner:
    // the samples of a curve).
    std::vector<int> degree(static_cast<std::size_t>(arrangement.points.rows()), 0);
    for (const std::array<int, 2>& piece : arrangement.segments)
      for (int end : piece) ++degree[static_cast<std::size_t>(end)];
    const auto corners = std::count_if(degree.begin(), degree.end(), [](int d) { return d > 0 && d != 2; });
    if (corners > options.maxPoints)
      throw std::length_error(prefix + "its lines end and meet at " + std::to_string(corners) +
                              " points; a design holds at most " + std::to_string(options.maxPoints) +
                              " corners (draw fewer lines, or split the pattern)");
  }
  const auto strokeOfPiece = [&strokeOfSegment, &arrangement](std::size_t s) {
    const int source = arrangement.sourceOfSegment[s];
    return source < 0 ? -1 : strokeOfSegment[static_cast<std::size_t>(source)];
  };
  // Holes: faces that outline (black) or cut (green) strokes inside the sheet wall off from the
  // sheet's edge — a region cut all round falls out.
  if (const int holes = spatial::cutOutHoles(arrangement, [&strokeOfSegment, &strokes](int source) {
        const EdgeAssignment a = strokes[static_cast<std::size_t>(strokeOfSegment[static_cast<std::size_t>(source)])].assignment;
        return a == EdgeAssignment::Boundary || a == EdgeAssignment::Cut;
      }))
    result.notes.push_back({noteElement, std::to_string(holes) + (svg ? " face(s) inside outline (black) or cut (green) strokes "
                                                                       : " face(s) inside boundary (B) or cut (C) lines ") +
                                             "within the sheet; cut out as holes"});

  std::set<int> leftOut;
  for (int s : arrangement.unusedSegments) leftOut.insert(strokeOfSegment[static_cast<std::size_t>(s)]);
  result.strokeLeftOut.assign(strokes.size(), false);
  for (int s : leftOut) result.strokeLeftOut[static_cast<std::size_t>(s)] = true;
  for (std::size_t s = 0; s < strokes.size(); ++s)
    if (pointLike[s]) {
      result.strokeLeftOut[s] = true;
      result.notes.push_back({strokes[s].element, "a stroke of no length (a point); left out"});
    }
  std::set<int> usedStrokes;
  for (int source : arrangement.sourceOfSegment)
    if (source >= 0) usedStrokes.insert(strokeOfSegment[static_cast<std::size_t>(source)]);
  for (int s : leftOut)
    if (!usedStrokes.count(s)) {
      const CreaseStroke& stroke = strokes[static_cast<std::size_t>(s)];
      std::ostringstream note;
      note.precision(4);
      note << (svg ? "a stroke" : "a line") << " with a free end, or apart from the sheet (from (" << stroke.points.front().x() << ", "
           << stroke.points.front().y() << ") to (" << stroke.points.back().x() << ", " << stroke.points.back().y()
           << ")); left out — a crease ends on another crease or on the outline";
      result.notes.push_back({stroke.element, note.str()});
    }
  if (arrangement.islands > 0)
    result.notes.push_back({noteElement, std::to_string(arrangement.islands) + " island(s) inside the sheet not bridged (no straight "
                                   "bridge fits, or past the bound on bridging work); left out"});
  if (arrangement.bridgedIslands > 0)
    result.notes.push_back({noteElement, std::to_string(arrangement.bridgedIslands) + " island(s) inside the sheet (closed "
                                             + (svg ? "strokes" : "lines") + " touching nothing) joined to what surrounds them by two straight rulings each"});
  if (arrangement.faces.empty())
    throw std::invalid_argument(prefix + (svg ? "the strokes enclose no face (draw the sheet's outline in black)"
                                              : "the lines enclose no face (the sheet needs an outline of B edges)"));

  CreasePattern& p = result.pattern;
  p.unitToMm = 1.0;
  p.vertices2d = arrangement.points;
  p.faces = arrangement.faces;
  std::map<std::pair<int, int>, int> facesOfPair;
  for (const auto& f : p.faces)
    for (std::size_t k = 0; k < f.size(); ++k) ++facesOfPair[std::minmax(f[k], f[(k + 1) % f.size()])];
  std::set<int> outlineCreases, innerBoundaries;
  std::vector<int> strokeOfEdge;  // per p.edges entry: its stroke, −1 for a bridge
  std::vector<double> boundingLength(strokes.size(), 0.0), strokeLength(strokes.size(), 0.0);
  for (std::size_t k = 0; k < segments.size(); ++k)
    strokeLength[static_cast<std::size_t>(strokeOfSegment[k])] += (points[static_cast<std::size_t>(segments[k][0])] -
                                                                    points[static_cast<std::size_t>(segments[k][1])]).norm();
  for (std::size_t s = 0; s < arrangement.segments.size(); ++s) {
    const auto key = std::minmax(arrangement.segments[s][0], arrangement.segments[s][1]);
    const auto count = facesOfPair.find(key);
    const int strokeId = strokeOfPiece(s);
    if (count == facesOfPair.end()) continue;
    if (strokeId < 0) {  // a bridge to an island
      CreaseEdge edge;
      edge.v0 = key.first;
      edge.v1 = key.second;
      edge.proposed = true;
      edge.assignment = count->second == 1 ? EdgeAssignment::Boundary : EdgeAssignment::Flat;
      p.edges.push_back(edge);
      strokeOfEdge.push_back(-1);
      continue;
    }
    boundingLength[static_cast<std::size_t>(strokeId)] +=
        (arrangement.points.row(arrangement.segments[s][0]) - arrangement.points.row(arrangement.segments[s][1])).norm();
    const CreaseStroke& stroke = strokes[static_cast<std::size_t>(strokeId)];
    CreaseEdge edge;
    edge.v0 = key.first;
    edge.v1 = key.second;
    edge.curve = anyCurved ? strokeId : -1;
    if (count->second == 1) {
      edge.assignment = EdgeAssignment::Boundary;
      if (stroke.assignment != EdgeAssignment::Boundary && stroke.assignment != EdgeAssignment::Cut) outlineCreases.insert(strokeId);
    } else if (stroke.assignment == EdgeAssignment::Boundary) {
      edge.assignment = EdgeAssignment::Cut;
      innerBoundaries.insert(strokeId);
    } else {
      edge.assignment = stroke.assignment;
      if (stroke.foldAngle && *stroke.foldAngle != 0.0) edge.foldAngle = stroke.foldAngle;
    }
    p.edges.push_back(edge);
    strokeOfEdge.push_back(strokeId);
  }
  // A stroke whose face-bounding pieces do not add up to its length lost a piece (a dangling
  // tail is pruned from the arrangement without a trace).
  for (std::size_t s = 0; s < strokes.size(); ++s)
    if (boundingLength[s] < strokeLength[s] * (1.0 - 1e-6) - 1e-9 * diagonal) result.strokeLeftOut[s] = true;
  // Two creases meeting alone at a corner (a polyline crease turning, a zigzag): no fold of both
  // keeps the sheet in one piece there (a crease's vertex needs more creases round it, or none to
  // turn), so say where before a fold stretches the sheet to reach it.
  {
    std::map<int, std::vector<std::size_t>> edgesAt;
    for (std::size_t e = 0; e < p.edges.size(); ++e) {
      edgesAt[p.edges[e].v0].push_back(e);
      edgesAt[p.edges[e].v1].push_back(e);
    }
    for (const auto& [v, at] : edgesAt) {
      if (at.size() != 2) continue;
      const CreaseEdge& a = p.edges[at[0]];
      const CreaseEdge& b = p.edges[at[1]];
      const auto folds = [](const CreaseEdge& e) { return e.assignment == EdgeAssignment::Mountain || e.assignment == EdgeAssignment::Valley; };
      if (!folds(a) || !folds(b) || strokeOfEdge[at[0]] == strokeOfEdge[at[1]]) continue;
      const Eigen::Vector2d here = p.vertices2d.row(v).transpose();
      const Eigen::Vector2d in = here - Eigen::Vector2d(p.vertices2d.row(a.v0 == v ? a.v1 : a.v0).transpose());
      const Eigen::Vector2d out = Eigen::Vector2d(p.vertices2d.row(b.v0 == v ? b.v1 : b.v0).transpose()) - here;
      const double turnDeg = std::atan2(std::abs(in.x() * out.y() - in.y() * out.x()), in.dot(out)) * 180.0 / 3.14159265358979323846;
      if (turnDeg <= 10.0) continue;
      std::ostringstream note;
      note.precision(4);
      note << "two creases meet alone at (" << here.x() << ", " << here.y() << ")" << (svg ? " mm from the page's bottom left, y up" : "")
           << ", turning by " << std::lround(turnDeg)
           << "°: they cannot both fold there without stretching the sheet (draw a crease on through the corner, or round it)";
      result.notes.push_back({strokes[static_cast<std::size_t>(strokeOfEdge[at[1]])].element, note.str()});
    }
  }
  for (int s : outlineCreases)
    result.notes.push_back({strokes[static_cast<std::size_t>(s)].element,
                            svg ? "a crease colour on the sheet's outline; read as boundary" : "a crease (M, V, F) on the sheet's outline; read as boundary"});
  for (int s : innerBoundaries)
    result.notes.push_back({strokes[static_cast<std::size_t>(s)].element,
                            svg ? "a boundary (black) line inside the sheet; read as a cut" : "a boundary (B) line inside the sheet; read as a cut"});
  // Only the points the faces use (merged duplicates and pruned ends would be noted as lone
  // vertices by every later step).
  std::vector<int> newIndex(static_cast<std::size_t>(p.vertices2d.rows()), -1);
  int used = 0;
  for (const auto& f : p.faces)
    for (int v : f)
      if (newIndex[static_cast<std::size_t>(v)] < 0) newIndex[static_cast<std::size_t>(v)] = used++;
  Eigen::MatrixX2d kept(used, 2);
  for (std::size_t v = 0; v < newIndex.size(); ++v)
    if (newIndex[v] >= 0) kept.row(newIndex[v]) = p.vertices2d.row(static_cast<Eigen::Index>(v));
  p.vertices2d = std::move(kept);
  for (auto& f : p.faces)
    for (int& v : f) v = newIndex[static_cast<std::size_t>(v)];
  for (CreaseEdge& e : p.edges) {
    e.v0 = newIndex[static_cast<std::size_t>(e.v0)];
    e.v1 = newIndex[static_cast<std::size_t>(e.v1)];
  }
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(prefix + e.what());
  }
  return result;
}

}  // namespace devsurf::io
