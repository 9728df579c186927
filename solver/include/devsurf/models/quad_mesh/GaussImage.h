#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/GuidedProjectionSolver.h"

namespace devsurf::models::quad_mesh {

/// Weights and iterations of the Gauss image solve (004_… §2.3.1, §3.2: w_norm E_norm +
/// w_sym E_sym + w_fair E_fair → min with M fixed). Weights multiply residuals (the solver
/// minimizes Σ (w r)²) and refer to M scaled to a unit bounding-box diagonal.
struct GaussImageOptions {
  double normalWeight = 1.0;     ///< w_norm of eq. 3 (GaussImageNormalTerm), Fig. 22 row 6
  double symmetryWeight = 1.0;   ///< w_sym of eq. 5 (ShapeOperatorSymmetryTerm), Fig. 22 row 6
  double fairnessWeight = 0.01;  ///< w_fair of n_i − 2n_j + n_k on the polyline triples
  /// Weight of (I − u_i u_iᵀ) n_i, u_i the unit start normal: keeps each normal near the
  /// direction it started in (its length stays free). Not in the paper: on a developable, eq. 3
  /// and 5 have a family of exact solutions (on a cone of axis a and half angle α the constant
  /// n_i = ±a / sin α satisfies both, with zero fairness energy), and without this
  /// anchor the fairness term drifts the normals toward that degenerate Gauss image (H → 0) a
  /// little more with every iteration. 0.001 makes the solve converge in a few steps without
  /// changing K on curved surfaces measurably.
  double anchorWeight = 0.001;
  /// Guided-projection iterations. With M fixed all rows are linear in the normals, so the solve
  /// is a linear least-squares problem that the regularized steps approach geometrically.
  int iterations = 10;
  double regularization = 1e-4;  ///< ε_reg of the steps (small: the problem is linear)
};

/// Vertex normals of a quad mesh M as its Gauss image (004_… §2.2.1, §3.2), with M fixed.
///
/// Solves eq. 3 (w_norm, hard), eq. 5 (w_sym, hard), the second differences n_i − 2n_j + n_k
/// along the mesh polylines (w_fair, soft) and the direction anchor (anchorWeight, soft) for one
/// normal per vertex, starting from unit area-weighted vertex normals (a quad weighs
/// (v2 − v0) × (v3 − v1) / 2, a triangle (v1 − v0) × (v2 − v0) / 2). The
/// normals point to the front side of the faces (counter-clockwise seen from there) and are not
/// unit vectors: they make every 'black' parallelogram of the normal mesh touch the unit sphere.
/// Feed them to metrics::checkerboardCurvature for K, H and principal directions.
/// @param[in] mesh             V×3 vertices of M (any scale: solved at unit size, normals do not
///                             depend on it)
/// @param[in] faces            vertex indices, counter-clockwise from the front; `[3] = -1` for a
///                             triangle
/// @param[in] polylineTriples  successive vertices (i, j, k) on mesh polylines
///                             (QuadMeshTopology::polylineTriples)
/// @param[in] options          weights and iterations
/// @param[out] summary         the engine's summary of the solve, if not null
/// @return V×3 vertex normals
/// @throws std::invalid_argument on an index out of range, a repeated vertex in a face or a
///         triple, or a vertex in no face
Eigen::MatrixX3d solveGaussImage(const Eigen::MatrixX3d& mesh,
                                 const std::vector<std::array<int, 4>>& faces,
                                 const std::vector<std::array<int, 3>>& polylineTriples,
                                 const GaussImageOptions& options = {},
                                 engine::SolveSummary* summary = nullptr);

}  // namespace devsurf::models::quad_mesh
