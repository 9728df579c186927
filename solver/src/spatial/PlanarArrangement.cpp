#include "devsurf/spatial/PlanarArrangement.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

namespace devsurf::spatial {

namespace {

double crossOf(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

/// A split of one input segment: parameter t along it and the point there.
struct SegmentSplit {
  double t = 0.0;
  int point = -1;
};

int findRoot(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

bool pointInLoop(const Eigen::MatrixX2d& points, const std::vector<int>& loop, const Eigen::Vector2d& p) {
  bool inside = false;
  for (std::size_t k = 0, j = loop.size() - 1; k < loop.size(); j = k++) {
    const Eigen::Vector2d a = points.row(loop[k]), b = points.row(loop[j]);
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
      inside = !inside;
  }
  return inside;
}

double loopSignedArea2(const Eigen::MatrixX2d& points, const std::vector<int>& loop) {
  double area2 = 0.0;
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const Eigen::Vector2d a = points.row(loop[k]), b = points.row(loop[(k + 1) % loop.size()]);
    area2 += crossOf(a, b);
  }
  return area2;
}

PlanarArrangement planarArrangement(const Eigen::MatrixX2d& inputPoints, const std::vector<std::array<int, 2>>& inputSegments,
                                    double tolerance) {
  const int n = static_cast<int>(inputPoints.rows());
  if (!inputPoints.allFinite()) throw std::invalid_argument("planarArrangement: a point is not finite");
  for (std::size_t s = 0; s < inputSegments.size(); ++s)
    for (int id : inputSegments[s])
      if (id < 0 || id >= n)
        throw std::invalid_argument("planarArrangement: segment " + std::to_string(s) + " has point id " + std::to_string(id) +
                                    " out of range [0, " + std::to_string(n) + ")");
  PlanarArrangement result;
  if (n == 0) return result;
  if (tolerance <= 0.0) {
    const double diagonal = (inputPoints.colwise().maxCoeff() - inputPoints.colwise().minCoeff()).norm();
    tolerance = 1e-9 * std::max(diagonal, 1e-300);
  }
  const double tol2 = tolerance * tolerance;

  // Merge points closer than the tolerance (sorted by x, so the scan is local).
  {
    std::vector<int> merge(n);
    std::iota(merge.begin(), merge.end(), 0);
    std::vector<int> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&inputPoints](int a, int b) { return inputPoints(a, 0) < inputPoints(b, 0); });
    for (int a = 0; a < n; ++a)
      for (int b = a + 1; b < n && inputPoints(order[b], 0) - inputPoints(order[a], 0) <= tolerance; ++b) {
        const int i = order[a], j = order[b];
        if ((inputPoints.row(i) - inputPoints.row(j)).squaredNorm() > tol2) continue;
        const int ri = findRoot(merge, i), rj = findRoot(merge, j);
        merge[std::max(ri, rj)] = std::min(ri, rj);  // the lowest id of a cluster is its root
      }
    result.mergedInto.resize(n);
    for (int i = 0; i < n; ++i) result.mergedInto[i] = findRoot(merge, i);
  }
  std::vector<Eigen::Vector2d> points;
  points.reserve(n);
  for (int i = 0; i < n; ++i) points.emplace_back(inputPoints.row(i).transpose());
  std::vector<std::array<int, 2>> segments(inputSegments.size());
  for (std::size_t s = 0; s < inputSegments.size(); ++s)
    segments[s] = {result.mergedInto[inputSegments[s][0]], result.mergedInto[inputSegments[s][1]]};

