// Poisson-like thinning of a reference cloud with a normal per kept point (000_… §4.2), ball
// queries through nanoflann's k-d tree.
#include "devsurf/reference/PointThinning.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Eigenvalues>

#include "devsurf/spatial/MatrixRowsKdTree.h"

namespace devsurf::reference {
namespace {

using CloudRows = spatial::MatrixRows;
using KdTree = spatial::MatrixRowsKdTree;

}  // namespace

ThinnedCloud thinPointCloud(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& normals,
                            const ThinningOptions& options) {
  if (!(std::isfinite(options.radius) && options.radius > 0.0))
    throw std::invalid_argument("radius: a positive finite length is needed, got " + std::to_string(options.radius));
  if (normals.rows() != 0 && normals.rows() != points.rows())
    throw std::invalid_argument("normals: " + std::to_string(points.rows()) + " rows expected, got " +
                                std::to_string(normals.rows()));
  if (!points.allFinite()) throw std::invalid_argument("points: every coordinate must be a finite number");
  ThinnedCloud out;
  const Eigen::Index n = points.rows();
  if (n == 0) {
    out.points.resize(0, 3);
    out.normals.resize(0, 3);
    return out;
  }
  const CloudRows cloud{points};
  const KdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));  // builds the index

  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::mt19937 random(options.seed);
  std::shuffle(order.begin(), order.end(), random);

  std::vector<char> discarded(static_cast<std::size_t>(n), 0);
  std::vector<std::pair<std::size_t, double>> ball;
  std::vector<Eigen::RowVector3d> keptNormals;
  std::vector<double> flatness;
  const double radiusSquared = options.radius * options.radius;
  nanoflann::SearchParams search(32, 0.0f, false);
  for (const int i : order) {
    if (discarded[static_cast<std::size_t>(i)]) continue;
    const Eigen::RowVector3d q = points.row(i);
    ball.clear();
    tree.radiusSearch(q.data(), radiusSquared, ball, search);
    // The plane through the ball: its centroid and the covariance's least eigenvector.
    Eigen::RowVector3d centroid = Eigen::RowVector3d::Zero();
    for (const auto& [j, d2] : ball) centroid += points.row(static_cast<Eigen::Index>(j));
    centroid /= static_cast<double>(std::max<std::size_t>(1, ball.size()));
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const auto& [j, d2] : ball) {
      const Eigen::RowVector3d d = points.row(static_cast<Eigen::Index>(j)) - centroid;
      covariance += d.transpose() * d;
      discarded[j] = 1;
    }
    discarded[static_cast<std::size_t>(i)] = 1;
    Eigen::RowVector3d normal = Eigen::RowVector3d::Zero();
    double ratio = 0.0;
    bool fitted = false;
    if (static_cast<int>(ball.size()) >= options.minimumNeighbours) {
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
      const Eigen::Vector3d values = eigen.eigenvalues();  // ascending
      if (values(2) > 0.0 && values(1) > 1e-12 * values(2)) {
        normal = eigen.eigenvectors().col(0).transpose();
        ratio = std::max(0.0, values(0)) / values(2);
        fitted = true;
      }
    }
    if (normals.rows() != 0) {
      const Eigen::RowVector3d given = normals.row(i);
      if (normal.squaredNorm() == 0.0) {
        const double length = given.norm();
        if (std::isfinite(length) && length > 0.0) normal = given / length;
      } else if (normal.dot(given) < 0.0) {
        normal = -normal;
      }
    }
    out.kept.push_back(i);
    keptNormals.push_back(normal);
    flatness.push_back(ratio);
    out.fitted.push_back(fitted ? 1 : 0);
  }
  const Eigen::Index m = static_cast<Eigen::Index>(out.kept.size());
  out.points.resize(m, 3);
  out.normals.resize(m, 3);
  out.flatness.resize(m);
  for (Eigen::Index k = 0; k < m; ++k) {
    out.points.row(k) = points.row(out.kept[static_cast<std::size_t>(k)]);
    out.normals.row(k) = keptNormals[static_cast<std::size_t>(k)];
    out.flatness(k) = flatness[static_cast<std::size_t>(k)];
  }
  return out;
}

double suggestedThinningRadius(const Eigen::MatrixX3d& points, bool normalsGiven) {
  if (points.rows() < 2) return 0.0;
  const double diagonal = (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm();
  if (!(diagonal > 0.0) || !std::isfinite(diagonal)) return 0.0;
  if (normalsGiven) return 0.03 * diagonal;
  return std::max(0.03 * diagonal, 1.5 * diagonal / std::sqrt(static_cast<double>(points.rows())));
}

}  // namespace devsurf::reference
