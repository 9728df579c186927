#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Deadline.h"
#include "devsurf/models/conical_strip/ArcLengthCurve.h"
#include "devsurf/models/conical_strip/ConicalPatch.h"
#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::models::conical_strip {

/// The criterion of Step 4 (and the reported quality measures), Chu et al. §5.1.
enum class Objective {
  NormalVariation,  ///< eq. 6–7: Σ 1 − n_k · n_{k+1} over the rulings between patches
  BendingEnergy,    ///< eq. 8–9: Σ A_{k+1} sin²θ_k / L_k² (K = 1)
};
const char* objectiveName(Objective objective);  ///< "normal_variation" / "bending_energy"

/// Everything that defines a conical strip (Chu, Wang, Tsai 2008): two boundary curves and the
/// parameters of the greedy algorithm. Lengths (h3, h4, deviations) are in the curves' units.
struct ConicalStripDesign {
  spline::BSplineCurve p;  ///< boundary P: clamped 3D B-spline (any degree, NURBS allowed)
  spline::BSplineCurve q;  ///< boundary Q, traversed in the same direction as P
  int np = 55;             ///< samples on P at equal arc length, ends included (≥ 2)
  int nq = 65;             ///< samples on Q (≥ 2)
  double h3 = 4.0;         ///< triangular patches: new ruling length |apex − new sample| ≤ h3
  double h4 = 4.0;         ///< quadrilateral patches: the plane/curve crossing (Step 3) within h4
                           ///< of the next sample and of the sample it replaces (searched up to h4
                           ///< beyond the next sample), and the scaled end corner within h4 of it
  double ra = 1.2;         ///< quadrilateral patches: max length ratio of the two boundaries (≥ 1)
  Objective objective = Objective::NormalVariation;
  bool g1 = true;          ///< degree elevation to cubic and G1 adjustment (§4)

  /// A polyline (rows are points, ≥ 2) as a degree-1 B-spline with chord-length knots.
  /// @throws std::invalid_argument if there are fewer than 2 rows, not 3 columns, or repeated points.
  static spline::BSplineCurve polyline(const Eigen::MatrixX3d& points);
};

/// Numerical settings; the defaults are what the tests and the benchmark use.
struct ConicalStripOptions {
  int arcLengthIntervalsPerSpan = 16;  ///< arc-length table resolution (5-point Gauss per interval)
  int intersectionScanSteps = 24;      ///< sign-change scan per plane/curve intersection (Step 3)
  int outlineSamples = 24;             ///< rulings per patch for the development and deviation
  /// G1 adjustment (§4.2): the free tangent lengths w1, w2 are the projections of the elevated
  /// cubic's inner control legs onto the G1 tangents, clamped to [min, max] × the chord length.
  double tangentLengthMin = 0.05;
  double tangentLengthMax = 0.6;
  /// Step 4 guard, not in the paper. A candidate *folds back* when its tangent plane at its start
  /// ruling turns by more than this (radians) against the previous patch's end, and *traps* the
  /// strip when, after it, a side that is not finished can only advance by a triangle that folds
  /// back against it. Step 4 passes over candidates that do either while another (of any type)
  /// does neither, keeping its order: quadrilaterals, triangles within h3, any triangle; then over
  /// those that fold back. Without it, a fan of triangles on one apex (no normal jump, so the
  /// criterion prefers it) runs on until the other side's next triangle turns by 180°.
  /// Default: a right angle; π or more switches the guard off (Step 4 as published, but for the
  /// forced step, which is ours either way: it takes the shortest new ruling). Must be positive.
  double foldBackAngle = 1.5707963267948966;
  /// Whoever runs solve() gives up here (a job's time limit, a session's budget): checked in every
  /// greedy step and in the loops over samples and patches; once passed, solve() throws
  /// engine::DeadlineExceeded and the model stays unsolved. Default: never.
  engine::Deadline deadline;
};

/// Counts and timings of one run (no timing is asserted anywhere; the bench reports them).
struct ConicalStripSummary {
  std::string termination;       ///< "completed" (the greedy loop reached p_m q_n)
  int patches = 0;
  int triangular = 0;            ///< n3
  int quadrilateral = 0;         ///< n4
  /// Steps that took a triangle beyond h3 (the shortest new ruling): no candidate passed its
  /// test (Step 3), or the fold-back guard passed over those that did.
  int forcedTriangles = 0;
  /// Steps whose patch turns the strip by more than a right angle against the previous one (with
  /// the guard on: every candidate did).
  int foldBacksTaken = 0;
  int quadCandidatesTested = 0;  ///< quadrilateral candidates that passed Step 2's side test
  int quadCandidatesFeasible = 0;
  /// Why tested quadrilateral candidates failed Step 3: no plane/curve crossing between the
  /// current corner and the sample after next; crossing farther than h4 from the sample; boundary
  /// length ratio outside [1/ra, ra]; scaled end corner farther than h4 from the curve.
  int quadRejectedNoCrossing = 0, quadRejectedDistance = 0, quadRejectedRatio = 0,
      quadRejectedCorner = 0;
  double timeMs = 0.0;           ///< total
  double greedyMs = 0.0;         ///< sampling + Steps 2–5
  double g1Ms = 0.0;             ///< degree elevation and G1 adjustment
  double metricsMs = 0.0;        ///< metrics and development
};

