#include "devsurf/models/quad_mesh/SegmentedApproximation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "devsurf/spatial/SegmentSetProximity.h"
#include "devsurf/spatial/TriangleMeshProximity.h"

namespace devsurf::models::quad_mesh {
namespace {

[[noreturn]] void failSegmentation(const std::string& why) {
  throw std::invalid_argument("segmentedApproximation: " + why);
}

/// A grid node of the parameter plane found inside the map: its triangle and barycentric weights.
struct NodeHit {
  bool inside = false;
  /// Outside the map but within reach of its boundary: `at` is the boundary's closest point.
  bool snapped = false;
  Eigen::Vector2d at = Eigen::Vector2d::Zero();  ///< where the node is in the map
  int triangle = -1;
  Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();
};

Eigen::Vector3d barycentricIn(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                              const Eigen::Vector2d& c) {
  const Eigen::Vector2d e0 = b - a, e1 = c - a, d = p - a;
  const double det = e0.x() * e1.y() - e0.y() * e1.x();
  const double s = (d.x() * e1.y() - d.y() * e1.x()) / det;
  const double t = (e0.x() * d.y() - e0.y() * d.x()) / det;
  Eigen::Vector3d w(1.0 - s - t, s, t);
  w = w.cwiseMax(0.0);
  return w / w.sum();
}

/// Fans around a grid node: the faces of one piece at the node, grouped where consecutive ones (in
/// the node's cyclic order c00, c10, c11, c01) share the grid edge between them. `inPiece[s]`:
/// slot s holds a face of the piece that uses the node; `linked[s]`: slots s and s+1 share their
/// edge (both faces have it). Returns each slot's fan index, or −1.
std::array<int, 4> fansAround(const std::array<bool, 4>& inPiece, const std::array<bool, 4>& linked) {
  std::array<int, 4> fan = {-1, -1, -1, -1};
  int fans = 0;
  for (int s = 0; s < 4; ++s) {
    if (!inPiece[s] || fan[s] >= 0) continue;
    fan[s] = fans;
    for (int step : {1, 3}) {  // walk both ways while linked
      int at = s;
      for (int k = 0; k < 3; ++k) {
        const int link = step == 1 ? at : (at + 3) % 4;
        const int next = (at + step) % 4;
        if (!linked[link] || !inPiece[next] || fan[next] >= 0) break;
        fan[next] = fans;
        at = next;
      }
    }
    ++fans;
  }
  return fan;
}

}  // namespace

SegmentedApproximation segmentedApproximation(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& T,
                                              const std::vector<int>& trianglePatch,
                                              const SegmentedApproximationOptions& options) {
  if (static_cast<Eigen::Index>(trianglePatch.size()) != T.rows())
    failSegmentation("patch ids: " + std::to_string(trianglePatch.size()) + " values for " + std::to_string(T.rows()) +
         " triangles");
  for (std::size_t t = 0; t < trianglePatch.size(); ++t)
    if (trianglePatch[t] < 0) failSegmentation("patch ids[" + std::to_string(t) + "] is negative");
  if (options.targetFaces < 1 && !(options.spacing > 0.0)) failSegmentation("targetFaces must be ≥ 1");
  if (!(options.spread >= 0.0) || !std::isfinite(options.spread)) failSegmentation("spread must be ≥ 0");

  Eigen::MatrixX2d uv = spatial::parameterizeDisk(V, T, options.method);
  {
    // Turn the map so that the lines a user sees run along the grid: the borders between patches
    // (a segmentation following a feature, e.g. a box's edges) and the reference's boundary, by
    // the length-weighted mean of their directions modulo 90° (4φ averaged on the circle). A line
    // across the grid becomes a staircase whose corners stand up to h/√2 off it.
    std::map<std::pair<int, int>, int> edgeUse;
    for (Eigen::Index t = 0; t < T.rows(); ++t)
      for (int k = 0; k < 3; ++k) ++edgeUse[std::minmax(T(t, k), T(t, (k + 1) % 3))];
    std::map<std::pair<int, int>, int> firstPatch;
    double sx = 0.0, sy = 0.0;
    auto addDirection = [&sx, &sy, &uv](int a, int b, double weight) {
      const Eigen::Vector2d e = uv.row(b) - uv.row(a);
      const double phi = std::atan2(e.y(), e.x());
      sx += weight * e.norm() * std::cos(4.0 * phi);
      sy += weight * e.norm() * std::sin(4.0 * phi);
    };
    for (Eigen::Index t = 0; t < T.rows(); ++t)
      for (int k = 0; k < 3; ++k) {
        const auto key = std::minmax(T(t, k), T(t, (k + 1) % 3));
        if (edgeUse[key] == 1) addDirection(key.first, key.second, 1.0);
        const auto [it, inserted] = firstPatch.emplace(key, trianglePatch[t]);
        if (!inserted && it->second != trianglePatch[t]) addDirection(key.first, key.second, 2.0);  // borders count double
      }
    const double angle = (sx != 0.0 || sy != 0.0) ? -0.25 * std::atan2(sy, sx) : 0.0;
    uv = (uv * Eigen::Rotation2Dd(angle).toRotationMatrix().transpose()).eval();
  }
  double area = 0.0;
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    const Eigen::Vector3d a = V.row(T(t, 0)), b = V.row(T(t, 1)), c = V.row(T(t, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  const double h = options.spacing > 0.0 ? options.spacing : std::sqrt(area / options.targetFaces);
  if (!(h > 0.0) || !std::isfinite(h)) failSegmentation("the quad spacing is not positive");

  // Point location in the map: the AABB tree over the map's triangles (lifted to z = 0).
  Eigen::MatrixX3d planar = Eigen::MatrixX3d::Zero(V.rows(), 3);
  planar.leftCols<2>() = uv;
  std::optional<spatial::TriangleMeshProximity> locator;
  try {
    locator.emplace(planar, T);
  } catch (const std::invalid_argument& e) {
    failSegmentation(std::string("the map to the plane has a degenerate triangle (") + e.what() + ")");
  }

  std::vector<char> used(V.rows(), 0);
  for (Eigen::Index t = 0; t < T.rows(); ++t)
    for (int k = 0; k < 3; ++k) used[T(t, k)] = 1;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = Eigen::Vector2d::Constant(-1e300);
  for (Eigen::Index v = 0; v < V.rows(); ++v)
    if (used[v]) lo = lo.cwiseMin(uv.row(v).transpose()), hi = hi.cwiseMax(uv.row(v).transpose());
  const Eigen::Vector2d extent = hi - lo;
  // One cell beyond the map on every side: nodes there snap onto its boundary.
  const long nx = static_cast<long>(std::ceil(extent.x() / h)) + 2, ny = static_cast<long>(std::ceil(extent.y() / h)) + 2;
  if (extent.x() < h || extent.y() < h) failSegmentation("the quad spacing is larger than the reference's map");
  if ((nx + 1) * (ny + 1) > 2'000'000) failSegmentation("the quad spacing makes more than 2 000 000 grid nodes");
  const Eigen::Vector2d origin = lo - 0.5 * (h * Eigen::Vector2d(nx, ny) - extent);
  const double insideTolerance = 1e-9 * h;

  // A point of the plane in the map (inside), or snapped onto the map's boundary when that is
  // within `reach`; the triangle and barycentric weights lift it onto the reference.
  auto locate = [&locator, &uv, &T, insideTolerance](const Eigen::Vector2d& p, double reach) {
    NodeHit hit;
    const spatial::ClosestPoint cp = locator->closest(Eigen::Vector3d(p.x(), p.y(), 0.0));
    const double distance = (cp.point.head<2>() - p).norm();
    if (distance > insideTolerance && distance > reach) return hit;
    hit.inside = distance <= insideTolerance;
    hit.snapped = !hit.inside;
    hit.at = hit.inside ? p : Eigen::Vector2d(cp.point.head<2>());
    hit.triangle = cp.triangle;
    hit.barycentric = barycentricIn(hit.at, uv.row(T(cp.triangle, 0)), uv.row(T(cp.triangle, 1)),
                                    uv.row(T(cp.triangle, 2)));
    return hit;
  };
  auto nodeId = [ny](long i, long j) { return i * (ny + 1) + j; };
  auto cellId = [ny](long i, long j) { return i * ny + j; };

  std::vector<NodeHit> nodes((nx + 1) * (ny + 1));
  for (long i = 0; i <= nx; ++i)
    for (long j = 0; j <= ny; ++j) nodes[nodeId(i, j)] = locate(origin + h * Eigen::Vector2d(i, j), 0.75 * h);

  // Cells of the map, labelled by the patch under their centre: those with all corners inside,
  // and along the boundary those whose outside corners snap onto the boundary (so M follows the
  // reference's edge instead of stopping a staircase short of it) when the snapped quad stays
  // convex with sides of at least h/4 — or, failing that, the triangle of three of its corners
  // (a boundary across the grid is then cut along cell diagonals, not stepped).
  auto wellShaped = [h](const std::vector<Eigen::Vector2d>& q) {
    const std::size_t n = q.size();
    for (std::size_t k = 0; k < n; ++k) {
      const Eigen::Vector2d e = q[(k + 1) % n] - q[k], next = q[(k + 2) % n] - q[(k + 1) % n];
      if (e.norm() < 0.25 * h || e.x() * next.y() - e.y() * next.x() < 0.1 * h * h) return false;
    }
    return true;
  };
  std::vector<int> cellPatch(nx * ny, -1);
  std::vector<int> cellMissing(nx * ny, -1);  // a triangle cell: which corner (0 … 3) it leaves out
  for (long i = 0; i < nx; ++i)
    for (long j = 0; j < ny; ++j) {
      const std::array<const NodeHit*, 4> corner = {&nodes[nodeId(i, j)], &nodes[nodeId(i + 1, j)],
                                                    &nodes[nodeId(i + 1, j + 1)], &nodes[nodeId(i, j + 1)]};
      int inside = 0, placed = 0;
      for (const NodeHit* c : corner) inside += c->inside ? 1 : 0, placed += (c->inside || c->snapped) ? 1 : 0;
      if (inside == 0 || placed < 3) continue;
      if (inside == 4 || (placed == 4 && wellShaped({corner[0]->at, corner[1]->at, corner[2]->at, corner[3]->at}))) {
        const NodeHit centre = locate(origin + h * Eigen::Vector2d(i + 0.5, j + 0.5), 0.5 * h);
        if (centre.inside || (centre.snapped && inside < 4)) {
          cellPatch[cellId(i, j)] = trianglePatch[centre.triangle];
          continue;
        }
        if (inside == 4) continue;
      }
      // A triangle: leave out a corner that is not inside (an unplaced one if there is one).
      int best = -1;
      double bestShortest = 0.0;
      for (int m = 0; m < 4; ++m) {
        if (corner[m]->inside) continue;
        if (placed == 3 && (corner[m]->snapped)) continue;
        std::vector<Eigen::Vector2d> tri;
        for (int k = 1; k < 4; ++k) tri.push_back(corner[(m + k) % 4]->at);
        if (!wellShaped(tri)) continue;
        const double shortest = std::min({(tri[1] - tri[0]).norm(), (tri[2] - tri[1]).norm(), (tri[0] - tri[2]).norm()});
        if (shortest > bestShortest) bestShortest = shortest, best = m;
      }
      if (best < 0) continue;
      const Eigen::Vector2d centroid =
          (corner[(best + 1) % 4]->at + corner[(best + 2) % 4]->at + corner[(best + 3) % 4]->at) / 3.0;
      const NodeHit centre = locate(centroid, 0.5 * h);
      if (!centre.inside && !centre.snapped) continue;
      cellPatch[cellId(i, j)] = trianglePatch[centre.triangle];
      cellMissing[cellId(i, j)] = best;
    }

  SegmentedApproximation result;
  result.spacing = h;
  const std::array<std::array<long, 2>, 4> across = {{{-1, 0}, {1, 0}, {0, -1}, {0, 1}}};
  // The side of a cell toward across[d], as its two corners, and whether both cells have it (a
  // triangle cell lacks the two sides at its missing corner).
  static constexpr std::array<std::array<int, 2>, 4> sideCorners = {{{0, 3}, {1, 2}, {0, 1}, {3, 2}}};
  auto shareSide = [&cellMissing](long c, long n, int d) {
    const int opposite = d ^ 1;  // left ↔ right, bottom ↔ top
    const int mc = cellMissing[c], mn = cellMissing[n];
    return mc != sideCorners[d][0] && mc != sideCorners[d][1] && mn != sideCorners[opposite][0] &&
           mn != sideCorners[opposite][1];
  };

  // Pieces: connected components of equally labelled cells (across shared edges); small ones join
  // the neighbouring patch they share most edges with, until none is left.
  std::vector<int> cellPiece(nx * ny, -1);
  int pieceCount = 0;
  std::vector<long> pieceSize;
  auto labelPieces = [&]() {
    std::fill(cellPiece.begin(), cellPiece.end(), -1);
    pieceCount = 0;
    pieceSize.clear();
    std::vector<long> stack;
    for (long c = 0; c < nx * ny; ++c) {
      if (cellPatch[c] < 0 || cellPiece[c] >= 0) continue;
      long size = 0;
      stack.assign(1, c);
      cellPiece[c] = pieceCount;
      while (!stack.empty()) {
        const long cur = stack.back();
        stack.pop_back();
        ++size;
        const long ci = cur / ny, cj = cur % ny;
        for (int d = 0; d < 4; ++d) {
          const long ni = ci + across[d][0], nj = cj + across[d][1];
          if (ni < 0 || nj < 0 || ni >= nx || nj >= ny) continue;
          const long n = cellId(ni, nj);
          if (cellPatch[n] == cellPatch[c] && cellPiece[n] < 0 && shareSide(cur, n, d))
            cellPiece[n] = pieceCount, stack.push_back(n);
        }
      }
      pieceSize.push_back(size);
      ++pieceCount;
    }
  };
  for (int pass = 0; pass < 256; ++pass) {
    labelPieces();
    bool changed = false;
    for (int p = 0; p < pieceCount; ++p) {
      if (pieceSize[p] >= options.minPieceFaces) continue;
      std::map<int, long> sharedEdges;  // neighbouring patch → edges shared with piece p
      for (long c = 0; c < nx * ny; ++c) {
        if (cellPiece[c] != p) continue;
        const long ci = c / ny, cj = c % ny;
        for (int d = 0; d < 4; ++d) {
          const long ni = ci + across[d][0], nj = cj + across[d][1];
          if (ni < 0 || nj < 0 || ni >= nx || nj >= ny) continue;
          const long n = cellId(ni, nj);
          if (cellPatch[n] >= 0 && cellPiece[n] != p && shareSide(c, n, d)) ++sharedEdges[cellPatch[n]];
        }
      }
      int to = -1;
      long best = 0;
      for (const auto& [patch, count] : sharedEdges)
        if (count > best) best = count, to = patch;
      for (long c = 0; c < nx * ny; ++c)
        if (cellPiece[c] == p) {
          if (to < 0) ++result.droppedFaces;
          cellPatch[c] = to;  // −1: an isolated sliver is left out
        }
      if (to >= 0) ++result.mergedPieces;
      changed = true;  // every small piece of this labelling moves at once; relabel and repeat
    }
    if (!changed) break;
  }
  labelPieces();
  if (pieceCount == 0) failSegmentation("no grid cell lies inside the reference; lower the spacing");

  // Borders between patches follow the segmentation: a node whose cells belong to several
  // patches moves onto the nearest border between two of them in the map (edges of the reference
  // between triangles of different patches), unless that would leave one of its cells concave or
  // a side shorter than h/4. Features a segmentation follows (a box's edges) are then lines of M
  // instead of staircases across them.
  {
    std::map<std::pair<int, int>, std::pair<int, int>> edgeTriangles;  // edge → (triangle, other or −1)
    std::vector<std::array<int, 2>> borderPatches;
    std::vector<Eigen::Vector3d> from, to;
    for (Eigen::Index t = 0; t < T.rows(); ++t)
      for (int k = 0; k < 3; ++k) {
        const auto key = std::minmax(T(t, k), T(t, (k + 1) % 3));
        const auto [it, inserted] = edgeTriangles.emplace(key, std::make_pair(static_cast<int>(t), -1));
        if (inserted) continue;
        const int other = it->second.first;
        if (trianglePatch[other] == trianglePatch[t]) continue;
        borderPatches.push_back({trianglePatch[other], trianglePatch[t]});
        from.emplace_back(uv(key.first, 0), uv(key.first, 1), 0.0);
        to.emplace_back(uv(key.second, 0), uv(key.second, 1), 0.0);
      }
    if (!from.empty()) {
      Eigen::MatrixX3d A(static_cast<Eigen::Index>(from.size()), 3), B(static_cast<Eigen::Index>(to.size()), 3);
      for (std::size_t k = 0; k < from.size(); ++k) A.row(k) = from[k].transpose(), B.row(k) = to[k].transpose();
      const spatial::SegmentSetProximity borders(A, B);
      auto cellActive = [&cellPiece, nx, ny, &cellId](long i, long j) {
        return i >= 0 && j >= 0 && i < nx && j < ny && cellPiece[cellId(i, j)] >= 0;
      };
      auto cellShaped = [&nodes, &nodeId, &wellShaped, &cellMissing, &cellId](long i, long j) {
        const std::array<long, 4> corner = {nodeId(i, j), nodeId(i + 1, j), nodeId(i + 1, j + 1), nodeId(i, j + 1)};
        std::vector<Eigen::Vector2d> polygon;
        for (int k = 0; k < 4; ++k)
          if (k != cellMissing[cellId(i, j)]) polygon.push_back(nodes[corner[k]].at);
        return wellShaped(polygon);
      };
      for (long i = 0; i <= nx; ++i)
        for (long j = 0; j <= ny; ++j) {
          const std::array<std::array<long, 2>, 4> around = {{{i - 1, j - 1}, {i, j - 1}, {i, j}, {i - 1, j}}};
          std::set<int> patchesHere;
          for (const auto& c : around)
            if (cellActive(c[0], c[1])) patchesHere.insert(cellPatch[cellId(c[0], c[1])]);
          if (patchesHere.size() < 2) continue;
          NodeHit& node = nodes[nodeId(i, j)];
          const spatial::ClosestSegmentPoint near = borders.closest(Eigen::Vector3d(node.at.x(), node.at.y(), 0.0));
          const Eigen::Vector2d target = near.point.head<2>();
          if ((target - node.at).norm() > 0.5 * h || (target - node.at).norm() == 0.0) continue;
          const auto& pair = borderPatches[near.segment];
          if (!patchesHere.count(pair[0]) || !patchesHere.count(pair[1])) continue;
          const NodeHit before = node;
          const NodeHit moved = locate(target, 1e-6 * h);
          if (!moved.inside && !moved.snapped) continue;
          node = moved;
          node.at = target;
          node.inside = before.inside;
          node.snapped = before.snapped;
          bool ok = true;
          for (const auto& c : around)
            if (cellActive(c[0], c[1]) && !cellShaped(c[0], c[1])) ok = false;
          if (ok) ++result.bordersAligned;
          else node = before;
        }
    }
  }

  // Vertices: one per (node, piece, fan around the node).
  std::map<std::array<long, 3>, int> vertexOf;
  std::vector<std::array<long, 3>> keys;
  auto vertexFor = [&vertexOf, &keys](long node, int piece, int fan) {
    const std::array<long, 3> key = {node, piece, fan};
    const auto [it, inserted] = vertexOf.emplace(key, static_cast<int>(keys.size()));
    if (inserted) keys.push_back(key);
    return it->second;
  };
  auto pieceOfCell = [&cellPiece, nx, ny, &cellId](long i, long j) {
    return i < 0 || j < 0 || i >= nx || j >= ny ? -1 : cellPiece[cellId(i, j)];
  };
  auto missingOf = [&cellMissing, nx, ny, &cellId](long i, long j) {
    return i < 0 || j < 0 || i >= nx || j >= ny ? -1 : cellMissing[cellId(i, j)];
  };
  auto fanAt = [&pieceOfCell, &missingOf](long i, long j, int piece, int slot) {
    // slots around node (i, j): 0 = cell (i−1, j−1), 1 = (i, j−1), 2 = (i, j), 3 = (i−1, j); the
    // node is corner nodeCorner[s] of slot s's cell (corners 0 … 3 counter-clockwise from (ci, cj))
    static constexpr std::array<int, 4> nodeCorner = {2, 3, 0, 1};
    // the far end of the edge between slots s and s+1, as a corner of each of the two cells
    static constexpr std::array<std::array<int, 2>, 4> farCorner = {{{1, 0}, {2, 1}, {3, 2}, {0, 3}}};
    const std::array<std::array<long, 2>, 4> cell = {{{i - 1, j - 1}, {i, j - 1}, {i, j}, {i - 1, j}}};
    std::array<bool, 4> inPiece{}, linked{};
    std::array<int, 4> missing{};
    for (int s = 0; s < 4; ++s) {
      missing[s] = missingOf(cell[s][0], cell[s][1]);
      inPiece[s] = pieceOfCell(cell[s][0], cell[s][1]) == piece && missing[s] != nodeCorner[s];
    }
    for (int s = 0; s < 4; ++s) {
      const int t = (s + 1) % 4;
      linked[s] = inPiece[s] && inPiece[t] && missing[s] != farCorner[s][0] && missing[t] != farCorner[s][1];
    }
    return fansAround(inPiece, linked)[slot];
  };
  std::vector<Face> faces;
  for (long i = 0; i < nx; ++i)
    for (long j = 0; j < ny; ++j) {
      const int p = cellPiece[cellId(i, j)];
      if (p < 0) continue;
      // Corners counter-clockwise in the plane; the cell sits in slot 2 of (i, j), 3 of
      // (i+1, j), 0 of (i+1, j+1) and 1 of (i, j+1).
      const int missing = cellMissing[cellId(i, j)];
      const std::array<std::array<long, 2>, 4> at = {{{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}}};
      static constexpr std::array<int, 4> slotOfCorner = {2, 3, 0, 1};
      std::array<int, 4> corner = {-1, -1, -1, -1};
      for (int k = 0; k < 4; ++k)
        if (k != missing) corner[k] = vertexFor(nodeId(at[k][0], at[k][1]), p, fanAt(at[k][0], at[k][1], p, slotOfCorner[k]));
      if (missing < 0) faces.push_back(corner);
      else faces.push_back({corner[(missing + 1) % 4], corner[(missing + 2) % 4], corner[(missing + 3) % 4], -1});
      result.facePatch.push_back(cellPatch[cellId(i, j)]);
      result.facePiece.push_back(p);
    }

  const int vertexCount = static_cast<int>(keys.size());
  {
    // A quad whose corner lies in no other face (a staircase corner of a grid boundary) is split
    // into two triangles cutting that corner off: eq. 1 holds only the diagonals of a quad, and
    // such a corner could swing about them in M, changing its two edges while the residual stays
    // zero; a triangle's rows are its three edges.
    std::vector<int> facesAt(vertexCount, 0);
    for (const Face& q : faces)
      for (int k = 0; k < faceSize(q); ++k) ++facesAt[q[k]];
    std::vector<Face> split;
    std::vector<int> splitPatch, splitPiece;
    for (std::size_t f = 0; f < faces.size(); ++f) {
      const Face& q = faces[f];
      int corner = -1;
      for (int k = 0; k < 4 && corner < 0 && faceSize(q) == 4; ++k)
        if (facesAt[q[k]] == 1) corner = k;
      if (corner < 0) {
        split.push_back(q);
        splitPatch.push_back(result.facePatch[f]);
        splitPiece.push_back(result.facePiece[f]);
        continue;
      }
      const int a = q[corner], b = q[(corner + 1) % 4], c = q[(corner + 2) % 4], e = q[(corner + 3) % 4];
      split.push_back({a, b, e, -1});
      split.push_back({b, c, e, -1});
      for (int r = 0; r < 2; ++r) splitPatch.push_back(result.facePatch[f]), splitPiece.push_back(result.facePiece[f]);
      ++result.cornerQuadsSplit;
    }
    faces = std::move(split);
    result.facePatch = std::move(splitPatch);
    result.facePiece = std::move(splitPiece);
  }
  QuadMeshDesign& d = result.design;
  d.faces = faces;
  d.mesh.resize(vertexCount, 3);
  for (int v = 0; v < vertexCount; ++v) {
    const NodeHit& hit = nodes[keys[v][0]];
    d.mesh.row(v) = hit.barycentric(0) * V.row(T(hit.triangle, 0)) + hit.barycentric(1) * V.row(T(hit.triangle, 1)) +
                    hit.barycentric(2) * V.row(T(hit.triangle, 2));
  }

  // M′: each piece mapped to the plane on its own (004_… §5: "conformally and near-isometrically
  // map each patch"), its quads split into triangles; a piece that is not a disk (it surrounds
  // another) keeps its part of the reference's map, scaled to its area. Each is turned to match
  // its place in the reference's map (2D Procrustes) and moved away from the centre.
  std::vector<std::vector<int>> pieceFaces(pieceCount);
  for (std::size_t f = 0; f < faces.size(); ++f) pieceFaces[result.facePiece[f]].push_back(static_cast<int>(f));
  std::vector<Eigen::Vector2d> gridAt(vertexCount);
  for (int v = 0; v < vertexCount; ++v) {
    const long node = keys[v][0];
    gridAt[v] = nodes[node].at;
  }
  Eigen::Vector2d overall = Eigen::Vector2d::Zero();
  for (int v = 0; v < vertexCount; ++v) overall += gridAt[v];
  overall /= static_cast<double>(vertexCount);
  d.unfolding = Eigen::MatrixX3d::Zero(vertexCount, 3);
  for (int p = 0; p < pieceCount; ++p) {
    std::vector<int> local(vertexCount, -1), globalOf;
    for (int f : pieceFaces[p])
      for (int k = 0; k < faceSize(faces[f]); ++k)
        if (local[faces[f][k]] < 0) local[faces[f][k]] = static_cast<int>(globalOf.size()), globalOf.push_back(faces[f][k]);
    const Eigen::Index n = static_cast<Eigen::Index>(globalOf.size());
    Eigen::MatrixX3d pieceMesh(n, 3);
    Eigen::MatrixX2d target(n, 2);  // the piece's part of the reference's map
    for (Eigen::Index k = 0; k < n; ++k) pieceMesh.row(k) = d.mesh.row(globalOf[k]), target.row(k) = gridAt[globalOf[k]];
    std::vector<std::array<int, 3>> triangles;
    double areaInSpace = 0.0;
    for (int f : pieceFaces[p]) {
      const Face& q = faces[f];
      if (faceSize(q) == 3) {
        triangles.push_back({q[0], q[1], q[2]});
        continue;
      }
      // split along the shorter diagonal in space
      const bool alongFirst = (d.mesh.row(q[0]) - d.mesh.row(q[2])).norm() <= (d.mesh.row(q[1]) - d.mesh.row(q[3])).norm();
      if (alongFirst) triangles.push_back({q[0], q[1], q[2]}), triangles.push_back({q[0], q[2], q[3]});
      else triangles.push_back({q[0], q[1], q[3]}), triangles.push_back({q[1], q[2], q[3]});
    }
    Eigen::MatrixX3i pieceTriangles(static_cast<Eigen::Index>(triangles.size()), 3);
    for (std::size_t k = 0; k < triangles.size(); ++k) {
      for (int c = 0; c < 3; ++c) pieceTriangles(static_cast<Eigen::Index>(k), c) = local[triangles[k][c]];
      const Eigen::Vector3d a = d.mesh.row(triangles[k][0]), b = d.mesh.row(triangles[k][1]), c = d.mesh.row(triangles[k][2]);
      areaInSpace += 0.5 * (b - a).cross(c - a).norm();
    }
    const Eigen::Vector2d targetCentre = target.colwise().mean();
    Eigen::MatrixX2d mapped;
    try {
      mapped = spatial::parameterizeDisk(pieceMesh, pieceTriangles, options.method);  // centred, area of the piece
      ++result.piecesMappedAlone;
      // The rotation that best turns the piece's own map onto its place in the reference's map.
      const Eigen::Matrix2d cov = mapped.transpose() * (target.rowwise() - targetCentre.transpose());
      const double angle = std::atan2(cov(0, 1) - cov(1, 0), cov(0, 0) + cov(1, 1));
      const Eigen::Matrix2d turn = Eigen::Rotation2Dd(angle).toRotationMatrix();
      mapped = (mapped * turn.transpose()).eval();
    } catch (const std::invalid_argument&) {
      double areaInMap = 0.0;
      for (const auto& t : triangles) {
        const Eigen::Vector2d a = gridAt[t[0]], b = gridAt[t[1]], c = gridAt[t[2]];
        areaInMap += 0.5 * std::abs((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
      }
      const double scale = std::sqrt(areaInSpace / areaInMap);
      mapped = (target.rowwise() - targetCentre.transpose()) * scale;
    }
    const Eigen::Vector2d placedCentre = overall + (1.0 + options.spread) * (targetCentre - overall);
    for (Eigen::Index k = 0; k < n; ++k) {
      d.unfolding(globalOf[k], 0) = placedCentre.x() + mapped(k, 0);
      d.unfolding(globalOf[k], 1) = placedCentre.y() + mapped(k, 1);
    }
  }
  d.unfoldingPlanar = true;
  d.variable = VariableMeshes::Both;

  // Gluing: the copies of a node (other pieces, or a piece's two fans at a pinch) chained.
  std::map<long, std::vector<int>> copiesOfNode;
  for (int v = 0; v < vertexCount; ++v) copiesOfNode[keys[v][0]].push_back(v);
  for (const auto& [node, copies] : copiesOfNode)
    for (std::size_t k = 1; k < copies.size(); ++k) d.glue.push_back({MeshSide::Mesh, copies[k - 1], copies[k]});

  ReferenceSurface reference;
  reference.vertices = V;
  reference.triangles = T;
  d.reference = std::move(reference);
  d.weights = options.weights;
  d.schedule = options.schedule;
  result.pieces = pieceCount;
  return result;
}

}  // namespace devsurf::models::quad_mesh
