// One-sided distances from reference points to a model's surface (issue 15's report).
#include "devsurf/reference/SurfaceDistance.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include "devsurf/spatial/TriangleMeshProximity.h"

namespace devsurf::reference {

SurfaceDistance surfaceDistance(const Eigen::MatrixX3d& reference, const Eigen::MatrixX3d& V,
                                const Eigen::MatrixX3i& T, double tolerance) {
  if (reference.rows() == 0) throw std::invalid_argument("reference: no points to measure");
  if (!reference.allFinite()) throw std::invalid_argument("reference: every coordinate must be a finite number");
  if (!V.allFinite()) throw std::invalid_argument("surface: every vertex coordinate must be a finite number");
  Eigen::MatrixX3i kept(T.rows(), 3);
  Eigen::Index count = 0;
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    for (int c = 0; c < 3; ++c)
      if (T(t, c) < 0 || T(t, c) >= V.rows())
        throw std::invalid_argument("triangles[" + std::to_string(t) + "]: vertex index out of range");
    const Eigen::Vector3d a = V.row(T(t, 0)).transpose(), b = V.row(T(t, 1)).transpose(), c = V.row(T(t, 2)).transpose();
    const double longest = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    if ((b - a).cross(c - a).norm() > 1e-12 * longest && T(t, 0) != T(t, 1) && T(t, 1) != T(t, 2) && T(t, 0) != T(t, 2))
      kept.row(count++) = T.row(t);
  }
  if (count == 0) throw std::invalid_argument("surface: no triangle of positive area to measure against");
  kept.conservativeResize(count, 3);
  const spatial::TriangleMeshProximity surface(V, kept);

  SurfaceDistance d;
  d.points = static_cast<int>(reference.rows());
  d.diagonal = (reference.colwise().maxCoeff() - reference.colwise().minCoeff()).norm();
  d.tolerance = tolerance > 0.0 ? tolerance : 0.01 * d.diagonal;
  double sumSquares = 0.0;
  long within = 0;
  d.distances.resize(reference.rows());
  for (Eigen::Index i = 0; i < reference.rows(); ++i) {
    const Eigen::Vector3d q = reference.row(i).transpose();
    const double distance = (surface.closest(q).point - q).norm();
    d.distances(i) = distance;
    d.maxDistance = std::max(d.maxDistance, distance);
    sumSquares += distance * distance;
    if (distance <= d.tolerance) ++within;
  }
  d.rmsDistance = std::sqrt(sumSquares / static_cast<double>(reference.rows()));
  d.coverage = static_cast<double>(within) / static_cast<double>(reference.rows());
  if (d.diagonal > 0.0) {
    d.maxRelative = d.maxDistance / d.diagonal;
    d.rmsRelative = d.rmsDistance / d.diagonal;
  }
  return d;
}

}  // namespace devsurf::reference
