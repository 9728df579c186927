#pragma once

#include <functional>

#include <Eigen/Core>

#include "devsurf/creases/FoldSamples.h"

namespace devsurf::creases {

/// A planar crease curve γ: [u0, u1] → ℝ², placed in the plane z = 0 as c(u) = (γ(u), 0).
struct PlanarCurve {
  /// γ(u) for derivative 0 and its exact derivatives γ′, γ″ for derivative 1, 2.
  std::function<Eigen::Vector2d(double u, int derivative)> evaluate;
  double u0 = 0.0, u1 = 1.0;
};

/// A planar curved fold made by reflection (Mundilova 003_… §2.3; the planar case of "the second
/// sheet reflects the first surface's tangent planes in the crease's osculating planes"): the
/// first sheet is the general cylinder c(u) + v d₁ over the planar crease; the crease's osculating
/// plane is the plane z = 0 everywhere, so the second sheet is the mirror image of the cylinder in
/// z = 0. The paper continues across the crease into the mirror image of the cylinder's OTHER half:
/// the second patch is c(u) + v d₂ with d₂ = −R d₁ = (−d₁x, −d₁y, d₁z), v ∈ [0, L] (both patches
/// on the same side of z = 0, as in a paper folded along a planar curve).
///
/// Development (exact isometry of the cylinder): with d = d₁ unit and s(u) the arc length of the
/// cylinder's orthogonal section, s′ = |γ′ − (γ′·d) d| = sqrt(|γ′|² − (γ′·d)²),
///   c̄(u) = (s(u), γ(u)·d),  first patch c̄ + v (0, 1),  second patch c̄ − v (0, 1):
/// the developed rulings are collinear across the crease (ψ₁ = ψ₂, thesis eq. 1.7).
///
/// \note Orientation as in FoldSamples: the first patch develops to the left of the developed
///       crease (above it), the second to the right; the oriented normals are mirror images up to
///       sign, N₂ = −R N₁, so N₁ + N₂ ∥ e₃, the osculating plane's normal (curved fold, 7*).
struct PlanarFold {
  Eigen::Vector3d rulingFirst;   ///< unit d₁ (first patch), d₁z ≠ 0
  Eigen::Vector3d rulingSecond;  ///< unit d₂ = (−d₁x, −d₁y, d₁z) (second patch)
  double rulingLength = 0.0;     ///< L
  FoldSamples samples;           ///< crease samples, both sheets and their developments

  QuadMesh3 sheetMesh(int sheet) const;        ///< see surfaceMesh; sheet ∈ {0, 1}
  QuadMesh2 developmentMesh(int sheet) const;  ///< see creases::developmentMesh
  const Eigen::MatrixX3d& creasePolyline() const { return samples.crease; }
  const Eigen::MatrixX2d& developedCreasePolyline() const { return samples.sheet[0].devCrease; }
};

/// Planar fold over a parametric planar curve (regular: γ′ ≠ 0), sampled at n ≥ 2 equally spaced
/// parameters, with exact derivatives; s(u) by adaptive Gauss–Kronrod quadrature (relative
/// accuracy ≈ 1e-14 on smooth curves).
/// @param[in] rulingDirection  d₁ (normalized here); must not lie in the plane z = 0
/// @throws std::invalid_argument on an empty curve, u0 ≥ u1, n < 2, L ≤ 0 or d₁z ≈ 0
PlanarFold planarFoldByReflection(const PlanarCurve& curve, const Eigen::Vector3d& rulingDirection,
                                  double rulingLength, int n);

/// Planar fold over a planar polyline (rows γ_i, n ≥ 2, consecutive points distinct). The sheets
/// are polyhedral cylinders (parallelogram quads) and their developments are exact: s_i is the
/// length of the polyline's orthogonal section, so every edge and diagonal length is reproduced
/// to rounding. No derivative data (FoldSamples' derivative blocks have 0 rows); samples.u holds
/// the vertex indices 0, 1, …, n−1.
/// @throws std::invalid_argument as above, or on repeated points
PlanarFold planarFoldByReflection(const Eigen::MatrixX2d& polyline,
                                  const Eigen::Vector3d& rulingDirection, double rulingLength);

}  // namespace devsurf::creases
