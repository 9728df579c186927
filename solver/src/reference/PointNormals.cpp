// Oriented normals for every point of a reference shape: from a mesh's triangles, a cloud's file,
// or fitted planes oriented along a spanning tree (Hoppe et al. 1992).
#include "devsurf/reference/PointNormals.h"

#include <algorithm>
#include <cmath>
#include <queue>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "devsurf/reference/PointThinning.h"
#include "devsurf/spatial/MatrixRowsKdTree.h"

namespace devsurf::reference {
namespace {

Eigen::MatrixX3d meshVertexNormals(const ReferenceShape& shape) {
  Eigen::MatrixX3d normals = Eigen::MatrixX3d::Zero(shape.points.rows(), 3);
  for (Eigen::Index f = 0; f < shape.triangles.rows(); ++f) {
    const Eigen::RowVector3d a = shape.points.row(shape.triangles(f, 0)), b = shape.points.row(shape.triangles(f, 1)),
                             c = shape.points.row(shape.triangles(f, 2));
    const Eigen::RowVector3d areaNormal = (b - a).cross(c - a);  // twice the area, along the normal
    for (int k = 0; k < 3; ++k) normals.row(shape.triangles(f, k)) += areaNormal;
  }
  return normals;
}

/// Turns the kept points' normals to agree along a maximum spanning tree of |⟨n_i, n_j⟩| over
/// links within `reach`, each connected part rooted at its point farthest from the centroid.
void orientAlongSpanningTree(const Eigen::MatrixX3d& points, Eigen::MatrixX3d& normals, double reach) {
  const Eigen::Index n = points.rows();
  const spatial::MatrixRows rows{points};
  const spatial::MatrixRowsKdTree tree(3, rows, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  const nanoflann::SearchParams search(32, 0.0f, false);
  const Eigen::RowVector3d centroid = points.colwise().mean();
  std::vector<char> reached(static_cast<std::size_t>(n), 0);
  std::vector<std::pair<std::size_t, double>> ball;
  // Roots in order of distance from the centroid, farthest first: each unreached one starts a part.
  std::vector<std::pair<double, Eigen::Index>> roots;
  for (Eigen::Index j = 0; j < n; ++j) roots.emplace_back(-(points.row(j) - centroid).squaredNorm(), j);
  std::sort(roots.begin(), roots.end());
  using Link = std::tuple<double, Eigen::Index, Eigen::Index>;  // (|cos|, from, to): most parallel first
  for (const auto& [unused, root] : roots) {
    if (reached[static_cast<std::size_t>(root)] || normals.row(root).squaredNorm() == 0.0) continue;
    if (normals.row(root).dot(points.row(root) - centroid) < 0.0) normals.row(root) *= -1.0;
    std::priority_queue<Link> frontier;
    const auto visit = [&reached, &ball, &tree, &search, &points, &normals, reach, &frontier](Eigen::Index j) {
      reached[static_cast<std::size_t>(j)] = 1;
      ball.clear();
      const Eigen::Vector3d p = points.row(j).transpose();  // a row of a column-major matrix is strided
      tree.radiusSearch(p.data(), reach * reach, ball, search);
      for (const auto& [k, d2] : ball) {
        const auto other = static_cast<Eigen::Index>(k);
        if (reached[k] || normals.row(other).squaredNorm() == 0.0) continue;
        frontier.emplace(std::abs(normals.row(j).dot(normals.row(other))), j, other);
      }
    };
    visit(root);
    while (!frontier.empty()) {
      const auto [cosine, from, to] = frontier.top();
      frontier.pop();
      if (reached[static_cast<std::size_t>(to)]) continue;
      if (normals.row(from).dot(normals.row(to)) < 0.0) normals.row(to) *= -1.0;
      visit(to);
    }
  }
}

}  // namespace

Eigen::MatrixX3d orientedPointNormals(const ReferenceShape& shape) {
  const Eigen::Index n = shape.points.rows();
  if (n == 0) throw std::invalid_argument("orientedPointNormals: the shape has no points");
  if (!shape.points.allFinite()) throw std::invalid_argument("orientedPointNormals: a coordinate is not finite");
  Eigen::MatrixX3d normals;
  if (shape.isMesh()) normals = meshVertexNormals(shape);
  else if (shape.normals.rows() == n) {
    if (!shape.normals.allFinite()) throw std::invalid_argument("orientedPointNormals: a normal is not finite");
    normals = shape.normals;
  } else {
    ThinningOptions thinning;
    thinning.radius = suggestedThinningRadius(shape.points, false);
    normals = Eigen::MatrixX3d::Zero(n, 3);
    if (!(thinning.radius > 0.0)) return normals;  // coincident points
    ThinnedCloud thin = thinPointCloud(shape.points, Eigen::MatrixX3d(0, 3), thinning);
    orientAlongSpanningTree(thin.points, thin.normals, 3.0 * thinning.radius);
    // Each point takes the normal of its nearest kept point that has one (a ball with too few
    // points fits none).
    std::vector<Eigen::Index> withNormal;
    for (Eigen::Index k = 0; k < thin.points.rows(); ++k)
      if (thin.normals.row(k).squaredNorm() > 0.0) withNormal.push_back(k);
    if (withNormal.empty()) return normals;
    Eigen::MatrixX3d keptPoints(static_cast<Eigen::Index>(withNormal.size()), 3);
    for (std::size_t k = 0; k < withNormal.size(); ++k)
      keptPoints.row(static_cast<Eigen::Index>(k)) = thin.points.row(withNormal[k]);
    const spatial::MatrixRows kept{keptPoints};
    const spatial::MatrixRowsKdTree tree(3, kept, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    for (Eigen::Index j = 0; j < n; ++j) {
      std::size_t nearest = 0;
      double d2 = 0.0;
      const Eigen::Vector3d p = shape.points.row(j).transpose();
      tree.knnSearch(p.data(), 1, &nearest, &d2);
      normals.row(j) = thin.normals.row(withNormal[nearest]);
    }
  }
  for (Eigen::Index j = 0; j < n; ++j) {
    const double length = normals.row(j).norm();
    if (length > 0.0) normals.row(j) /= length;
    else normals.row(j).setZero();
  }
  return normals;
}

}  // namespace devsurf::reference