  // Split every segment where another one crosses it or ends on its interior.
  std::vector<std::vector<SegmentSplit>> splits(segments.size());
  std::vector<int> crossingPoints;
  auto pointAt = [&points, &crossingPoints, tol2](const Eigen::Vector2d& p) {
    for (int c : crossingPoints)
      if ((points[c] - p).squaredNorm() <= tol2) return c;
    points.push_back(p);
    crossingPoints.push_back(static_cast<int>(points.size()) - 1);
    return crossingPoints.back();
  };
  // Parameter of p on segment s when p lies on its interior (farther than the tolerance from both
  // ends); negative otherwise.
  auto interiorParameter = [&points, &segments, tolerance, tol2](std::size_t s, const Eigen::Vector2d& p) {
    const Eigen::Vector2d a = points[segments[s][0]], b = points[segments[s][1]];
    const Eigen::Vector2d d = b - a;
    const double length2 = d.squaredNorm();
    if (length2 <= tol2) return -1.0;
    const double t = (p - a).dot(d) / length2;
    if (t <= 0.0 || t >= 1.0) return -1.0;
    if ((a + t * d - p).squaredNorm() > tol2) return -1.0;
    if ((p - a).squaredNorm() <= tol2 || (p - b).squaredNorm() <= tol2) return -1.0;
    (void)tolerance;
    return t;
  };
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const Eigen::Vector2d p = points[segments[i][0]], q = points[segments[i][1]];
    const Eigen::Vector2d lo = p.cwiseMin(q).array() - tolerance, hi = p.cwiseMax(q).array() + tolerance;
    for (std::size_t j = i + 1; j < segments.size(); ++j) {
      const Eigen::Vector2d r = points[segments[j][0]], s = points[segments[j][1]];
      if (r.cwiseMax(s).x() < lo.x() || r.cwiseMin(s).x() > hi.x() || r.cwiseMax(s).y() < lo.y() || r.cwiseMin(s).y() > hi.y())
        continue;
      bool met = false;
      for (int end : segments[j])
        if (const double t = interiorParameter(i, points[end]); t > 0.0) {
          splits[i].push_back({t, end});
          met = true;
        }
      for (int end : segments[i])
        if (const double t = interiorParameter(j, points[end]); t > 0.0) {
          splits[j].push_back({t, end});
          met = true;
        }
      const double d1 = crossOf(q - p, r - p), d2 = crossOf(q - p, s - p);
      const double d3 = crossOf(s - r, p - r), d4 = crossOf(s - r, q - r);
      if (!met && ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) {
        const double t = d3 / (d3 - d4);
        const Eigen::Vector2d x = p + t * (q - p);
        const double u = (x - r).dot(s - r) / (s - r).squaredNorm();
        const bool nearEnd = (x - p).squaredNorm() <= tol2 || (x - q).squaredNorm() <= tol2 ||
                             (x - r).squaredNorm() <= tol2 || (x - s).squaredNorm() <= tol2;
        if (!nearEnd) {
          const int c = pointAt(x);
          splits[i].push_back({t, c});
          splits[j].push_back({u, c});
          met = true;
        }
      }
      if (met) result.crossings.push_back({static_cast<int>(i), static_cast<int>(j)});
    }
  }

  // Pieces, without repeats (an overlap yields the same piece twice) and without zero lengths.
  std::map<std::pair<int, int>, int> pieceOfPair;
  std::vector<std::array<int, 2>> pieces;
  std::vector<int> sourceOfPiece;
  for (std::size_t s = 0; s < segments.size(); ++s) {
    auto& cuts = splits[s];
    std::sort(cuts.begin(), cuts.end(), [](const SegmentSplit& a, const SegmentSplit& b) { return a.t < b.t; });
    std::vector<int> chain{segments[s][0]};
    for (const SegmentSplit& c : cuts)
      if (c.point != chain.back()) chain.push_back(c.point);
    if (segments[s][1] != chain.back()) chain.push_back(segments[s][1]);
    for (std::size_t k = 0; k + 1 < chain.size(); ++k) {
      const int a = chain[k], b = chain[k + 1];
      if (a == b || (points[a] - points[b]).squaredNorm() <= tol2) continue;
      const auto key = std::minmax(a, b);
      if (pieceOfPair.count(key)) continue;
      pieceOfPair[key] = static_cast<int>(pieces.size());
      pieces.push_back({a, b});
      sourceOfPiece.push_back(static_cast<int>(s));
    }
  }

  // Drop dangling pieces, repeatedly.
  const int pointCount = static_cast<int>(points.size());
  std::vector<std::vector<int>> piecesAt(pointCount);
  for (std::size_t k = 0; k < pieces.size(); ++k)
    for (int end : pieces[k]) piecesAt[end].push_back(static_cast<int>(k));
  std::vector<bool> alive(pieces.size(), true);
  std::vector<int> degree(pointCount);
  for (int v = 0; v < pointCount; ++v) degree[v] = static_cast<int>(piecesAt[v].size());
  std::vector<int> leaves;
  for (int v = 0; v < pointCount; ++v)
    if (degree[v] == 1) leaves.push_back(v);
  while (!leaves.empty()) {
    const int v = leaves.back();
    leaves.pop_back();
    for (int k : piecesAt[v]) {
      if (!alive[k]) continue;
      alive[k] = false;
      for (int end : pieces[k])
        if (--degree[end] == 1) leaves.push_back(end);
    }
  }

