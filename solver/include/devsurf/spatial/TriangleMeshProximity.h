#pragma once

#include <memory>

#include <Eigen/Core>

namespace devsurf::spatial {

/// The point of a triangle mesh closest to a query point.
struct ClosestPoint {
  Eigen::Vector3d point;   ///< on the mesh
  int triangle = -1;       ///< row of T holding it (one of them when it lies on a shared edge)
  Eigen::Vector3d normal;  ///< unit normal of that triangle, (b − a) × (c − a) normalized
};

/// Closest-point queries on a fixed reference triangle mesh Φ (004_… §2.3.2): CGAL's AABB tree
/// (Simple_cartesian<double> kernel) over the triangles, built once in the constructor together
/// with its distance-query acceleration. Queries are const and may run concurrently. CGAL stays
/// inside the implementation (one translation unit).
class TriangleMeshProximity {
 public:
  /// @param[in] V  vertex positions (rows), finite
  /// @param[in] T  triangles (rows of 3 vertex indices, counter-clockwise seen from the front)
  /// @throws std::invalid_argument on no triangles, a non-finite coordinate, an index out of
  ///         range, a vertex repeated in a triangle, or a degenerate triangle (area ≤ 1e-12 times
  ///         its longest edge squared); the message names the triangle
  TriangleMeshProximity(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& T);
  ~TriangleMeshProximity();
  TriangleMeshProximity(TriangleMeshProximity&&) noexcept;
  TriangleMeshProximity& operator=(TriangleMeshProximity&&) noexcept;
  TriangleMeshProximity(const TriangleMeshProximity&) = delete;
  TriangleMeshProximity& operator=(const TriangleMeshProximity&) = delete;

  /// The closest point of the mesh to q, its triangle and that triangle's unit normal.
  ClosestPoint closest(const Eigen::Vector3d& q) const;

  int triangleCount() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace devsurf::spatial
