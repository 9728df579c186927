#pragma once

#include <Eigen/Core>

#include "devsurf/creases/FoldSamples.h"

namespace devsurf::creases {

/// The curved crease of constant angle φ on the cylinder of revolution (Mundilova 003_… §3.1.3),
/// in closed form, with both sheets and their developments.
///
/// Crease (unit cylinder, axis z; p(u) = (−cos u, sin u, 0) has unit speed and
/// p′ = (sin α, cos α) with α(u) = u, as in eq. 3.4):
///   c(u) = (−cos u, sin u, h(u)),  h(u) = tan φ · cosh(u cot φ),
///   |c′(u)| = cosh(u cot φ),
/// and its development on the cylinder's development (arc length of p, z) is the catenary
///   c̄(u) = (u, h(u))  — the catenary y = a cosh(x/a) with a = tan φ.
///
/// First sheet σ₁: the cylinder, rulings r₁ = side·e₃ (side = +1: the patch above the crease,
/// developing to the region above the catenary; side = −1: below). Its development is
/// (u, z) ↦ (u, z).
///
/// Second sheet σ₂: the envelope of the cylinder's tangent planes reflected in the crease's
/// osculating planes. With the plane family n₂(u)·x = d₂(u), d₂ = n₂·c, its ruling at c(u) is
/// the characteristic line {n₂·x = d₂, n₂′·x = d₂′}, direction r₂ ∥ n₂ × n₂′ (all in closed form
/// with exact derivatives up to n₂″). r₂ is oriented so that the second patch is where the paper
/// continues across the crease: its development lies on the other side of the catenary than the
/// first patch's (r₂·b₂ has the sign −side). Its development is c̄(u) + v r̄₂(u) with
/// r̄₂ = (r₂·t) t̄ + (r₂·b₂) J t̄ (the angle ψ₂ between ruling and crease tangent is kept, and
/// b₂ ↦ J t̄ since t′·b₂ = t′·b₁ is the curved-fold condition). The thesis' ψ₂ = π − ψ₁ gives the
/// closed form r̄₂ = side·(2 sinh, sinh² − 1)/cosh² (argument u cot φ), which the tests compare.
///
/// Regularity: for side = +1 the second patch develops below the convex catenary, its rulings
/// diverge and its edge of regression lies on the discarded half (regressionParameter < 0): any L
/// is regular. For side = −1 they converge and the patch is regular only for L < v*(u).
/// Sampled meshes: the second sheet is neither a cylinder nor a cone (Mundilova Thm. 3.4), so its
/// rulings at u_i and u_{i+1} are skew lines and a sampled ruling quad is planar only to O(h²)
/// (its exact per-ruling warp, from tangents, is 0); the cylinder's quads are planar.
///
/// \note Frames follow Mundilova ch. 1 with n₁ := the cylinder's OUTWARD normal
///       ρ(u) = (−cos u, sin u, 0) and b_i = t × n_i. Then, with the Frenet frame (t, n, b):
///         n = −sin φ ρ + cos φ b₁,  b = −cos φ ρ − sin φ b₁,
///         n₁ = −sin φ n − cos φ b,  b₁ = cos φ n − sin φ b,
///         n₂ =  sin φ n − cos φ b = cos 2φ ρ + sin 2φ b₁  (= −R n₁, R the reflection in the
///                                                         osculating plane),
///         b₂ =  cos φ n + sin φ b = R b₁,
///       so cos φ = n·b₁ = n·b₂ (thesis eq. in ch. 1) with φ ∈ (0, π/2). With the inward normal
///       (the thesis' n₁ = p′ × e₃ for this p) the same crease has the thesis angle φ − π.
///       The thesis' geodesic curvature κ_d = −t′·b_i/|c′| = −κ cos φ = −cot φ / cosh²(u cot φ);
///       the catenary's signed curvature (left normal J t̄) is +cot φ / cosh² — the thesis'
///       sign convention is opposite to the signed curvature of the development.
/// \note The oriented sheet normals of FoldSamples' convention are N₁ = −n₁ and N₂ = −n₂ for
///       either side (flipping r flips both c′ × r and det(c̄′, r̄)); N₁ + N₂ = 2 cos φ b.
class CylinderCatenaryCrease {
 public:
  /// @param[in] phi  crease angle φ ∈ (0, π/2): angle between the osculating plane and the
  ///                 cylinder's tangent plane (and, by the bisector property, the second sheet's)
  /// @param[in] u0, u1  parameter interval, u0 < u1
  /// @param[in] rulingLength  L > 0: length of the rulings of each sheet
  /// @param[in] side  +1 or −1, see the class comment
  /// @throws std::invalid_argument on values out of range
  CylinderCatenaryCrease(double phi, double u0, double u1, double rulingLength, int side = +1);

