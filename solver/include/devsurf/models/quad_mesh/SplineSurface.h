#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "devsurf/models/quad_mesh/QuadMeshDesign.h"

namespace devsurf::models::quad_mesh {

/// S^k(M) of a control net (004_… §4, Algorithm 2) as one mesh: every patch refined by
/// spline::cubicGridSubdivisionMatrix, the refined vertices of shared sides merged (two refined
/// vertices are one when their rows of S are equal, which on a shared side they are exactly: a
/// boundary curve's refinement depends on its own control points only).
struct SplineRefinement {
  /// V × P: refined vertex v = Σ_j S(v, j) · control point j.
  Eigen::SparseMatrix<double> subdivision;
  std::vector<Face> faces;  ///< the refined quads, patch by patch, counter-clockwise as the patches
  /// Per patch: its refined grid (R_p × C_p, row-major) as indices of refined vertices.
  std::vector<std::vector<int>> patchVertices;
  std::vector<std::array<int, 2>> patchGridSize;  ///< (R_p, C_p) per patch
};

/// @throws std::invalid_argument naming the field ("control.patches[2].indices[5]: …") when the net
///         has fewer than 4 rows or columns in a patch, rounds outside 0 … 4, points not finite or
///         of another count, indices out of range or repeated in a patch, points no patch uses, a
///         side shared by more than two patches, or two patches whose shared side runs the same
///         way in both boundary loops (their faces would face opposite ways)
SplineRefinement splineRefinement(const ControlNet& net);

/// Two patches sharing a side: patch a's side sideA and patch b's side sideB (0 … 3 in loop
/// order: row 0, last column, last row, column 0), run in opposite directions.
struct SharedSide {
  int patchA = 0, sideA = 0, patchB = 0, sideB = 0;
};
std::vector<SharedSide> splineSharedSides(const ControlNet& net);

/// The smoothness rows across shared sides: for each point b of a shared side, (a, b, c) with a
/// its neighbour across the side in one patch and c in the other (control-point indices). a − 2b
/// + c = 0 makes the cross-boundary derivatives of the two bicubic patches equal along the whole
/// side (both have uniform knots of the same spacing), so M^∞ is C1 there, hence G1.
std::vector<std::array<int, 3>> splineSmoothnessTriples(const ControlNet& net);

/// One patch of M^∞ as a B-spline surface: degree 3 × 3, clamped knots with uniform interior
/// knots 0, 1, …, n − 3 (integers: written exactly to IGES and STEP); points(i + nu·j) = P_{i,j}
/// with i along u = the patch's columns and j along v = its rows (u fastest, IGES order).
struct SplinePatchSurface {
  int nu = 0, nv = 0;
  std::vector<double> knotsU, knotsV;
  Eigen::MatrixX3d points;
};
std::vector<SplinePatchSurface> splinePatchSurfaces(const ControlNet& net, const Eigen::MatrixX3d& points);

/// Analysis options; defaults as documented.
struct SplineAnalysisOptions {
  int samplesPerSpan = 8;       ///< curvature samples per knot span and direction
  /// Rulings are traced from seeds this many per span and direction (0 = no rulings).
  int rulingSeedsPerSpan = 1;
  /// A sample counts as developable and curved when |K| ≤ developableRatio · κ_max² and
  /// |κ_max| · diameter ≥ curvedMin (planar parts have no rulings).
  double developableRatio = 0.02;
  double curvedMin = 0.05;
};

/// The spline M^∞ itself, sampled densely (issue 14 "verification on the spline itself").
struct SplineSurfaceAnalysis {
  double diameter = 0.0;         ///< bounding-box diagonal of the samples (design units)
  double gaussMaxScaled = 0.0;   ///< max |K| · diameter² over all samples
  double gaussMeanScaled = 0.0;  ///< area-weighted mean of |K| · diameter²
  int sharedSides = 0;
  /// Largest angle (degrees) between the normals of two patches at common points of a shared
  /// side, sampled samplesPerSpan per span; 0 without shared sides.
  double normalJumpMaxDegrees = 0.0;
  /// Per patch: the sample grid ((spans_v·s + 1) × (spans_u·s + 1), row-major, rows along v) and
  /// K there.
  std::vector<std::array<int, 2>> sampleGridSize;
  std::vector<Eigen::MatrixX3d> samples;
  std::vector<Eigen::VectorXd> gauss;
  /// Traced rulings where the surface is developable and curved: polylines on M^∞ that follow the
  /// principal direction of least |κ| (straight on a developable).
  std::vector<Eigen::MatrixX3d> rulings;
};

/// @param[in] points  the net's control points, P×3 (the net's own are ignored: pass the solved)
SplineSurfaceAnalysis analyzeSplineSurface(const ControlNet& net, const Eigen::MatrixX3d& points,
                                           const SplineAnalysisOptions& options = {});

}  // namespace devsurf::models::quad_mesh
