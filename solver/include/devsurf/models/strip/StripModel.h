#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/GuidedProjectionSolver.h"
#include "devsurf/engine/Normalization.h"
#include "devsurf/engine/Problem.h"
#include "devsurf/io/QuadMesh.h"
#include "devsurf/metrics/StripQuality.h"
#include "devsurf/spline/Basis.h"
#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/terms/LinearPoints.h"

namespace devsurf::models::strip {

/// Which boundary curve a control point belongs to.
enum class Curve { A, B };
const char* curveName(Curve c);

/// A control point addressed the way the scene does: {"curve": "b", "index": 4}.
struct ControlPointRef {
  Curve curve = Curve::A;
  int index = 0;
  bool operator==(const ControlPointRef& o) const { return curve == o.curve && index == o.index; }
};

/// A control point pulled toward a target with a weight (the drag mechanism).
struct Handle {
  ControlPointRef point;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double weight = 1.0;
};

/// How the normals of eq. (3)/(4) are represented (000_… §2.2).
struct NormalRepresentation {
  enum class Type { Vectors, Spline };
  Type type = Type::Vectors;  ///< one free vector per evaluation parameter, or a normal spline
  int degree = 3;             ///< normal spline degree
  int points = 0;             ///< normal spline control points (0 = one per curve control point)
};

/// Reference points the strip approximates (000_… §4.2): thinned points q_j with normals m_j from
/// a local plane fit (reference::thinPointCloud), and the weights of eq. (9)–(11). Defaults are
/// the paper's (Fig. 17, footnote **): 1e-3, 1e-4, 1e-2.
struct ApproximationTarget {
  Eigen::MatrixX3d points;            ///< q_j, N×3 (design coordinates)
  Eigen::MatrixX3d normals;           ///< m_j, N×3 (any length > 0; normalized when used)
  double pointWeight = 1e-3;          ///< eq. (9): s(u_j, v_j) − q_j
  double tangencyWeight = 1e-4;       ///< eq. (10): ⟨m_j, a − b⟩, ⟨m_j, a′⟩ at u_j
  double tangentPlaneWeight = 1e-2;   ///< eq. (11): ⟨s(u_j, v_j) − q_j, n(u_j)⟩
  /// Not in the paper: the strip's own samples farther than overhangReach from every q_j pulled
  /// back (terms::StripOverhangTerm), so that a strip on a bounded or doubly curved region does not
  /// spread where no point holds it. 0 = off (eq. 9–11 alone, as the paper).
  double overhangWeight = 0.0;
  /// ρ of the overhang rows in design units; 0 = twice the median distance from a q_j to its
  /// nearest other q_j (a thinned cloud's spacing).
  double overhangReach = 0.0;
};

/// A neighbouring strip's boundary that one of this strip's curves is to follow (000_… §4.2,
/// Fig. 10d: "proximity of boundaries as an additional optimization goal"): samples of the curve
/// at regularly spaced parameters are kept on the tangent lines of the polyline at their closest
/// points (terms::CurveTangentLineDistanceTerm, soft, "boundary_proximity"), renewed every
/// iteration. Used by models::strip::pairStripBoundaries; not a scene field.
struct BoundaryTarget {
  Curve curve = Curve::A;
  /// The other boundary (design coordinates), ≥ 2 points, ordered from the end that this curve's
  /// start is to meet.
  Eigen::MatrixX3d polyline;
  double weight = 0.1;   ///< assembler weight of the rows
  int samples = 0;       ///< samples of the curve; 0 = 4 per control point
  bool pinEnds = true;   ///< the curve's ends are held at the polyline's ends too
};

/// Everything that defines a strip design: the two boundary curves and the user's constraints.
/// Curves a and b share degree, knots and closedness; weights (NURBS) are held constant.
struct StripDesign {
  spline::BSplineCurve a, b;
  NormalRepresentation normals;
  std::vector<ControlPointRef> fixed;
  std::vector<Handle> handles;
  /// Reference points to approximate (scene field "approximation"); none by default.
  std::optional<ApproximationTarget> approximation;
  /// Neighbouring boundaries to follow (not a scene field; see BoundaryTarget).
  std::vector<BoundaryTarget> boundaryTargets;
};

/// Weights and switches of the strip model; defaults as documented in proto/schemas.
struct StripOptions {
  double developabilityWeight = 1.0;  ///< hard developability rows (eq. 4)
  double unitNormalWeight = 0.1;      ///< soft unit length of normals not held hard (ε_unit)
  /// Multiplier of ε_reg² for the normals (auxiliary variables). Small, so that a step rotates
  /// normals rather than collapsing the strip (rulings shrinking to zero length also satisfy
  /// eq. 4 to first order and need no normal to turn).
  double normalRegularizationScale = 1e-4;
  bool normalize = true;              ///< centre and scale to unit size while solving (003_… §5.5)
  engine::LinearSolverKind linearSolver = engine::LinearSolverKind::Auto;  ///< fixed when the model is built
  /// Degeneracy guard (terms::RulingLengthTerm, hard, "ruling_length"): no ruling at an evaluation
  /// parameter shrinks below this fraction of its length when the model was built. 0 = off.
  double rulingGuardRatio = 0.35;
  /// Degeneracy guard (terms::StripWidthTerm, hard, "strip_width"): the area element
  /// |(b − a) × (a′ + b′)| at the guarded parameters, and each side's |(b − a) × a′| and
  /// |(b − a) × b′|, keep this fraction of their values when the model was built (no collapse
  /// across the rulings, no curve turning into its rulings, no cusp). 0 = off.
  double widthGuardRatio = 0.25;
  /// Degeneracy guards (hard, open curves): "curve_backtrack" (terms::PolygonBacktrackTerm: no two
  /// legs of a or b within one span's reach point more than 90° apart where they did not when the
  /// model was built) and "curve_leg_length" (no leg shrinks below legGuardRatio of its length then).
  bool backtrackGuard = true;
  double legGuardRatio = 0.25;
  /// With an approximation target the start is a rough placement (a PCA rectangle), not a design
  /// to keep: the width and leg guards are loosened to at most this ratio of the start. A cone's
  /// sector narrows its top edge to a fraction of the rectangle's (a scanned lampshade with slant
  /// 0.6–1.6: the default 0.25 held the fit at 0.2° warp). Over 60 random scanned cylinders and
  /// cones, 0.1 fitted all within 2.23σ; at 0.15 and 0.2 the guard held some fits far from their
  /// scans (coverage down to 14 %). The price: on a doubly curved region a strip narrows until the
  /// guard holds it and then loses developability (the kitten's flank: warp 1° after 60 iterations).
  double approximationGuardRatio = 0.1;
  /// Whoever builds the model gives up here (a job's time limit, a session's budget): checked
  /// while the pattern is analyzed; once passed, the constructor throws engine::DeadlineExceeded.
  /// Solves have their own (engine::SolverOptions::deadline). Default: never.
  engine::Deadline deadline;
};

/// Sampled geometry for drawing and export (in the design's coordinates).
struct StripGeometry {
  io::QuadMesh surface;               ///< (uSamples)×(vSamples) grid of points s(u,v)
  Eigen::MatrixX3d curveA, curveB;    ///< polylines of a and b at the u samples
  Eigen::MatrixX3d rulingStart, rulingEnd;  ///< one row per ruling: a(u), b(u)
  Eigen::MatrixX3d normals;           ///< unit surface normal per ruling
};

/// The developable strip of Tang et al. 2016 §2 / Mundilova ch. 5: a ruled B-spline surface
/// s(u,v) = (1−v)a(u) + v b(u) made developable by guided projection.
///
/// Setup/solve split: the constructor validates the design, builds variables and terms and
/// analyzes the topology once; solve() runs iterations; handle targets and weights can change
/// between solves without a new analysis.
///
/// Variables (normalized coordinates): block "curve a" and "curve b" (3 per control point),
/// block "normals" (3 per evaluation parameter, or 3 per normal-spline control point).
/// Terms: "developability" (hard), "unit_normal_hard" (hard), "unit_normal" (soft),
/// "fairness" (soft, decaying), "handle" (soft, weight per handle); with an approximation target
/// "approximation_point" (eq. 9), "approximation_tangency" (eq. 10) and
/// "approximation_tangent_plane" (eq. 11), all soft, sharing closest points renewed per iteration.
class StripModel {
 public:
  /// @throws std::invalid_argument with a message naming the offending part ("b.knots: …",
  ///         "fixed[2].index: …") for designs that cannot be solved.
  explicit StripModel(StripDesign design, StripOptions options = {});

