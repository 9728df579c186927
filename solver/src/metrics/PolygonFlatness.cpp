#include "devsurf/metrics/PolygonFlatness.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace devsurf::metrics {

double polygonFlatness(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& loop, double tiny) {
  const std::size_t n = loop.size();
  if (n < 4) return 0.0;
  double shortest = std::numeric_limits<double>::infinity(), second = shortest;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < n; ++k) {
    assert(loop[k] >= 0 && static_cast<std::size_t>(loop[k]) < points.size() && "corner index out of range");
    const Eigen::Vector3d& p = points[static_cast<std::size_t>(loop[k])];
    centroid += p;
    const double length = (points[static_cast<std::size_t>(loop[(k + 1) % n])] - p).norm();
    if (length < shortest) {
      second = shortest;
      shortest = length;
    } else if (length < second) {
      second = length;
    }
  }
  const double scale = 0.5 * (shortest + second);
  if (!(scale > tiny)) return 0.0;
  centroid /= static_cast<double>(n);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (int index : loop) {
    const Eigen::Vector3d d = points[static_cast<std::size_t>(index)] - centroid;
    covariance.noalias() += d * d.transpose();
  }
  // The plane's normal: the direction of least spread (eigenvalues in increasing order).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  const Eigen::Vector3d normal = eigen.eigenvectors().col(0);
  double distance = 0.0;
  for (int index : loop) distance = std::max(distance, std::abs((points[static_cast<std::size_t>(index)] - centroid).dot(normal)));
  return distance / scale;
}

}  // namespace devsurf::metrics
