#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

namespace devsurf::metrics {

/// Curvatures of one face of a quad mesh from its vertex normals (004_… §2.2.1 eq. 4).
///
/// The discrete shape operator s_f of the face v0 v1 v2 v3 maps the diagonals of the inscribed
/// parallelogram, v2 − v0 ↦ −(n2 − n0) and v3 − v1 ↦ −(n3 − n1), as a linear map of the plane
/// n_f^⊥ into itself (normal components of n2 − n0, n3 − n1 are dropped). Sign convention of the
/// paper, s = −dn: curvature is positive where the surface bends toward the side the vertex
/// normals point to. A sphere of radius r has K = 1/r² on either side; H = +1/r with normals
/// pointing to the centre, H = −1/r with outward normals. K and H do not depend on the face's
/// orientation, only on the normals. A triangle v0 v1 v2 uses its edges the same way:
/// v1 − v0 ↦ −(n1 − n0), v2 − v0 ↦ −(n2 − n0).
struct FaceCurvature {
  double gauss = 0.0;         ///< K = det s_f (1/length²)
  double mean = 0.0;          ///< H = tr s_f / 2 (1/length)
  double principalMax = 0.0;  ///< κ1 = H + √(H² − K) (κ1 ≥ κ2; both H when H² < K, which only a
                              ///< non-symmetric s_f can give: eq. 5 not satisfied)
  double principalMin = 0.0;  ///< κ2 = H − √(H² − K)
  /// Unit eigenvectors of s_f for κ1 and κ2 (sign arbitrary). They are orthogonal when s_f is
  /// symmetric (eq. 5). Where H² < K, or at an umbilic (s_f = H·I), the eigenvectors of the
  /// symmetric part (s_f + s_fᵀ)/2 instead (any orthonormal pair at an umbilic).
  Eigen::Vector3d directionMax = Eigen::Vector3d::Zero();
  Eigen::Vector3d directionMin = Eigen::Vector3d::Zero();
  /// The principal direction of the eigenvalue with the smaller |κ| (sign arbitrary): the ruling
  /// of a developable (004_… §3.2, zero eigenspace of s_f). Meaningful where |K| is small.
  Eigen::Vector3d ruling = Eigen::Vector3d::Zero();
  /// Unit normal of the inscribed parallelogram (v2 − v0) × (v3 − v1) / ‖…‖, or of the triangle
  /// (v1 − v0) × (v2 − v0) / ‖…‖ (front side).
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  /// False for a face whose diagonals (triangle: edges) are parallel: no plane; then every field
  /// above is 0 (no NaN).
  bool valid = false;
};

/// Curvatures of one face from its two spanning vectors and their images in the Gauss image.
/// @param[in] d0, d1  v2 − v0 and v3 − v1 of a quad (v1 − v0 and v2 − v0 of a triangle)
/// @param[in] m0, m1  the same differences of the vertex normals (n2 − n0, n3 − n1, …)
FaceCurvature checkerboardFaceCurvature(const Eigen::Vector3d& d0, const Eigen::Vector3d& d1,
                                        const Eigen::Vector3d& m0, const Eigen::Vector3d& m1);

/// Per-face curvatures of a quad mesh M (triangles allowed) with vertex normals N.
/// @param[in] mesh     V×3 vertices of M
/// @param[in] normals  V×3 vertex normals (the Gauss image, e.g. from solveGaussImage; not
///                     necessarily unit)
/// @param[in] faces    vertex indices, counter-clockwise from the front; `[3] = -1` for a triangle
/// @return one FaceCurvature per face, in order
/// @throws std::invalid_argument if the row counts differ or a face has an index out of range
std::vector<FaceCurvature> checkerboardCurvature(const Eigen::MatrixX3d& mesh,
                                                 const Eigen::MatrixX3d& normals,
                                                 const std::vector<std::array<int, 4>>& faces);

}  // namespace devsurf::metrics