  /// The checks the constructor makes, without building anything; fills defaults (the normal
  /// spline's control-point count). Messages start with the path inside the model: "b.knots: …".
  /// @throws std::invalid_argument
  static void validateDesign(StripDesign& design);

  /// Runs guided projection from the current state.
  engine::SolveSummary solve(const engine::SolverOptions& options);

  /// The current design with control points moved (design coordinates).
  StripDesign design() const;
  const StripOptions& options() const { return options_; }

  /// The reference points the strip approximates, if any (design coordinates).
  const std::optional<ApproximationTarget>& approximation() const { return design_.approximation; }

  /// Moves handle `i` to a new target (design coordinates); no re-analysis.
  void setHandleTarget(int i, const Eigen::Vector3d& position);
  /// Re-initializes the normals from the current curves (e.g. after a large edit).
  void resetNormals();

  /// [ruling_length_min_ratio] the narrowest ruling at the evaluation parameters over its length
  /// when the model was built (1 when nothing is guarded).
  double rulingLengthMinRatio() const;
  /// [strip_width_min_ratio] the smallest area element over its value when the model was built.
  double stripWidthMinRatio() const;
  /// Sets the weight of handle `i` (0 releases it without rebuilding the model).
  void setHandleWeight(int i, double weight);
  /// Quality over `rulings` rulings equally spaced in u.
  metrics::StripQuality quality(int rulings = 1000) const;
  /// Sampled surface, curves and rulings.
  StripGeometry geometry(int uSamples = 64, int vSamples = 2, int rulings = 32) const;

