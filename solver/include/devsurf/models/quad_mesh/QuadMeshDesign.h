#pragma once

#include <array>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "devsurf/models/quad_mesh/QuadMeshTopology.h"

namespace devsurf::models::quad_mesh {

/// Which of the two combinatorially equal meshes a vertex reference means: M (the surface in
/// space) or M′ (the unfolding: planar, or a second surface).
/// Which points a vertex reference addresses: M, M′, or (spline-surface designs only) the
/// control points of the control net, whose refinement is M.
enum class MeshSide { Mesh, Unfolding, Control };
const char* meshSideName(MeshSide side);  ///< "mesh", "unfolding", "control"

/// Which meshes the optimization moves (004_… §3.1: either or both).
enum class VariableMeshes { Mesh, Unfolding, Both };
const char* variableMeshesName(VariableMeshes v);  ///< "mesh", "unfolding", "both"

struct VertexRef {
  MeshSide on = MeshSide::Mesh;
  int vertex = 0;
  bool operator==(const VertexRef& o) const { return on == o.on && vertex == o.vertex; }
};

/// A vertex pulled toward a target (E_pos, first sum; the browser's drag).
struct VertexHandle {
  VertexRef vertex;
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  ///< design units; z ignored on a planar M′
  double weight = 1.0;                               ///< multiplies QuadMeshWeights::position
};

/// Two vertices of one mesh forced together (E_pos, second sum): gluing, cutting and gluing,
/// D-forms, zero-width holes for curved folds (004_… §5).
struct GluePair {
  MeshSide on = MeshSide::Mesh;
  int a = 0, b = 0;
};

/// The reference shape Φ of the proximity energies (004_… §2.3.2): a triangle mesh.
struct ReferenceSurface {
  Eigen::MatrixX3d vertices;   ///< R×3
  Eigen::MatrixX3i triangles;  ///< T×3, indices into vertices
};

/// Weights of Fig. 22 (scene "weights"; defaults as Fig. 7: w_iso = w_pos = 1, w_fair = 0.1).
struct QuadMeshWeights {
  double isometry = 1.0;          ///< w_iso, eq. 1 (hard)
  double conformality = 1.0;      ///< w_conf, eq. 2 (hard; replaces eq. 1 when conformal)
  double conformalFactor = 0.1;   ///< w_λ, E_λ = Σ(λ_f − 1)²
  double position = 1.0;          ///< w_pos: handles (× their weight) and gluing
  double fairnessMesh = 0.1;      ///< w_fair,M at round 0 of Algorithm 1 (0 = off)
  double fairnessUnfolding = 0.1; ///< w_fair,M′ at round 0 (0 = off)
  double proximityPoint = 0.0;    ///< w_prox,1 (needs a reference)
  double proximityPlane = 0.0;    ///< w_prox,2 (needs a reference)
  /// w_map, E_map (0 = off). Default 1, a departure from Fig. 22 (which lists no w_map): eq. 1
  /// couples only vertices of equal parity along the diagonals, and E_map ties the two lattices
  /// together without resisting bending (docs/architecture.md "quad_mesh").
  double mapping = 1.0;
  double normals = 1.0;           ///< w_norm, eq. 3 (Gauss image)
  double symmetry = 1.0;          ///< w_sym, eq. 5 (Gauss image)
};

/// Algorithm 1 (004_… §2.3.3): rounds of at most `roundIterations` guided-projection steps that
/// end early once E ≤ energyMin (or E stops changing); after each round w_fair ← w_fair / divisor;
/// done when E_iso ≤ isometryMin or after `rounds` rounds (or the solve's iteration limit).
struct IsometrySchedule {
  double energyMin = 1e-12;     ///< E_min (normalized units: the mesh has diameter 1)
  double isometryMin = 1e-12;   ///< E_iso,min
  int roundIterations = 10;     ///< iterations per round at most
  int rounds = 3;               ///< rounds at most
  double fairnessDivisor = 10;  ///< w_fair is divided by this after every round (≥ 1)
};

/// One rectangular patch of a control mesh: a rows × columns grid of indices into
/// ControlNet::points, grid point (r, c) at r·columns + c. Its boundary polylines are the four
/// sides of the grid; the patch's faces are counter-clockwise seen from the front when rows run
/// along +y and columns along +x, so its boundary loop is row 0 (c ascending), column C−1 (r
/// ascending), row R−1 (c descending), column 0 (r descending).
struct ControlPatch {
  int rows = 0, columns = 0;  ///< ≥ 4 each
  std::vector<int> indices;   ///< rows·columns control-point indices, pairwise distinct
};

/// The control mesh M of a developable spline surface (004_… §4, Algorithm 2; issue 14): control
/// points grouped into rectangular patches, each the control net of a bicubic clamped B-spline
/// surface with uniform interior knots; M^∞, the union of those surfaces, is the design. A design
/// with one has `mesh` = S^k(M), every patch refined by `rounds` rounds of eq. 8 (spline::
/// cubicGridSubdivisionMatrix) and the refined grids merged where patches share a side, and the
/// optimization moves the control points: S^k(M) follows them through a hard linear map
/// (LinearPointMapTerm) while eq. 1 holds it isometric to M′.
///
/// Patches that share a boundary polyline (a whole side, the same control points, run in opposite
/// directions by their boundary loops) share their boundary curve, which depends on those points
/// only: the model is watertight by construction. Smoothness across such a side is asked with
/// `smoothness` > 0 (see splineSmoothnessTriples).
struct ControlNet {
  /// The single-patch form: a rows × columns grid over all points in order (used when `patches`
  /// is empty; 0 otherwise).
  int rows = 0, columns = 0;
  int rounds = 2;             ///< k, 0 … 4 (Algorithm 2's default 2)
  Eigen::MatrixX3d points;    ///< all control points, design units
  std::vector<ControlPatch> patches;  ///< empty: one patch rows × columns
  /// Weight of the soft smoothness across shared sides (normalized units; 0 = not asked): per
  /// point b of a shared side with its neighbours a, c across it, a − 2b + c (C1 in the uniform
  /// parametrization, which implies G1).
  double smoothness = 0.0;
};

/// The patches of a net: `patches`, or the single-patch form as one patch.
std::vector<ControlPatch> controlPatches(const ControlNet& net);

/// Everything that defines a quad-mesh design (scene kind "quad_mesh").
struct QuadMeshDesign {
  std::vector<Face> faces;             ///< F faces, ccw seen from the front; triangles [3] = −1
  Eigen::MatrixX3d mesh;               ///< M, V×3
  /// M′, V×3 (z = 0 when planar). Empty when the scene gave none: the model then starts it as M
  /// projected onto its least-squares plane (only allowed when M′ is a variable).
  Eigen::MatrixX3d unfolding;
  bool unfoldingPlanar = true;         ///< M′ lies in the plane z = 0
  VariableMeshes variable = VariableMeshes::Mesh;
  bool conformal = false;              ///< eq. 2 with per-face λ_f and E_λ instead of eq. 1
  bool gaussImage = false;             ///< report curvatures (vertex normals of the Gauss image)
  std::vector<VertexRef> fixed;
  std::vector<VertexHandle> handles;
  std::vector<GluePair> glue;
  std::optional<ReferenceSurface> reference;
  QuadMeshWeights weights;
  IsometrySchedule schedule;
  /// Per-face conformal factors λ_f (F values) of a conformal design after a solve; empty = 1.
  std::vector<double> conformalFactors;
  /// Set for a developable spline surface: `mesh` and `faces` are then its refined grid
  /// (splineSurfaceDesign builds them).
  std::optional<ControlNet> control;
};

/// A design for Algorithm 2: `mesh` = S^k(M) of the control net, `faces` the refined grid's quads
/// (counter-clockwise when rows run along +y and columns along +x), M′ left to the model (its
/// least-squares-plane projection of S^k(M)), both S^k(M) (through M) and M′ variable, weights and
/// schedule at their defaults.
/// @throws std::invalid_argument if the net has fewer than 4 rows or columns, rounds outside
///         0 … 4, or points of another count or not finite
QuadMeshDesign splineSurfaceDesign(ControlNet net);

}  // namespace devsurf::models::quad_mesh
