#pragma once

#include <Eigen/Core>

namespace devsurf::reference {

/// How well a surface covers reference points (issue 15's report): distances are one-sided, from
/// each reference point to the surface (000_… §4.2: a noisy cloud is measured this way, not the
/// other way round).
struct SurfaceDistance {
  int points = 0;                ///< reference points measured
  double maxDistance = 0.0;      ///< max over points of the distance to the surface
  double rmsDistance = 0.0;      ///< root mean square of those distances
  double diagonal = 0.0;         ///< bounding-box diagonal of the reference points
  double maxRelative = 0.0;      ///< maxDistance / diagonal
  double rmsRelative = 0.0;      ///< rmsDistance / diagonal
  double tolerance = 0.0;        ///< the tolerance coverage was counted with
  double coverage = 0.0;         ///< fraction of points within `tolerance` of the surface
  Eigen::VectorXd distances;     ///< per point, its distance to the surface (for colouring)
};

/// Distances from reference points to a triangle surface through CGAL's AABB tree
/// (spatial::TriangleMeshProximity). Triangles of zero area (a strip's rulings meeting in a
/// point) are left out, as they hold no points the others do not.
/// @param[in] reference  r×3 points (a cloud, or a mesh's vertices)
/// @param[in] V, T       the surface: vertices and triangles
/// @param[in] tolerance  coverage counts points within it; ≤ 0 means 1% of the reference's diagonal
/// @throws std::invalid_argument if there are no reference points, a coordinate is not finite, an
///         index is out of range, or no triangle has positive area
SurfaceDistance surfaceDistance(const Eigen::MatrixX3d& reference, const Eigen::MatrixX3d& V,
                                const Eigen::MatrixX3i& T, double tolerance = 0.0);

}  // namespace devsurf::reference
