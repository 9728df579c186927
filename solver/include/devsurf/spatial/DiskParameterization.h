#pragma once

#include <Eigen/Core>

namespace devsurf::spatial {

/// How a disk-like triangle mesh is mapped to the plane.
enum class ParameterizationMethod {
  /// Least-squares conformal map (Lévy et al. 2002), two boundary vertices pinned: angles kept,
  /// areas not.
  Conformal,
  /// As-rigid-as-possible (Liu et al. 2008) started from the conformal map: near-isometric, the
  /// map 004_… §5 asks for ("conformally and near-isometrically").
  NearIsometric,
};

/// A planar parameterization of a triangle mesh with the topology of a disk (connected, one
/// boundary loop, Euler characteristic 1) through CGAL's Surface_mesh_parameterization (CGAL stays
/// in one translation unit). The result is scaled so that its area equals the mesh's and centred
/// at the origin; its orientation is the mesh's (a triangle counter-clockwise seen from the front
/// is counter-clockwise in the plane).
/// @param[in] V  n×3 vertex positions, finite
/// @param[in] T  t×3 triangles, counter-clockwise seen from the front
/// @return n×2 planar positions (rows of vertices no triangle uses are 0)
/// @throws std::invalid_argument if the mesh is empty, not a disk (several components, no
///         boundary, holes, non-manifold), has a degenerate triangle, or CGAL reports a failure;
///         the message says which
Eigen::MatrixX2d parameterizeDisk(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& T,
                                  ParameterizationMethod method = ParameterizationMethod::NearIsometric);

}  // namespace devsurf::spatial
