#pragma once

#include <optional>

#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "devsurf/engine/Deadline.h"
#include "devsurf/engine/GuidedProjectionSolver.h"
#include "devsurf/engine/LinearSolver.h"
#include "devsurf/engine/Normalization.h"
#include "devsurf/engine/Problem.h"
#include "devsurf/models/quad_mesh/QuadMeshDesign.h"
#include "devsurf/models/quad_mesh/QuadMeshTopology.h"

namespace devsurf::models::quad_mesh {

/// Model switches; defaults as documented.
struct QuadMeshOptions {
  bool normalize = true;  ///< solve with M scaled to diameter 1 (M′ by the same factor)
  engine::LinearSolverKind linearSolver = engine::LinearSolverKind::Auto;  ///< fixed at build
  /// Checked while the model is built (engine::DeadlineExceeded); solves have their own.
  engine::Deadline deadline;
  /// From this many free unknowns on, solve() reuses the first factorization of every round for
  /// the round's later steps (engine::FactorizationReuseOptions: CG preconditioned with it, the
  /// steps to a relative residual of kReuseTolerance; a factorization again when CG needs more
  /// than 10 solves), unless the caller's options already ask for reuse. Measured with
  /// bench/quad_mesh_iteration (saddle, M and M′ variable, docs/architecture.md "quad_mesh
  /// performance"): from ~40 000 unknowns the factorization is most of an iteration and 2–5
  /// preconditioned solves replace it (40 500: 264 → 101 ms per iteration; 250 880: 3.57 →
  /// 0.88 s); at 10 000 a factorization costs ~10 solves.
  int factorizationReuseFrom = 40000;
};

/// Relative residual ‖H δ + g‖ ≤ tol · ‖g‖ to which a step is solved with an earlier
/// factorization (an inexact Gauss–Newton step). 1e-3 against 1e-6 (stop 35, bench medians, one
/// core): 10 iterations at 250 880 unknowns 11.7 → 8.8 s, 100 820: 4.4 → 3.4 s, 40 500: 1.6 →
/// 1.0 s (preconditioned solves 35 → 18, 44 → 27, 54 → 27); L-Err after them changes in the 6th
/// digit (0.0372543 → 0.0372541; at 250 880: 0.0844339 both).
inline constexpr double kReuseTolerance = 1e-3;

/// The isometry quality of Fig. 22 and the gluing, in the design's units.
struct QuadMeshQuality {
  double lengthError = 0.0;     ///< L-Err: ‖L′ − L‖ / ‖L‖ over all edges (a fraction, not %)
  double edgeLengthErrorMax = 0.0;  ///< max over edges of |l′ − l| / l: one edge stretched, which
                                    ///< L-Err (weighted by l²) hides among many long ones
  double areaError = 0.0;       ///< A-Err: ‖A′ − A‖ / ‖A‖ over faces (a quad: mean of both
                                ///< triangulations)
  double isometryResidualMax = 0.0;  ///< max |c_iso,j(f)| ÷ diameter(M)² (eq. 1; conformal: eq. 2)
  double glueGapMax = 0.0;      ///< max ‖v_a − v_b‖ of a glued pair ÷ diameter(M)
  double handleDistanceMax = 0.0;  ///< max distance of a handled vertex from its target (units)
  double unfoldingFlippedFaces = 0; ///< faces of a planar M′ turned clockwise (negative area)
  Eigen::VectorXd edgeLengthError;  ///< per edge (topology().edges()) (l′ − l) / l
};

/// Per-face curvatures of M from the Gauss image (004_… §2.2, eq. 4): filled by curvature().
struct QuadMeshCurvature {
  Eigen::MatrixX3d normals;       ///< V×3 unit vertex normals n_i (the Gauss image σ(M))
  Eigen::VectorXd gauss, mean;    ///< K(f), H(f), F values (units 1/length², 1/length)
  Eigen::VectorXd kappa1, kappa2; ///< principal curvatures κ1 ≥ κ2
  Eigen::MatrixX3d direction1, direction2, ruling;  ///< unit vectors per face
};

/// What one Algorithm-1 solve did: the engine's per-iteration records over all rounds (numbered
/// on), the rounds run and the fairness weight of each.
struct QuadMeshSolveSummary {
  engine::SolveSummary summary;
  int rounds = 0;
  std::vector<double> roundFairness;  ///< w_fair,M (or M′ when M is fixed) per round
  bool isometryReached = false;       ///< E_iso ≤ schedule.isometryMin at the end
};

/// Quad-mesh isometries and discrete developables (Jiang et al. 2020, 004_…): M and M′ with
/// congruent checkerboard patterns (eq. 1), or similar ones (eq. 2), solved by guided projection
/// under Algorithm 1.
///
/// Variables (normalized: M centred and scaled to diameter 1, M′ centred and scaled by the same
/// factor): "mesh" (3 per vertex), "unfolding" (3 per vertex; z fixed when planar), "conformal
/// factors" (one per face, when conformal). Fixed meshes and vertices leave the system.
/// Terms: "isometry" (hard, eq. 1) or "conformality" (hard, eq. 2) + "conformal_factor" (soft);
/// "glue" (hard, E_pos pairs); "handle" (soft, one per handle, relaxable); "fairness_mesh",
/// "fairness_unfolding" (soft, Algorithm 1 lowers them); "proximity_point", "proximity_plane"
/// (soft, foot points on the reference renewed every iteration); "mapping" (soft, E_map; constant:
/// lowering it with the fairness let the lattices drift apart again, L-Err 0.14 % → 1.2 % on the
/// bent-sheet preset).
class QuadMeshModel {
 public:
  /// @throws std::invalid_argument naming the part ("handles[2].vertex: …", "faces[7]: …")
  explicit QuadMeshModel(QuadMeshDesign design, QuadMeshOptions options = {});
  ~QuadMeshModel();

