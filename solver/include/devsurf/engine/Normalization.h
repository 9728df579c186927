#pragma once

#include <Eigen/Core>

namespace devsurf::engine {

/// Similarity that centres input at the origin and scales it to unit size before solving, and
/// maps results back (003_… §5.5): normalized = (p − centre) / scale.
/// \note scale is the diagonal of the bounding box, so normalized input has diameter 1 and
///       weights mean the same for every scene. A degenerate (single point) input keeps scale 1.
struct Normalization {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double scale = 1.0;

  /// From points as rows (m×3).
  static Normalization fromPoints(const Eigen::MatrixX3d& points);

  Eigen::Vector3d toNormalized(const Eigen::Vector3d& p) const { return (p - centre) / scale; }
  Eigen::Vector3d fromNormalized(const Eigen::Vector3d& q) const { return q * scale + centre; }
  /// Rows mapped in place.
  void normalizeRows(Eigen::MatrixX3d& points) const;
  void denormalizeRows(Eigen::MatrixX3d& points) const;
};

}  // namespace devsurf::engine