  double phi() const { return phi_; }
  double u0() const { return u0_; }
  double u1() const { return u1_; }
  double rulingLength() const { return length_; }
  int side() const { return side_; }

  /// h(u) = tan φ cosh(u cot φ) and its derivatives (order ≥ 0).
  double height(double u, int derivative = 0) const;
  /// c(u) and its derivatives (order ≥ 0).
  Eigen::Vector3d crease(double u, int derivative = 0) const;
  /// c̄(u) = (u, h(u)) and its derivatives (order ≥ 0).
  Eigen::Vector2d developedCrease(double u, int derivative = 0) const;

  Eigen::Vector3d tangent(double u) const;            ///< t = c′/|c′|
  Eigen::Vector3d principalNormal(double u) const;    ///< n (Frenet)
  Eigen::Vector3d osculatingNormal(double u) const;   ///< b = t × n, normal of the osculating plane
  /// Darboux normal n_i of sheet i ∈ {0, 1} (see the class \note; n₁ = outward cylinder normal).
  Eigen::Vector3d sheetNormal(int sheet, double u) const;
  /// Darboux binormal b_i = t × n_i of sheet i ∈ {0, 1}.
  Eigen::Vector3d sheetBinormal(int sheet, double u) const;

  /// The second sheet's tangent plane family n₂(u)·x = d₂(u): returns n₂ or its derivatives
  /// (order 0, 1, 2), exact.
  Eigen::Vector3d secondPlaneNormal(double u, int derivative = 0) const;
  /// d₂(u) = n₂·c and its derivatives (order 0, 1).
  double secondPlaneOffset(double u, int derivative = 0) const;

  /// Unit ruling direction r_i of sheet i ∈ {0, 1} pointing into its patch, or its
  /// u-derivative (order 0, 1). Sheet 0: side·e₃; sheet 1: the normalized n₂ × n₂′ (oriented).
  Eigen::Vector3d ruling(int sheet, double u, int derivative = 0) const;
  /// Developed ruling r̄_i (unit) or its u-derivative (order 0, 1).
  Eigen::Vector2d developedRuling(int sheet, double u, int derivative = 0) const;

  /// Signed curvature of the developed crease (left normal): cot φ / cosh²(u cot φ); equal to
  /// the geodesic curvature det(c′, c″, N_i)/|c′|³ of c on both sheets (FoldSamples'
  /// orientation convention).
  double developedCurvature(double u) const;

  /// v at which the ruling c(u) + v r_i(u) meets the sheet's edge of regression,
  /// v* = −(c′·r′)/|r′|² (+∞ where r′ = 0, e.g. always on the cylinder). The patch is regular
  /// where v* ∉ (0, L].
  double regressionParameter(int sheet, double u) const;

  /// Samples u_j = u0 + (u1 − u0) j/(n−1), j = 0..n−1 (n ≥ 2), with exact derivatives.
  FoldSamples sample(int n) const;

  QuadMesh3 sheetMesh(int sheet, int n) const;        ///< see surfaceMesh
  QuadMesh2 developmentMesh(int sheet, int n) const;  ///< see creases::developmentMesh
  Eigen::MatrixX3d creasePolyline(int n) const;       ///< n×3
  Eigen::MatrixX2d developedCreasePolyline(int n) const;  ///< n×2, the catenary

 private:
  double phi_, u0_, u1_, length_;
  int side_;
  double k_;  // cot φ
  double a_;  // tan φ
};

}  // namespace devsurf::creases
