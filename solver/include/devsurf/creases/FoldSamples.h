#pragma once

#include <Eigen/Core>

namespace devsurf::creases {

/// A quad mesh in space (same layout as io::QuadMesh, kept here so that the creases layer
/// depends on nothing but Eigen).
struct QuadMesh3 {
  Eigen::MatrixX3d vertices;  ///< m×3
  Eigen::MatrixX4i quads;     ///< f×4 vertex indices
};

/// A quad mesh in the plane (a development).
struct QuadMesh2 {
  Eigen::MatrixX2d vertices;  ///< m×2
  Eigen::MatrixX4i quads;     ///< f×4 vertex indices, counter-clockwise in the plane
};

/// One developable patch (sheet) bounded by a crease, sampled at n crease parameters u_0<…<u_{n−1}:
/// the ruling segment from the crease point c(u_i) to its end c(u_i) + L r(u_i) (r unit, pointing
/// into the patch), in space and in the development (c̄(u_i), c̄(u_i) + L r̄(u_i)).
///
/// The derivative blocks hold exact u-derivatives of the four boundary curves when the producer
/// knows them in closed form; they have 0 rows otherwise. Because the patch is ruled,
/// X(u,v) = c(u) + v r(u), the u-derivative along a ruling interpolates linearly between
/// dCrease (v = 0) and dRulingEnd (v = L), so the four derivative blocks determine the first
/// fundamental form on the whole patch.
struct SheetSamples {
  Eigen::MatrixX3d crease;        ///< n×3, c(u_i)
  Eigen::MatrixX3d rulingEnd;     ///< n×3, c(u_i) + L r(u_i)
  Eigen::MatrixX2d devCrease;     ///< n×2, c̄(u_i)
  Eigen::MatrixX2d devRulingEnd;  ///< n×2, c̄(u_i) + L r̄(u_i)
  Eigen::MatrixX3d dCrease, dRulingEnd;        ///< n×3 or 0×3: c′(u_i), c′(u_i) + L r′(u_i)
  Eigen::MatrixX2d dDevCrease, dDevRulingEnd;  ///< n×2 or 0×2: c̄′(u_i), c̄′(u_i) + L r̄′(u_i)

  int size() const { return static_cast<int>(crease.rows()); }
  bool hasDerivatives() const {
    return dCrease.rows() == crease.rows() && dRulingEnd.rows() == crease.rows() &&
           dDevCrease.rows() == crease.rows() && dDevRulingEnd.rows() == crease.rows() &&
           crease.rows() > 0;
  }
};

/// A sampled curved fold: the crease polyline and the two sheets on either side of it.
///
/// \note Orientation convention (shared by every producer in devsurf::creases): the crease is
///       traversed by increasing u; each sheet's development lies in the plane with its usual
///       orientation (normal +z), and a sheet's oriented unit normal in space is the one the
///       development maps to +z, N = sign(det(c̄′, r̄)) (c′ × r)/|c′ × r|. For a curved fold
///       (paper folded without cutting) the two developments share the developed crease and lie
///       on opposite sides of it; then N₁ + N₂ is normal to the crease's osculating plane and
///       the geodesic curvatures κ_g = det(c′, c″, N)/|c′|³ agree (Tang et al. eq. 7*).
struct FoldSamples {
  Eigen::VectorXd u;           ///< n crease parameters
  Eigen::MatrixX3d crease;     ///< n×3 crease polyline c(u_i)
  Eigen::MatrixX3d creaseD1;   ///< n×3 c′(u_i), or 0 rows when unknown
  Eigen::MatrixX3d creaseD2;   ///< n×3 c″(u_i), or 0 rows when unknown
  SheetSamples sheet[2];       ///< [0]: first sheet, [1]: second sheet

  int size() const { return static_cast<int>(crease.rows()); }
  bool hasDerivatives() const {
    return creaseD1.rows() == crease.rows() && creaseD2.rows() == crease.rows() &&
           crease.rows() > 0 && sheet[0].hasDerivatives() && sheet[1].hasDerivatives();
  }
};

/// The sheet as a quad strip: vertex 2i is c(u_i), vertex 2i+1 the ruling end; quad i joins the
/// rulings i and i+1, ordered so that it is counter-clockwise in the development (and hence
/// oriented by the normal N of FoldSamples' convention in space).
QuadMesh3 surfaceMesh(const SheetSamples& sheet);

/// The development of the sheet with the same vertex and quad layout as surfaceMesh.
QuadMesh2 developmentMesh(const SheetSamples& sheet);

}  // namespace devsurf::creases
