// Unfolding of (nearly) developable polygon meshes onto the plane from their edge lengths; the
// flat patterns of composites cut along seams and of strips are made of it.
#include "devsurf/spatial/IsometricUnfolding.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Eigenvalues>

#include "devsurf/spatial/DisjointSets.h"
#include "devsurf/spatial/MatrixRowsKdTree.h"

namespace devsurf::spatial {
namespace {

/// The third corner of a triangle unfolded onto one side of edge (p, q) (side +1: left of p→q),
/// at distances dp from p and dq from q.
Eigen::Vector2d unfoldCorner(const Eigen::Vector2d& p, const Eigen::Vector2d& q, double dp, double dq, double side) {
  const Eigen::Vector2d pq = q - p;
  const double d = pq.norm();
  if (!(d > 0.0)) throw std::invalid_argument("unfoldPieces: a polygon has an edge of zero length");
  const double along = (dp * dp - dq * dq + d * d) / (2.0 * d);
  const double across = std::sqrt(std::max(0.0, dp * dp - along * along));
  const Eigen::Vector2d u = pq / d, n(-u.y(), u.x());
  return p + along * u + side * across * n;
}

double planarCross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

}  // namespace

FlatLayout unfoldPieces(const std::vector<Eigen::Vector3d>& points, const std::vector<std::vector<int>>& polygons,
                        const std::vector<int>& pieceOfPolygon) {
  if (pieceOfPolygon.size() != polygons.size())
    throw std::invalid_argument("unfoldPieces: " + std::to_string(polygons.size()) + " piece ids expected, got " +
                                std::to_string(pieceOfPolygon.size()));
  const int numPoints = static_cast<int>(points.size());
  for (const Eigen::Vector3d& p : points)
    if (!p.allFinite()) throw std::invalid_argument("unfoldPieces: every point must be finite");
  for (std::size_t k = 0; k < polygons.size(); ++k) {
    if (pieceOfPolygon[k] < 0) throw std::invalid_argument("unfoldPieces: piece ids must be ≥ 0");
    for (const int id : polygons[k])
      if (id < 0 || id >= numPoints)
        throw std::invalid_argument("unfoldPieces: polygon " + std::to_string(k) + " has point id " + std::to_string(id) +
                                    " outside [0, " + std::to_string(numPoints) + ")");
  }
  std::map<int, std::vector<int>> polygonsOfPiece;  // ordered by piece id
  for (std::size_t k = 0; k < polygons.size(); ++k)
    if (polygons[k].size() >= 3) polygonsOfPiece[pieceOfPolygon[k]].push_back(static_cast<int>(k));

  FlatLayout out;
  out.polygons.assign(polygons.size(), {});
  std::vector<Eigen::Vector2d> flat;
  auto length = [&points](int i, int j) {
    return (points[static_cast<std::size_t>(i)] - points[static_cast<std::size_t>(j)]).norm();
  };
  double cursorY = 0.0;
  for (const auto& [pieceId, members] : polygonsOfPiece) {
    struct Triangle {
      std::array<int, 3> ids;
      int polygon;
    };
    std::vector<Triangle> triangles;
    for (const int k : members) {
      const std::vector<int>& poly = polygons[static_cast<std::size_t>(k)];
      for (std::size_t c = 1; c + 1 < poly.size(); ++c) triangles.push_back({{poly[0], poly[c], poly[c + 1]}, k});
    }
    std::map<std::pair<int, int>, std::vector<int>> edgeTriangles;
    for (std::size_t t = 0; t < triangles.size(); ++t)
      for (int c = 0; c < 3; ++c) {
        const int i = triangles[t].ids[static_cast<std::size_t>(c)];
        const int j = triangles[t].ids[static_cast<std::size_t>((c + 1) % 3)];
        if (i != j) edgeTriangles[std::minmax(i, j)].push_back(static_cast<int>(t));
      }
    // Breadth-first from the first triangle with three distinct corners.
    std::map<int, Eigen::Vector2d> at;
    std::vector<bool> placed(triangles.size(), false);
    std::deque<int> queue;
    for (std::size_t t = 0; t < triangles.size() && queue.empty(); ++t) {
      const auto& ids = triangles[t].ids;
      if (ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2]) continue;
      at[ids[0]] = Eigen::Vector2d::Zero();
      at[ids[1]] = Eigen::Vector2d(length(ids[0], ids[1]), 0.0);
      if (!(at[ids[1]].x() > 0.0)) throw std::invalid_argument("unfoldPieces: a polygon has an edge of zero length");
      at[ids[2]] = unfoldCorner(at[ids[0]], at[ids[1]], length(ids[0], ids[2]), length(ids[1], ids[2]), 1.0);
      placed[t] = true;
      queue.push_back(static_cast<int>(t));
    }
    while (!queue.empty()) {
      const int t = queue.front();
      queue.pop_front();
      const auto& ids = triangles[static_cast<std::size_t>(t)].ids;
      for (int c = 0; c < 3; ++c) {
        const int i = ids[static_cast<std::size_t>(c)], j = ids[static_cast<std::size_t>((c + 1) % 3)];
        const int opposite = ids[static_cast<std::size_t>((c + 2) % 3)];
        if (i == j) continue;
        for (const int n : edgeTriangles[std::minmax(i, j)]) {
          if (placed[static_cast<std::size_t>(n)]) continue;
          placed[static_cast<std::size_t>(n)] = true;
          queue.push_back(n);
          const auto& other = triangles[static_cast<std::size_t>(n)].ids;
          const int third = other[0] != i && other[0] != j ? other[0] : (other[1] != i && other[1] != j ? other[1] : other[2]);
          if (at.count(third)) continue;  // reached before (a closed loop of triangles)
          // Across edge (i, j) from `opposite`; a degenerate triangle (opposite on the edge) turns left.
          const double side = planarCross(at[j] - at[i], at[opposite] - at[i]) > 0.0 ? -1.0 : 1.0;
          at[third] = unfoldCorner(at[i], at[j], length(i, third), length(j, third), side);
        }
      }
    }
    if (at.size() < 3) continue;
    // Longest direction along x, then stacked above the previous piece.
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& [id, p] : at) mean += p;
    mean /= static_cast<double>(at.size());
    Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
    for (const auto& [id, p] : at) covariance += (p - mean) * (p - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(covariance);
    const Eigen::Vector2d axis = eigen.eigenvectors().col(1);
    const Eigen::Matrix2d rotation = (Eigen::Matrix2d() << axis.x(), axis.y(), -axis.y(), axis.x()).finished();
    double minX = 1e300, minY = 1e300, maxY = -1e300;
    for (auto& [id, p] : at) {
      p = rotation * (p - mean);  // a rotation: orientation kept
      minX = std::min(minX, p.x());
      minY = std::min(minY, p.y());
      maxY = std::max(maxY, p.y());
    }
    const int piece = out.pieces++;
    std::map<int, int> copyOf;
    for (const auto& [id, p] : at) {
      copyOf[id] = static_cast<int>(flat.size());
      flat.emplace_back(p.x() - minX, p.y() - minY + cursorY);
      out.pieceOfVertex.push_back(piece);
      out.pointOfVertex.push_back(id);
    }
    cursorY += (maxY - minY) * 1.15;
    for (const int k : members) {
      const std::vector<int>& poly = polygons[static_cast<std::size_t>(k)];
      if (!std::all_of(poly.begin(), poly.end(), [&copyOf](int id) { return copyOf.count(id) > 0; })) continue;
      std::vector<int>& ids = out.polygons[static_cast<std::size_t>(k)];
      for (const int id : poly) ids.push_back(copyOf.at(id));
    }
  }
  out.vertices.resize(static_cast<Eigen::Index>(flat.size()), 2);
  for (std::size_t k = 0; k < flat.size(); ++k) out.vertices.row(static_cast<Eigen::Index>(k)) = flat[k].transpose();
  for (const std::vector<int>& ids : out.polygons)
    for (std::size_t c = 0; c < ids.size(); ++c) {
      const int i = ids[c], j = ids[(c + 1) % ids.size()];
      const double l3 = length(out.pointOfVertex[static_cast<std::size_t>(i)], out.pointOfVertex[static_cast<std::size_t>(j)]);
      const double l2 = (out.vertices.row(i) - out.vertices.row(j)).norm();
      if (l3 > 0.0) out.lengthErrorMax = std::max(out.lengthErrorMax, std::abs(l2 - l3) / l3);
    }
  return out;
}

