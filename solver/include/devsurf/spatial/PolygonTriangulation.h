#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

namespace devsurf::spatial {

/// Triangles of a simple polygon by ear clipping (O(n²) for ordinary polygons, O(n³) at worst): n − 2 triangles of point indices into
/// `loop`, each counter-clockwise when the loop is; together they cover the polygon exactly, also
/// when it is not convex (a face with a notch, an L, a face around a hole's bridge).
///
/// @param[in] loop  n×2 corners in order (either orientation), n ≥ 3, no point twice
/// @return triangles as rows of `loop`; for a clockwise loop they are clockwise too
/// @throws std::invalid_argument for fewer than 3 points or a loop that is not simple (no ear left)
std::vector<std::array<int, 3>> triangulateSimplePolygon(const Eigen::MatrixX2d& loop);

/// Whether a polygon is convex (every turn the same way, collinear corners allowed).
bool isConvexPolygon(const Eigen::MatrixX2d& loop);

/// A planar 3D polygon written in 2D coordinates of its own plane (Newell's normal, any two
/// orthonormal directions across it), keeping its orientation: counter-clockwise in 2D when it
/// is counter-clockwise seen from the side its normal points to.
/// @param[in] corners  n×3 corners, n ≥ 3
Eigen::MatrixX2d polygonInItsPlane(const Eigen::MatrixX3d& corners);

}  // namespace devsurf::spatial
