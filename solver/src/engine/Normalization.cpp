#include "devsurf/engine/Normalization.h"

namespace devsurf::engine {

Normalization Normalization::fromPoints(const Eigen::MatrixX3d& points) {
  Normalization n;
  if (points.rows() == 0) return n;
  const Eigen::Vector3d lo = points.colwise().minCoeff().transpose();
  const Eigen::Vector3d hi = points.colwise().maxCoeff().transpose();
  n.centre = 0.5 * (lo + hi);
  const double diagonal = (hi - lo).norm();
  n.scale = diagonal > 0.0 ? diagonal : 1.0;
  return n;
}

void Normalization::normalizeRows(Eigen::MatrixX3d& points) const {
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    points.row(i) = toNormalized(points.row(i).transpose()).transpose();
}

void Normalization::denormalizeRows(Eigen::MatrixX3d& points) const {
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    points.row(i) = fromNormalized(points.row(i).transpose()).transpose();
}

}  // namespace devsurf::engine