  // Connected components of what is left; keep the one with the largest outer boundary.
  std::vector<int> parent(pointCount);
  std::iota(parent.begin(), parent.end(), 0);
  for (std::size_t k = 0; k < pieces.size(); ++k)
    if (alive[k]) parent[findRoot(parent, pieces[k][0])] = findRoot(parent, pieces[k][1]);

  // Half-edges 2k (a → b) and 2k + 1 (b → a); outgoing ones per point sorted counter-clockwise.
  const int halfEdges = 2 * static_cast<int>(pieces.size());
  auto origin = [&pieces](int h) { return pieces[h / 2][h % 2]; };
  auto target = [&pieces](int h) { return pieces[h / 2][1 - h % 2]; };
  std::vector<std::vector<int>> outgoing(pointCount);
  for (int h = 0; h < halfEdges; ++h)
    if (alive[h / 2]) outgoing[origin(h)].push_back(h);
  std::vector<int> positionAtOrigin(halfEdges, -1);
  for (int v = 0; v < pointCount; ++v) {
    auto& out = outgoing[v];
    std::vector<double> angle(halfEdges);
    for (int h : out) {
      const Eigen::Vector2d d = points[target(h)] - points[v];
      angle[h] = std::atan2(d.y(), d.x());
    }
    std::sort(out.begin(), out.end(), [&angle](int a, int b) { return angle[a] < angle[b]; });
    for (std::size_t k = 0; k < out.size(); ++k) positionAtOrigin[out[k]] = static_cast<int>(k);
  }
  auto next = [&outgoing, &positionAtOrigin, &target](int h) {
    const int v = target(h), twin = h ^ 1;
    const auto& out = outgoing[v];
    const int k = positionAtOrigin[twin];
    return out[(k + static_cast<int>(out.size()) - 1) % static_cast<int>(out.size())];
  };
  Eigen::MatrixX2d pointMatrix(pointCount, 2);
  for (int v = 0; v < pointCount; ++v) pointMatrix.row(v) = points[v].transpose();
  std::vector<bool> visited(halfEdges, false);
  std::vector<std::vector<int>> bounded;
  std::map<int, std::vector<int>> outerOfComponent;
  std::map<int, double> outerArea;
  for (int h0 = 0; h0 < halfEdges; ++h0) {
    if (!alive[h0 / 2] || visited[h0]) continue;
    std::vector<int> loop;
    int h = h0;
    do {
      visited[h] = true;
      loop.push_back(origin(h));
      h = next(h);
    } while (h != h0 && loop.size() <= static_cast<std::size_t>(halfEdges));
    const double area2 = loopSignedArea2(pointMatrix, loop);
    if (area2 > 0.0) {
      bounded.push_back(std::move(loop));
    } else {
      const int component = findRoot(parent, loop.front());
      if (!outerArea.count(component) || -area2 > outerArea[component]) {
        outerArea[component] = -area2;
        outerOfComponent[component] = std::move(loop);
      }
    }
  }
  int kept = -1;
  for (const auto& [component, area] : outerArea)
    if (kept < 0 || area > outerArea[kept]) kept = component;
  for (const auto& [component, loop] : outerOfComponent)
    if (component != kept && pointInLoop(pointMatrix, outerOfComponent[kept], pointMatrix.row(loop.front()).transpose()))
      ++result.islands;

  std::vector<bool> used(segments.size(), false);
  for (auto& loop : bounded) {
    if (findRoot(parent, loop.front()) != kept) continue;
    std::vector<int> sorted = loop;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
      ++result.pinchedFaces;
      continue;
    }
    result.faces.push_back(std::move(loop));
  }
  // Keep the pieces on the kept faces, renumbering nothing: points stay as they are.
  std::map<std::pair<int, int>, bool> onFace;
  for (const auto& loop : result.faces)
    for (std::size_t k = 0; k < loop.size(); ++k) onFace[std::minmax(loop[k], loop[(k + 1) % loop.size()])] = true;
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    if (!onFace.count(std::minmax(pieces[k][0], pieces[k][1]))) continue;
    result.segments.push_back(pieces[k]);
    result.sourceOfSegment.push_back(sourceOfPiece[k]);
    used[sourceOfPiece[k]] = true;
  }
  for (std::size_t s = 0; s < segments.size(); ++s)
    if (!used[s]) result.unusedSegments.push_back(static_cast<int>(s));
  result.points = std::move(pointMatrix);
  return result;
}

}  // namespace devsurf::spatial
