#include "devsurf/models/quad_mesh/SegmentedApproximation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "devsurf/spatial/TriangleMeshProximity.h"

namespace devsurf::models::quad_mesh {
namespace {

[[noreturn]] void fail(const std::string& why) {
  throw std::invalid_argument("segmentedApproximation: " + why);
}

/// A grid node of the parameter plane found inside the map: its triangle and barycentric weights.
struct NodeHit {
  bool inside = false;
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

/// Connected runs of cells around a grid node that belong to one piece, in the node's cyclic
/// order (c00, c10, c11, c01: consecutive cells share an edge at the node). Returns for each of
/// the four slots the run index, or −1.
std::array<int, 4> fansAround(const std::array<int, 4>& pieceOfSlot, int piece) {
  std::array<int, 4> fan = {-1, -1, -1, -1};
  int start = -1;
  for (int s = 0; s < 4; ++s)
    if (pieceOfSlot[s] != piece) { start = s; break; }
  if (start < 0) {  // all four cells: one fan
    fan.fill(0);
    return fan;
  }
  int runs = -1;
  bool inRun = false;
  for (int k = 1; k <= 4; ++k) {
    const int s = (start + k) % 4;
    if (pieceOfSlot[s] == piece) {
      if (!inRun) ++runs, inRun = true;
      fan[s] = runs;
    } else {
      inRun = false;
    }
  }
  return fan;
}

}  // namespace

SegmentedApproximation segmentedApproximation(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& T,
                                              const std::vector<int>& trianglePatch,
                                              const SegmentedApproximationOptions& options) {
  if (static_cast<Eigen::Index>(trianglePatch.size()) != T.rows())
    fail("patch ids: " + std::to_string(trianglePatch.size()) + " values for " + std::to_string(T.rows()) +
         " triangles");
  for (std::size_t t = 0; t < trianglePatch.size(); ++t)
    if (trianglePatch[t] < 0) fail("patch ids[" + std::to_string(t) + "] is negative");
  if (options.targetFaces < 1 && !(options.spacing > 0.0)) fail("targetFaces must be ≥ 1");
  if (!(options.spread >= 0.0) || !std::isfinite(options.spread)) fail("spread must be ≥ 0");

  Eigen::MatrixX2d uv = spatial::parameterizeDisk(V, T, options.method);
  {
    // Turn the map so that its bounding rectangle is smallest: a straight side of the reference
    // then runs along the grid instead of across it as a staircase (whose corners, each in one
    // quad only, are the least constrained vertices of eq. 1).
    double bestArea = std::numeric_limits<double>::infinity(), bestAngle = 0.0;
    for (int step = 0; step < 180; ++step) {
      const double angle = step * (M_PI / 360.0);  // 0 … 90° by ½°
      const Eigen::Matrix2d turn = Eigen::Rotation2Dd(angle).toRotationMatrix();
      const Eigen::MatrixX2d turned = uv * turn.transpose();
      const Eigen::Vector2d size = turned.colwise().maxCoeff() - turned.colwise().minCoeff();
      if (size.prod() < bestArea - 1e-12 * bestArea) bestArea = size.prod(), bestAngle = angle;
    }
    uv = (uv * Eigen::Rotation2Dd(bestAngle).toRotationMatrix().transpose()).eval();
  }
  double area = 0.0;
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    const Eigen::Vector3d a = V.row(T(t, 0)), b = V.row(T(t, 1)), c = V.row(T(t, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  const double h = options.spacing > 0.0 ? options.spacing : std::sqrt(area / options.targetFaces);
  if (!(h > 0.0) || !std::isfinite(h)) fail("the quad spacing is not positive");

  // Point location in the map: the AABB tree over the map's triangles (lifted to z = 0).
  Eigen::MatrixX3d planar = Eigen::MatrixX3d::Zero(V.rows(), 3);
  planar.leftCols<2>() = uv;
  std::optional<spatial::TriangleMeshProximity> locator;
  try {
    locator.emplace(planar, T);
  } catch (const std::invalid_argument& e) {
    fail(std::string("the map to the plane has a degenerate triangle (") + e.what() + ")");
  }

  std::vector<char> used(V.rows(), 0);
  for (Eigen::Index t = 0; t < T.rows(); ++t)
    for (int k = 0; k < 3; ++k) used[T(t, k)] = 1;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = Eigen::Vector2d::Constant(-1e300);
  for (Eigen::Index v = 0; v < V.rows(); ++v)
    if (used[v]) lo = lo.cwiseMin(uv.row(v).transpose()), hi = hi.cwiseMax(uv.row(v).transpose());
  const Eigen::Vector2d extent = hi - lo;
  const long nx = static_cast<long>(std::floor(extent.x() / h)), ny = static_cast<long>(std::floor(extent.y() / h));
  if (nx < 1 || ny < 1) fail("the quad spacing is larger than the reference's map");
  if ((nx + 1) * (ny + 1) > 2'000'000) fail("the quad spacing makes more than 2 000 000 grid nodes");
  const Eigen::Vector2d origin = lo + 0.5 * (extent - h * Eigen::Vector2d(nx, ny));
  const double insideTolerance = 1e-9 * h;

  auto locate = [&locator, &uv, &T, insideTolerance](const Eigen::Vector2d& p) {
    NodeHit hit;
    const spatial::ClosestPoint cp = locator->closest(Eigen::Vector3d(p.x(), p.y(), 0.0));
    if ((cp.point.head<2>() - p).norm() > insideTolerance) return hit;
    hit.inside = true;
    hit.triangle = cp.triangle;
    hit.barycentric = barycentricIn(p, uv.row(T(cp.triangle, 0)), uv.row(T(cp.triangle, 1)),
                                    uv.row(T(cp.triangle, 2)));
    return hit;
  };
  auto nodeId = [ny](long i, long j) { return i * (ny + 1) + j; };
  auto cellId = [ny](long i, long j) { return i * ny + j; };

  std::vector<NodeHit> nodes((nx + 1) * (ny + 1));
  for (long i = 0; i <= nx; ++i)
    for (long j = 0; j <= ny; ++j) nodes[nodeId(i, j)] = locate(origin + h * Eigen::Vector2d(i, j));

  // Cells inside the map, labelled by the patch under their centre.
  std::vector<int> cellPatch(nx * ny, -1);
  for (long i = 0; i < nx; ++i)
    for (long j = 0; j < ny; ++j) {
      if (!nodes[nodeId(i, j)].inside || !nodes[nodeId(i + 1, j)].inside || !nodes[nodeId(i + 1, j + 1)].inside ||
          !nodes[nodeId(i, j + 1)].inside)
        continue;
      const NodeHit centre = locate(origin + h * Eigen::Vector2d(i + 0.5, j + 0.5));
      if (centre.inside) cellPatch[cellId(i, j)] = trianglePatch[centre.triangle];
    }

  SegmentedApproximation result;
  result.spacing = h;
  const std::array<std::array<long, 2>, 4> across = {{{-1, 0}, {1, 0}, {0, -1}, {0, 1}}};

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
        for (const auto& d : across) {
          const long ni = ci + d[0], nj = cj + d[1];
          if (ni < 0 || nj < 0 || ni >= nx || nj >= ny) continue;
          const long n = cellId(ni, nj);
          if (cellPatch[n] == cellPatch[c] && cellPiece[n] < 0) cellPiece[n] = pieceCount, stack.push_back(n);
        }
      }
      pieceSize.push_back(size);
      ++pieceCount;
    }
  };
  for (int pass = 0; pass < 64; ++pass) {
    labelPieces();
    bool changed = false;
    for (int p = 0; p < pieceCount; ++p) {
      if (pieceSize[p] >= options.minPieceFaces) continue;
      std::map<int, long> sharedEdges;  // neighbouring patch → edges shared with piece p
      for (long c = 0; c < nx * ny; ++c) {
        if (cellPiece[c] != p) continue;
        const long ci = c / ny, cj = c % ny;
        for (const auto& d : across) {
          const long ni = ci + d[0], nj = cj + d[1];
          if (ni < 0 || nj < 0 || ni >= nx || nj >= ny) continue;
          const long n = cellId(ni, nj);
          if (cellPatch[n] >= 0 && cellPiece[n] != p) ++sharedEdges[cellPatch[n]];
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
      changed = true;
      break;  // relabel: the neighbour's piece has grown
    }
    if (!changed) break;
  }
  labelPieces();
  if (pieceCount == 0) fail("no grid cell lies inside the reference; lower the spacing");

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
  auto fanAt = [&pieceOfCell](long i, long j, int piece, int slot) {
    // slots around node (i, j): 0 = cell (i−1, j−1), 1 = (i, j−1), 2 = (i, j), 3 = (i−1, j)
    const std::array<int, 4> around = {pieceOfCell(i - 1, j - 1), pieceOfCell(i, j - 1), pieceOfCell(i, j),
                                       pieceOfCell(i - 1, j)};
    return fansAround(around, piece)[slot];
  };
  std::vector<Face> faces;
  for (long i = 0; i < nx; ++i)
    for (long j = 0; j < ny; ++j) {
      const int p = cellPiece[cellId(i, j)];
      if (p < 0) continue;
      // Corners counter-clockwise in the plane; the cell sits in slot 2 of (i, j), 3 of
      // (i+1, j), 0 of (i+1, j+1) and 1 of (i, j+1).
      faces.push_back({vertexFor(nodeId(i, j), p, fanAt(i, j, p, 2)),
                       vertexFor(nodeId(i + 1, j), p, fanAt(i + 1, j, p, 3)),
                       vertexFor(nodeId(i + 1, j + 1), p, fanAt(i + 1, j + 1, p, 0)),
                       vertexFor(nodeId(i, j + 1), p, fanAt(i, j + 1, p, 1))});
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
      for (int k = 0; k < 4; ++k) ++facesAt[q[k]];
    std::vector<Face> split;
    std::vector<int> splitPatch, splitPiece;
    for (std::size_t f = 0; f < faces.size(); ++f) {
      const Face& q = faces[f];
      int corner = -1;
      for (int k = 0; k < 4 && corner < 0; ++k)
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
    gridAt[v] = origin + h * Eigen::Vector2d(static_cast<double>(node / (ny + 1)), static_cast<double>(node % (ny + 1)));
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