/// The papers' quality measures of a strip (patches in order along the strip).
struct ConicalStripMetrics {
  double normalVariation = 0.0;  ///< eq. 7 (0 for a G1 strip)
  double bendingEnergy = 0.0;    ///< eq. 9, K = 1 (0 for a G1 strip)
  int n3 = 0;                    ///< triangular patches
  int n4 = 0;                    ///< quadrilateral patches
  /// Largest distance from a point of a patch boundary (outlineSamples+1 per boundary, corners
  /// included) to its input curve.
  double deviationMax = 0.0;
  /// Largest distance of a patch corner from its input curve (nonzero only at the scaled end of
  /// quadrilateral patches, §3.2: "only three control points … can be freely specified").
  double cornerDeviationMax = 0.0;
  double projectionResidualMax = 0.0;   ///< max over patches of projectionResidual (eq. 3)
  double coplanarityResidualMax = 0.0;  ///< max over patches of coplanarityResidual (eq. 2)
  double normalJumpMaxRad = 0.0;        ///< largest angle between normals across a shared ruling
};

/// A patch's development: the boundaries' images at outlineSamples+1 rulings, in the plane of the
/// whole strip's development (patches unfolded one after the other across their shared rulings).
struct UnfoldedPatch {
  Eigen::MatrixX2d a;  ///< images of a(u_k), u_k = k/outlineSamples
  Eigen::MatrixX2d b;  ///< images of b(u_k)
};

struct ConicalStripResult {
  /// Step 1: the sample points (rows) and their curve parameters.
  Eigen::MatrixX3d samplesP, samplesQ;
  std::vector<double> paramsP, paramsQ;
  /// The corner the strip passes through for each sample: the sample itself, or (for the sample a
  /// quadrilateral patch replaced on its scaled side) the patch's end corner. A quadrilateral
  /// whose plane/curve crossing lies beyond the next sample (allowed within h4) skips the samples
  /// before the one it replaces: those are not corners (their rows keep the sample).
  Eigen::MatrixX3d cornersP, cornersQ;
  std::vector<bool> replacedP, replacedQ;
  std::vector<bool> skippedP, skippedQ;
  /// Quadratic patches of the greedy algorithm (§3.3), G0 across rulings.
  std::vector<ConicalPatch> greedyPatches;
  /// The final patches: cubic and G1 when design.g1, else the greedy patches.
  std::vector<ConicalPatch> patches;
  /// G1 tangent planes, one unit normal per ruling (patches.size()+1; empty when !design.g1):
  /// the plane along ruling k is spanned by the ruling and the average of the curves' tangents at
  /// its ends (§4.2); both patches at the ruling have it as tangent plane, so the strip is G1.
  /// Each patch's base boundary leaves a ruling along its curve's tangent projected into it.
  std::vector<Eigen::Vector3d> rulingPlaneNormals;
  std::vector<UnfoldedPatch> unfolded;  ///< development of `patches`
  ConicalStripMetrics metrics;          ///< of `patches`
  ConicalStripMetrics greedyMetrics;    ///< of `greedyPatches` (the paper's tables, G0)
};

/// The conical strip of Chu, Wang, Tsai 2008: a constructive, greedy chain of quadratic Bézier
/// patches in generalized conical form (eq. 3) interpolating two sampled space curves, optionally
/// degree-elevated to cubic and adjusted to G1 (§4). No optimization engine is involved.
///
/// Usage:
///   ConicalStripModel model(design);           // validates; throws naming the field
///   const ConicalStripSummary& s = model.solve();
///   const ConicalStripResult& r = model.result();
///
/// Conventions: patches run from the ruling p_1 q_1 to p_Np q_Nq; in each patch a is the P side
/// and b the Q side, u runs along the strip, the normal ((a′+b′)/2)×(b−a) is oriented the same
/// way in every patch.
class ConicalStripModel {
 public:
  /// @throws std::invalid_argument naming the field (`p`, `q`, `np`, `nq`, `h3`, `h4`, `ra`,
  ///         `options.…`) when the design or the options do not qualify.
  explicit ConicalStripModel(ConicalStripDesign design, ConicalStripOptions options = {});

  /// Runs the greedy algorithm (and the G1 adjustment), computes metrics and the development.
  /// Calling it again recomputes from scratch.
  /// @throws engine::DeadlineExceeded once options.deadline has passed (solved() is then false)
  const ConicalStripSummary& solve();

  bool solved() const { return solved_; }
  const ConicalStripDesign& design() const { return design_; }
  const ConicalStripOptions& options() const { return options_; }
  /// Replaces options.deadline (for the next solve()).
  void setDeadline(engine::Deadline deadline) { options_.deadline = std::move(deadline); }
  const ConicalStripSummary& summary() const { return summary_; }
  /// @throws std::logic_error before solve().
  const ConicalStripResult& result() const;

  const ArcLengthCurve& curveP() const { return curveP_; }
  const ArcLengthCurve& curveQ() const { return curveQ_; }

 private:
  ConicalStripDesign design_;
  ConicalStripOptions options_;
  ArcLengthCurve curveP_, curveQ_;
  ConicalStripSummary summary_;
  ConicalStripResult result_;
  bool solved_ = false;
};

/// The metrics of a chain of patches against the two input curves (used for both the greedy and
/// the final patches). `outlineSamples` boundary samples per patch for the deviation.
/// @throws engine::DeadlineExceeded once `deadline` has passed
ConicalStripMetrics measureStrip(const std::vector<ConicalPatch>& patches,
                                 const ArcLengthCurve& curveP, const ArcLengthCurve& curveQ,
                                 int outlineSamples, const engine::Deadline& deadline = {});

/// Unfolds a chain of patches into the plane: each patch sampled at outlineSamples+1 rulings and
/// unfolded triangle by triangle (edge lengths kept exactly), continuing across shared rulings.
/// @throws engine::DeadlineExceeded once `deadline` has passed
std::vector<UnfoldedPatch> unfoldStrip(const std::vector<ConicalPatch>& patches, int outlineSamples,
                                       const engine::Deadline& deadline = {});

}  // namespace devsurf::models::conical_strip