  /// Evaluation parameters of the developability rows (3m−2 per span; 6m−3 for NURBS).
  const std::vector<double>& evaluationParameters() const { return params_; }
  engine::Problem& problem() { return problem_; }
  const engine::Problem& problem() const { return problem_; }
  engine::GuidedProjectionSolver& solver() { return *solver_; }
  int numUnknowns() const { return problem_.layout().numFree(); }

 private:
  void buildProblem();
  void initializeNormals();
  /// Control points of curve c from x, design coordinates (n×3).
  Eigen::MatrixXd controlPoints(Curve c) const;
  int pointOffset(const ControlPointRef& p) const;

  StripDesign design_;   ///< curves kept for knots/weights/degree; points live in x
  StripOptions options_;
  engine::Normalization normalization_;
  engine::Problem problem_;
  std::unique_ptr<engine::GuidedProjectionSolver> solver_;
  std::vector<double> params_;
  spline::EvaluationMatrix normalEvaluation_;  ///< normal spline at params_ (spline normals)
  /// a, a′, b, b′ at params_ as linear functions of the control points in x.
  std::array<terms::LinearPoints, 4> curveRows_;
  int blockA_ = -1, blockB_ = -1, blockNormals_ = -1;
  std::vector<int> handleTerms_;
  int rulingTerm_ = -1;
  std::vector<int> widthTerms_;  ///< "strip_width": (b − a) against a′ + b′, a′, b′
};

}  // namespace devsurf::models::strip