  /// The checks the constructor makes, without building anything.
  /// @throws std::invalid_argument
  static void validateDesign(const QuadMeshDesign& design);

  /// Algorithm 1 from the current state: `options.maxIterations` bounds the steps of all rounds
  /// together; `options.firstIteration` resumes the schedule (round = firstIteration ÷
  /// roundIterations); fairness/fairnessDecay of `options` are not used (the schedule's are).
  QuadMeshSolveSummary solve(const engine::SolverOptions& options);

  /// The design with the current geometry (design units; λ_f when conformal).
  QuadMeshDesign design() const;
  const QuadMeshTopology& topology() const { return topology_; }
  /// M and M′ in design units (V×3).
  Eigen::MatrixX3d meshVertices() const;
  Eigen::MatrixX3d unfoldingVertices() const;
  /// The control points of a spline-surface design (design units; empty without a control net).
  /// Then meshVertices() is S^k of them exactly.
  Eigen::MatrixX3d controlPoints() const;
  /// Weight of the hard map S^k(M) = S·M (normalized units) in a spline-surface design.
  static constexpr double kSubdivisionWeight = 10.0;

  void setHandleTarget(int i, const Eigen::Vector3d& target);
  void setHandleWeight(int i, double weight);
  int handleCount() const { return static_cast<int>(design_.handles.size()); }
  /// The reference Φ of the proximity energies, if the design has one (design units).
  const std::optional<ReferenceSurface>& reference() const { return design_.reference; }

  QuadMeshQuality quality() const;
  /// Per-face curvatures of the current M by eq. 4 with unit area-weighted vertex normals (see the
  /// .cpp for why not solveGaussImage's).
  QuadMeshCurvature curvature() const;

  engine::Problem& problem() { return problem_; }
  const engine::Problem& problem() const { return problem_; }
  engine::GuidedProjectionSolver& solver() { return *solver_; }
  int numUnknowns() const { return problem_.layout().numFree(); }
  /// The weight of the fairness terms in round r of Algorithm 1.
  double fairnessWeight(double roundZeroWeight, int round) const;

 private:
  void buildProblem();
  int pointOffset(const VertexRef& v) const;
  const engine::Normalization& normalizationOf(MeshSide side) const;

  QuadMeshDesign design_;  ///< faces, constraints, weights; positions live in x
  QuadMeshOptions options_;
  QuadMeshTopology topology_;
  engine::Normalization meshNormalization_, unfoldingNormalization_;
  engine::Problem problem_;
  std::unique_ptr<engine::GuidedProjectionSolver> solver_;
  int blockMesh_ = -1, blockUnfolding_ = -1, blockFactors_ = -1, blockControl_ = -1;
  Eigen::SparseMatrix<double> subdivision_;  ///< S^k for a control net (design_.control), else empty
  /// Patches of every refined vertex when patches may meet at an angle (several patches, no
  /// smoothness asked): E_fair on S^k(M) keeps to polylines within one patch. Else empty.
  std::vector<std::vector<int>> patchesOfVertex_;
  /// Whether the refined vertices all lie in one patch (always, when patchesOfVertex_ is empty).
  bool inOnePatch(const int* vertices, int count) const;
  int isometryTerm_ = -1, factorTerm_ = -1, glueTerm_ = -1;
  double isometryRowScale_ = 0.0;  ///< mean squared diagonal of M′ at build (normalized)
  int fairnessMeshTerm_ = -1, fairnessUnfoldingTerm_ = -1, mappingTerm_ = -1;
  std::vector<int> handleTerms_;
};

}  // namespace devsurf::models::quad_mesh