std::vector<int> edgeConnectedPieces(const std::vector<std::vector<int>>& polygons) {
  DisjointSets sets(polygons.size());
  std::map<std::pair<int, int>, int> firstPolygonOfEdge;
  for (std::size_t k = 0; k < polygons.size(); ++k) {
    const std::vector<int>& poly = polygons[k];
    for (std::size_t c = 0; c < poly.size(); ++c) {
      const int i = poly[c], j = poly[(c + 1) % poly.size()];
      if (i == j) continue;
      const auto [it, inserted] = firstPolygonOfEdge.emplace(std::minmax(i, j), static_cast<int>(k));
      if (!inserted) sets.join(it->second, static_cast<int>(k));
    }
  }
  std::map<int, int> number;
  std::vector<int> piece(polygons.size());
  for (std::size_t k = 0; k < polygons.size(); ++k) {
    const int root = sets.find(static_cast<int>(k));
    piece[k] = number.emplace(root, static_cast<int>(number.size())).first->second;
  }
  return piece;
}

std::vector<int> weldedPointIds(const Eigen::MatrixX3d& points, double tolerance) {
  if (!(tolerance >= 0.0)) throw std::invalid_argument("weldedPointIds: tolerance must be ≥ 0");
  const std::size_t n = static_cast<std::size_t>(points.rows());
  DisjointSets sets(n);
  if (n > 0) {
    const MatrixRows rows{points};
    const MatrixRowsKdTree tree(3, rows, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    std::vector<std::pair<std::size_t, double>> ball;
    const nanoflann::SearchParams search(32, 0.0f, false);
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::RowVector3d q = points.row(static_cast<Eigen::Index>(i));
      ball.clear();
      tree.radiusSearch(q.data(), tolerance * tolerance, ball, search);
      for (const auto& [j, d2] : ball) sets.join(static_cast<int>(i), static_cast<int>(j));
    }
  }
  std::vector<int> ids(n);
  for (std::size_t i = 0; i < n; ++i) ids[i] = sets.find(static_cast<int>(i));
  return ids;
}

}  // namespace devsurf::spatial
