#include "devsurf/spatial/PlanarArrangement.h"

#include <algorithm>
#include <limits>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>
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
                                    const PlanarArrangementOptions& options) {
  double tolerance = options.tolerance;
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

  // Connected components of what is left, and the faces of every component (each half-edge
  // followed by the next one clockwise around its end point): bounded loops, and per component its
  // outer loop (the one of largest negative area).
  struct FaceWalk {
    std::vector<int> parent;
    std::vector<std::vector<int>> bounded;
    std::map<int, std::vector<int>> outerOfComponent;
    std::map<int, double> outerArea;
    int kept = -1;
  };
  Eigen::MatrixX2d pointMatrix;
  const auto walkFaces = [&points, &pieces, &alive, &pointMatrix]() {
    FaceWalk walk;
    const int pointCount = static_cast<int>(points.size());
    walk.parent.resize(pointCount);
    std::iota(walk.parent.begin(), walk.parent.end(), 0);
    for (std::size_t k = 0; k < pieces.size(); ++k)
      if (alive[k]) walk.parent[findRoot(walk.parent, pieces[k][0])] = findRoot(walk.parent, pieces[k][1]);
    // Half-edges 2k (a → b) and 2k + 1 (b → a); outgoing ones per point sorted counter-clockwise.
    const int halfEdges = 2 * static_cast<int>(pieces.size());
    const auto origin = [&pieces](int h) { return pieces[h / 2][h % 2]; };
    const auto target = [&pieces](int h) { return pieces[h / 2][1 - h % 2]; };
    std::vector<std::vector<int>> outgoing(pointCount);
    for (int h = 0; h < halfEdges; ++h)
      if (alive[h / 2]) outgoing[origin(h)].push_back(h);
    std::vector<int> positionAtOrigin(halfEdges, -1);
    std::vector<double> angle(halfEdges);
    for (int v = 0; v < pointCount; ++v) {
      auto& out = outgoing[v];
      for (int h : out) {
        const Eigen::Vector2d d = points[target(h)] - points[v];
        angle[h] = std::atan2(d.y(), d.x());
      }
      std::sort(out.begin(), out.end(), [&angle](int a, int b) { return angle[a] < angle[b]; });
      for (std::size_t k = 0; k < out.size(); ++k) positionAtOrigin[out[k]] = static_cast<int>(k);
    }
    const auto next = [&outgoing, &positionAtOrigin, &target](int h) {
      const auto& out = outgoing[target(h)];
      const int k = positionAtOrigin[h ^ 1];
      return out[(k + static_cast<int>(out.size()) - 1) % static_cast<int>(out.size())];
    };
    pointMatrix.resize(pointCount, 2);
    for (int v = 0; v < pointCount; ++v) pointMatrix.row(v) = points[v].transpose();
    std::vector<bool> visited(halfEdges, false);
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
        walk.bounded.push_back(std::move(loop));
      } else {
        const int component = findRoot(walk.parent, loop.front());
        if (!walk.outerArea.count(component) || -area2 > walk.outerArea[component]) {
          walk.outerArea[component] = -area2;
          walk.outerOfComponent[component] = std::move(loop);
        }
      }
    }
    for (const auto& [component, area] : walk.outerArea)
      if (walk.kept < 0 || area > walk.outerArea[walk.kept]) walk.kept = component;
    return walk;
  };
  FaceWalk walk = walkFaces();
  // Components inside the kept one's outer loop: islands; the others are separate sheets.
  const auto islandsOf = [&pointMatrix](const FaceWalk& w) {
    std::vector<int> inside;
    if (w.kept < 0) return inside;
    for (const auto& [component, loop] : w.outerOfComponent)
      if (component != w.kept && pointInLoop(pointMatrix, w.outerOfComponent.at(w.kept), pointMatrix.row(loop.front()).transpose()))
        inside.push_back(component);
    return inside;
  };
  std::vector<int> islands = islandsOf(walk);

  if (options.bridgeIslands && !islands.empty()) {
    // Outer islands first: one inside another is bridged to it once it is joined.
    std::sort(islands.begin(), islands.end(),
              [&walk](int a, int b) { return walk.outerArea.at(a) > walk.outerArea.at(b); });
    std::vector<bool> joined(points.size(), false);  // per component root: joined to the sheet
    joined[static_cast<std::size_t>(walk.kept)] = true;
    std::vector<bool> isBridge(pieces.size(), false);
    // Whether the segment p–q crosses or touches an alive piece other than those the caller
    // allows (the pieces at its ends).
    const auto blocked = [&points, &pieces, &alive, tolerance](const Eigen::Vector2d& p, const Eigen::Vector2d& q,
                                                               const std::vector<int>& allowed) {
      const Eigen::Vector2d lo = p.cwiseMin(q).array() - tolerance, hi = p.cwiseMax(q).array() + tolerance;
      for (std::size_t k = 0; k < pieces.size(); ++k) {
        if (!alive[k] || std::find(allowed.begin(), allowed.end(), static_cast<int>(k)) != allowed.end()) continue;
        const Eigen::Vector2d r = points[pieces[k][0]], s = points[pieces[k][1]];
        if (r.cwiseMax(s).x() < lo.x() || r.cwiseMin(s).x() > hi.x() || r.cwiseMax(s).y() < lo.y() || r.cwiseMin(s).y() > hi.y())
          continue;
        // Distance between the two segments (zero when they cross) below the tolerance.
        const double d1 = crossOf(q - p, r - p), d2 = crossOf(q - p, s - p);
        const double d3 = crossOf(s - r, p - r), d4 = crossOf(s - r, q - r);
        if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
        const auto pointToSegment = [](const Eigen::Vector2d& x, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
          const Eigen::Vector2d d = b - a;
          const double t = d.squaredNorm() > 0.0 ? std::clamp((x - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
          return (a + t * d - x).norm();
        };
        if (std::min({pointToSegment(r, p, q), pointToSegment(s, p, q), pointToSegment(p, r, s), pointToSegment(q, r, s)}) <=
            tolerance)
          return true;
      }
      return false;
    };
    struct BridgeCandidate {
      double length = 0.0;  ///< its length, divided by 1.5 when it ends where an earlier bridge ends
      int from = -1;       ///< island point
      int position = -1;   ///< its index on the island's outer loop
      int piece = -1;      ///< the piece it ends on
      double t = 0.0;      ///< where along the piece (0 or 1: at its ends)
    };
    // Work bound: every island weighs its outline's points times the pieces (the candidates it
    // sorts, and then some visibility tests); past kBridgeWork the remaining islands are left out,
    // as without bridging (a perforated sheet of thousands of tiny loops would otherwise take
    // minutes).
    constexpr double kBridgeWork = 4e7;
    double work = 0.0;
    // Candidates tested per bridge: the kFirstTried shortest (each costs a pass over the pieces,
    // and a bridge not among them would be long and crooked anyway) — all of them, in order, in a
    // last round for the islands whose first ones were all blocked (a regular grid of holes: every
    // one of its 96 shortest can be blocked by a point's rounding), their tests counted as work.
    constexpr std::size_t kFirstTried = 96;
    std::size_t maxTried = kFirstTried;
    // Whether a bridge may leave or end beside an earlier bridge (a sliver between the two): only
    // in a final round, for islands that have no other way out (better a sliver than a hole the
    // import leaves out).
    bool besideBridges = false;
    // The shortest bridge from the loop's points (those `from` allows) to a joined piece that
    // crosses nothing, ending farther than the tolerance from `notAt`; nullopt when none fits.
    const auto shortestBridge = [&](const std::vector<int>& loop, const std::function<bool(std::size_t)>& from,
                                    const Eigen::Vector2d* notAt) -> std::optional<BridgeCandidate> {
      // Whether direction d leaves the island at its point i: the outer loop has the outside on
      // its left, so d must lie in the wedge turning counter-clockwise from the next edge to the
      // reversed previous one (10° clear of both).
      const auto leavesOutward = [&points, &loop](std::size_t i, const Eigen::Vector2d& d) {
        const std::size_t n = loop.size();
        const Eigen::Vector2d x = points[loop[i]];
        const Eigen::Vector2d next = points[loop[(i + 1) % n]] - x, back = points[loop[(i + n - 1) % n]] - x;
        const auto angleFrom = [](const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
          double a = std::atan2(from.x() * to.y() - from.y() * to.x(), from.dot(to));
          return a < 0.0 ? a + 2.0 * M_PI : a;
        };
        const double wedge = angleFrom(next, back), at = angleFrom(next, d);
        const double margin = 10.0 * M_PI / 180.0;
        return at > margin && at < wedge - margin;
      };
      std::vector<BridgeCandidate> candidates;
      for (std::size_t i = 0; i < loop.size(); ++i) {
        if (!from(i)) continue;
        const Eigen::Vector2d x = points[loop[i]];
        for (std::size_t k = 0; k < pieces.size(); ++k) {
          if (!alive[k] || isBridge[k] || !joined[static_cast<std::size_t>(findRoot(walk.parent, pieces[k][0]))]) continue;
          const Eigen::Vector2d a = points[pieces[k][0]], b = points[pieces[k][1]], d = b - a;
          double t = std::clamp((x - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
          if ((a + t * d - a).squaredNorm() <= tol2) t = 0.0;
          if ((a + t * d - b).squaredNorm() <= tol2) t = 1.0;
          const Eigen::Vector2d end = a + t * d;
          if ((!notAt || (end - *notAt).squaredNorm() > tol2) && leavesOutward(i, end - x))
            candidates.push_back({(end - x).norm(), loop[i], static_cast<int>(i), static_cast<int>(k), t});
          // The piece's ends too (a corner around the island may be the only end that leaves the
          // island steeply enough when its nearest points run on along its sides).
          if (t != 0.0 && (!notAt || (a - *notAt).squaredNorm() > tol2) && leavesOutward(i, a - x))
            candidates.push_back({(a - x).norm(), loop[i], static_cast<int>(i), static_cast<int>(k), 0.0});
          if (t != 1.0 && (!notAt || (b - *notAt).squaredNorm() > tol2) && leavesOutward(i, b - x))
            candidates.push_back({(b - x).norm(), loop[i], static_cast<int>(i), static_cast<int>(k), 1.0});
        }
      }
      // Ends of earlier bridges are preferred (a bridge up to 1.5× longer ending there wins): nested
      // islands are then joined along one line of rulings (concentric creases: radial rulings from
      // ring to ring) rather than leaving corners in the middle of each other's curves.
      for (std::size_t k = 0; k < pieces.size(); ++k) {
        if (!alive[k] || !isBridge[k]) continue;
        for (const int end : pieces[k]) {
          int along = -1;
          for (int j : piecesAt[static_cast<std::size_t>(end)])
            if (alive[static_cast<std::size_t>(j)] && !isBridge[static_cast<std::size_t>(j)] &&
                joined[static_cast<std::size_t>(findRoot(walk.parent, pieces[static_cast<std::size_t>(j)][0]))])
              along = j;
          if (along < 0 || (notAt && (points[end] - *notAt).squaredNorm() <= tol2)) continue;
          const double t = pieces[static_cast<std::size_t>(along)][0] == end ? 0.0 : 1.0;
          for (std::size_t i = 0; i < loop.size(); ++i) {
            if (!from(i) || !leavesOutward(i, points[end] - points[loop[i]])) continue;
            candidates.push_back({(points[end] - points[loop[i]]).norm() / 1.5, loop[i], static_cast<int>(i), along, t});
          }
        }
      }
      // The maxTried shortest, in order.
      const auto shorter = [](const BridgeCandidate& a, const BridgeCandidate& b) { return a.length < b.length; };
      if (candidates.size() > maxTried) {
        std::nth_element(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(maxTried), candidates.end(),
                         shorter);
        candidates.resize(maxTried);
      }
      std::sort(candidates.begin(), candidates.end(), shorter);
      std::size_t tried = 0;
      for (const BridgeCandidate& c : candidates) {
        if (c.length <= tolerance) continue;
        if (tried++ >= kFirstTried) {
          work += static_cast<double>(pieces.size());
          if (work > kBridgeWork) return std::nullopt;
        }
        const auto& piece = pieces[static_cast<std::size_t>(c.piece)];
        const Eigen::Vector2d end = points[piece[0]] + c.t * (points[piece[1]] - points[piece[0]]);
        std::vector<int> allowed = piecesAt[static_cast<std::size_t>(c.from)];
        allowed.push_back(c.piece);
        if (c.t == 0.0 || c.t == 1.0)
          for (int k : piecesAt[static_cast<std::size_t>(piece[c.t == 0.0 ? 0 : 1])]) allowed.push_back(k);
        // A bridge leaves its island and meets what it ends on at 10° or more to every piece there:
        // one running on along a side would give its face a straight angle at the bridge's foot,
        // one grazing a piece a sliver of a face. `leaving`: the new bridge's direction away from
        // the point the piece is at.
        const Eigen::Vector2d along = (end - points[c.from]).normalized();
        const double minSine = std::sin(10.0 * M_PI / 180.0);
        const auto grazes = [&points, &pieces, &alive, &isBridge, &besideBridges, minSine](
                                const Eigen::Vector2d& at, int k, const Eigen::Vector2d& leaving) {
          if (!alive[static_cast<std::size_t>(k)] || (besideBridges && isBridge[static_cast<std::size_t>(k)])) return false;
          const auto& ends = pieces[static_cast<std::size_t>(k)];
          const Eigen::Vector2d away = (points[ends[0]] - at).squaredNorm() >= (points[ends[1]] - at).squaredNorm()
                                           ? Eigen::Vector2d(points[ends[0]] - at)
                                           : Eigen::Vector2d(points[ends[1]] - at);
          const Eigen::Vector2d u = away.normalized();
          const bool narrow = std::abs(u.x() * leaving.y() - u.y() * leaving.x()) < minSine;
          // Running on through an earlier bridge (nearly straight on) is what the preference for
          // their ends is for; leaving beside it, nearly along it, cuts a sliver between the two.
          if (isBridge[static_cast<std::size_t>(k)]) return narrow && u.dot(leaving) > 0.0;
          return narrow;
        };
        bool steep = true;
        for (int k : piecesAt[static_cast<std::size_t>(c.from)]) steep = steep && !grazes(points[c.from], k, along);
        if (c.t == 0.0 || c.t == 1.0) {
          const int at = piece[c.t == 0.0 ? 0 : 1];
          for (int k : piecesAt[static_cast<std::size_t>(at)]) steep = steep && !grazes(points[at], k, -along);
        } else {
          steep = steep && !grazes(end, c.piece, -along);
        }
        if (steep && !blocked(points[c.from], end, allowed)) return c;
      }
      return std::nullopt;
    };
    const auto addPiece = [&pieces, &sourceOfPiece, &alive, &isBridge, &piecesAt](int a, int b, int source, bool bridge) {
      const int k = static_cast<int>(pieces.size());
      pieces.push_back({a, b});
      sourceOfPiece.push_back(source);
      alive.push_back(true);
      isBridge.push_back(bridge);
      piecesAt[static_cast<std::size_t>(a)].push_back(k);
      piecesAt[static_cast<std::size_t>(b)].push_back(k);
    };
    // Adds the bridge (splitting the piece it ends on inside) and returns where it ends.
    const auto addBridge = [&](const BridgeCandidate& c) {
      const int k = c.piece;
      const int a = pieces[static_cast<std::size_t>(k)][0], b = pieces[static_cast<std::size_t>(k)][1];
      int end = c.t == 0.0 ? a : c.t == 1.0 ? b : -1;
      if (end < 0) {
        end = static_cast<int>(points.size());
        points.push_back(points[a] + c.t * (points[b] - points[a]));
        piecesAt.emplace_back();
        walk.parent.push_back(findRoot(walk.parent, a));
        joined.push_back(false);
        auto& atB = piecesAt[static_cast<std::size_t>(b)];
        atB.erase(std::find(atB.begin(), atB.end(), k));
        pieces[static_cast<std::size_t>(k)][1] = end;
        piecesAt[static_cast<std::size_t>(end)].push_back(k);
        addPiece(end, b, sourceOfPiece[static_cast<std::size_t>(k)], false);
      }
      addPiece(c.from, end, -1, true);
      return points[end];
    };
    // Passes until one joins nothing: an island whose only clear way out runs past islands not yet
    // joined is tried again once they are.
    std::vector<bool> done(islands.size(), false);
    for (bool progress = true; progress && work <= kBridgeWork;) {
      progress = false;
      for (std::size_t which = 0; which < islands.size() && work <= kBridgeWork; ++which) {
        if (done[which]) continue;
        const int island = islands[which];
        const std::vector<int>& loop = walk.outerOfComponent.at(island);
        work += 3.0 * static_cast<double>(loop.size()) * static_cast<double>(pieces.size());
        if (work > kBridgeWork) break;
        const std::optional<BridgeCandidate> first =
            shortestBridge(loop, [](std::size_t /*anywhere*/) { return true; }, nullptr);
        if (!first) continue;
        const Eigen::Vector2d firstEnd = points[pieces[first->piece][0]] +
                                         first->t * (points[pieces[first->piece][1]] - points[pieces[first->piece][0]]);
        // The second bridge must not cross the first: it is alive (and not a joined piece to end on).
        const int before = static_cast<int>(pieces.size());
        addBridge(*first);
        // It leaves the island on the far side (seen from the island's centroid, at least 120° from
        // the first), so the two split what surrounds the island in two; failing that, from a point
        // at least a third of the island's outline away. (Asking it also to head the other way
        // from the first, so the two cut across what surrounds the island, left more faces without
        // a ruling layout: 36 of 120 random sheets with a hole against 17.)
        Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
        for (int v : loop) centroid += points[v];
        centroid /= static_cast<double>(loop.size());
        const Eigen::Vector2d firstOut = points[first->from] - centroid;
        const auto farSide = [&points, &loop, &centroid, &firstOut, &first](std::size_t i) {
          const Eigen::Vector2d out = points[loop[i]] - centroid;
          return i != static_cast<std::size_t>(first->position) && out.dot(firstOut) <= -0.5 * out.norm() * firstOut.norm();
        };
        const std::size_t minGap = std::max<std::size_t>(1, loop.size() / 3);
        const auto farAlong = [&loop, minGap, &first](std::size_t i) {
          const std::size_t gap = (i + loop.size() - static_cast<std::size_t>(first->position)) % loop.size();
          return std::min(gap, loop.size() - gap) >= minGap;
        };
        std::optional<BridgeCandidate> second = shortestBridge(loop, farSide, &firstEnd);
        if (!second) second = shortestBridge(loop, farAlong, &firstEnd);
        if (!second) {
          // Undo the first bridge (the island stays out): its piece dies; a split piece stays split.
          for (int k = before; k < static_cast<int>(pieces.size()); ++k)
            if (isBridge[static_cast<std::size_t>(k)]) alive[static_cast<std::size_t>(k)] = false;
          continue;
        }
        addBridge(*second);
        joined[static_cast<std::size_t>(island)] = true;
        done[which] = true;
        progress = true;
        ++result.bridgedIslands;
      }
      // Nothing more joined with the shortest candidates: a last round with all of them.
      if (!progress && maxTried == kFirstTried && std::find(done.begin(), done.end(), false) != done.end()) {
        maxTried = std::numeric_limits<std::size_t>::max();
        progress = true;
      } else if (!progress && !besideBridges && std::find(done.begin(), done.end(), false) != done.end()) {
        besideBridges = true;  // and, failing that, beside earlier bridges too
        progress = true;
      }
    }
    walk = walkFaces();
    islands = islandsOf(walk);
  }
  result.islands = static_cast<int>(islands.size());
  const int kept = walk.kept;

  std::vector<bool> used(segments.size(), false);
  for (auto& loop : walk.bounded) {
    if (findRoot(walk.parent, loop.front()) != kept) continue;
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
    if (!alive[k] || !onFace.count(std::minmax(pieces[k][0], pieces[k][1]))) continue;
    if (sourceOfPiece[k] < 0) result.bridges.push_back(static_cast<int>(result.segments.size()));
    result.segments.push_back(pieces[k]);
    result.sourceOfSegment.push_back(sourceOfPiece[k]);
    if (sourceOfPiece[k] >= 0) used[static_cast<std::size_t>(sourceOfPiece[k])] = true;
  }
  for (std::size_t s = 0; s < segments.size(); ++s)
    if (!used[s]) result.unusedSegments.push_back(static_cast<int>(s));
  if (kept >= 0) result.outline = walk.outerOfComponent.at(kept);
  result.points = std::move(pointMatrix);
  return result;
}

PlanarArrangement planarArrangement(const Eigen::MatrixX2d& points, const std::vector<std::array<int, 2>>& segments,
                                    double tolerance) {
  PlanarArrangementOptions options;
  options.tolerance = tolerance;
  return planarArrangement(points, segments, options);
}

std::vector<bool> holeFaces(const std::vector<std::vector<int>>& faces, const std::vector<int>& outline,
                            const std::function<bool(int, int)>& isWall) {
  std::map<std::pair<int, int>, std::vector<int>> facesOfEdge;
  for (std::size_t f = 0; f < faces.size(); ++f)
    for (std::size_t k = 0; k < faces[f].size(); ++k)
      facesOfEdge[std::minmax(faces[f][k], faces[f][(k + 1) % faces[f].size()])].push_back(static_cast<int>(f));
  std::vector<bool> reached(faces.size(), false);
  std::vector<int> stack;
  for (std::size_t k = 0; k < outline.size(); ++k) {
    const auto it = facesOfEdge.find(std::minmax(outline[k], outline[(k + 1) % outline.size()]));
    if (it == facesOfEdge.end()) continue;
    for (int f : it->second)
      if (!reached[static_cast<std::size_t>(f)]) {
        reached[static_cast<std::size_t>(f)] = true;
        stack.push_back(f);
      }
  }
  while (!stack.empty()) {
    const int f = stack.back();
    stack.pop_back();
    const auto& loop = faces[static_cast<std::size_t>(f)];
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const auto edge = std::minmax(loop[k], loop[(k + 1) % loop.size()]);
      const auto& around = facesOfEdge[edge];
      if (around.size() != 2 || isWall(edge.first, edge.second)) continue;
      const int other = around[0] == f ? around[1] : around[0];
      if (reached[static_cast<std::size_t>(other)]) continue;
      reached[static_cast<std::size_t>(other)] = true;
      stack.push_back(other);
    }
  }
  std::vector<bool> hole(faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f) hole[f] = !reached[f];
  return hole;
}

int cutOutHoles(PlanarArrangement& arrangement, const std::function<bool(int)>& isWallSource) {
  std::map<std::pair<int, int>, int> sourceOfPair;
  for (std::size_t s = 0; s < arrangement.segments.size(); ++s)
    sourceOfPair[std::minmax(arrangement.segments[s][0], arrangement.segments[s][1])] = arrangement.sourceOfSegment[s];
  const auto isWall = [&sourceOfPair, &isWallSource](int a, int b) {
    const auto it = sourceOfPair.find(std::minmax(a, b));
    return it != sourceOfPair.end() && it->second >= 0 && isWallSource(it->second);
  };
  std::vector<bool> hole = holeFaces(arrangement.faces, arrangement.outline, isWall);
  // A walled-off region with a drawn edge inside it (not a wall, not a bridge) is not a hole: a
  // hole holds no creases (an outline drawn twice, a frame drawn inside the sheet); its walls
  // stay what they were (cuts).
  {
    std::map<std::pair<int, int>, std::vector<int>> facesOfEdge;
    for (std::size_t f = 0; f < arrangement.faces.size(); ++f)
      if (hole[f])
        for (std::size_t k = 0; k < arrangement.faces[f].size(); ++k)
          facesOfEdge[std::minmax(arrangement.faces[f][k], arrangement.faces[f][(k + 1) % arrangement.faces[f].size()])]
              .push_back(static_cast<int>(f));
    std::vector<int> region(arrangement.faces.size(), -1);
    std::vector<bool> holdsCrease;
    for (std::size_t start = 0; start < arrangement.faces.size(); ++start) {
      if (!hole[start] || region[start] >= 0) continue;
      const int id = static_cast<int>(holdsCrease.size());
      holdsCrease.push_back(false);
      std::vector<int> stack{static_cast<int>(start)};
      region[start] = id;
      while (!stack.empty()) {
        const auto& loop = arrangement.faces[static_cast<std::size_t>(stack.back())];
        const int f = stack.back();
        stack.pop_back();
        for (std::size_t k = 0; k < loop.size(); ++k) {
          const auto edge = std::minmax(loop[k], loop[(k + 1) % loop.size()]);
          const auto& around = facesOfEdge[edge];
          if (around.size() != 2 || isWall(edge.first, edge.second)) continue;
          const auto source = sourceOfPair.find(edge);
          if (source != sourceOfPair.end() && source->second >= 0) holdsCrease[static_cast<std::size_t>(id)] = true;
          const int other = around[0] == f ? around[1] : around[0];
          if (region[static_cast<std::size_t>(other)] < 0) {
            region[static_cast<std::size_t>(other)] = id;
            stack.push_back(other);
          }
        }
      }
    }
    for (std::size_t f = 0; f < hole.size(); ++f)
      if (hole[f] && holdsCrease[static_cast<std::size_t>(region[f])]) hole[f] = false;
  }
  const auto holes = static_cast<int>(std::count(hole.begin(), hole.end(), true));
  if (holes == 0 || holes == static_cast<int>(hole.size())) return 0;
  std::vector<std::vector<int>> sheet;
  for (std::size_t f = 0; f < hole.size(); ++f)
    if (!hole[f]) sheet.push_back(std::move(arrangement.faces[f]));
  arrangement.faces = std::move(sheet);
  return holes;
}

}  // namespace devsurf::spatial
