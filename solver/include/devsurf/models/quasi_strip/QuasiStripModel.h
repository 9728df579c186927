#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Deadline.h"
#include "devsurf/engine/GuidedProjectionSolver.h"
#include "devsurf/engine/Problem.h"
#include "devsurf/models/quasi_strip/Lbfgs.h"
#include "devsurf/models/quasi_strip/Mapping.h"
#include "devsurf/models/quasi_strip/SurfaceConversion.h"
#include "devsurf/spline/Basis.h"
#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/terms/ExtendedCurve.h"

namespace devsurf::models::quasi_strip {

/// The B-spline mapping function of eq. 5.
struct MappingSpec {
  int degree = 2;         ///< d
  int coefficients = 50;  ///< n+1 control coefficients (clamped uniform knots on C1's parameter)
};

/// End-point fixing of §5.4: an extra term pulling the strip's end points on C2, C2(σ(t_begin))
/// and C2(σ(t_end)), to C2's own end points (weight 1000 in the paper's objective).
struct EndPointFixing {
  bool enabled = false;
  double weight = 1000.0;  ///< μ: adds μ·|C2(σ(t_e)) − C2(T_e)|² to eq. 9 (normalized coordinates)
};

/// Curve extension of §3.4. Lengths are fractions of the curve's parameter domain added before its
/// begin / after its end by continuing the end spans' polynomials.
struct CurveExtension {
  double c1Begin = 0.0, c1End = 0.0, c2Begin = 0.0, c2End = 0.0;
  /// After a solve, when σ leaves an end part of C2 uncovered (Case 1: σ(t_end) < T_end, or
  /// σ(t_begin) > T_begin), extend C1 at that end by 1.25× the missing length (estimated with σ′)
  /// and solve again, at most `maxRounds` times. A round is followed by another only if its result
  /// is the best so far (see QuasiStripModel::solve). Where σ runs past C2's end, C2's polynomial
  /// continuation is used as it is (the solver evaluates C2 beyond its domain anyway).
  bool automatic = true;
  int maxRounds = 2;
  double tolerance = 1e-3;  ///< uncovered parameter length (fraction of C2's domain) tolerated
  /// What the model may add to a curve at either end, beyond the extension given above: at most
  /// this fraction of the curve's parameter domain and of its arc length. It caps the automatic
  /// extension of C1, and solve() returns no state whose end rulings are further than this from
  /// C2's ends along C2 (σ running past C2's explicitly extended end, i.e. Case 2 of §3.4 by C2's
  /// polynomial continuation, or falling short of C2's ends by more than `tolerance` + this).
  /// So the strip's boundaries stay within maxLength × the curves' arc lengths of the input curves.
  double maxLength = 0.1;
};

/// Everything that defines a quasi-developable strip between two given curves (001_…).
///
/// Convention: rulings join C1(t) and C2(σ(t)); σ maps C1's parameter t to C2's parameter T
/// (the paper's §3: "ruling lines C1(t)C2(σ(t))"), and the samples t_i are taken on C1.
struct QuasiStripDesign {
  spline::BSplineCurve c1;  ///< clamped, non-rational, 3 columns, any degree/knots
  spline::BSplineCurve c2;  ///< as c1; its domain may differ from c1's
  MappingSpec mapping;
  int samples = 100;        ///< K rulings t_i equally spaced over C1's (extended) domain, ends included
  EndPointFixing endPoints;
  CurveExtension extension;
};

/// How σ is represented.
enum class MappingMethod {
  BSpline,   ///< eq. 5 (the paper's method)
  Discrete,  ///< §3.1: one parameter T_i = Σ_{j≤i} α_j² per sample, then the piecewise-linear σ
             ///< through (t_i, T_i) (the "discrete mapping method", Fig. 7 c/d)
};

/// Which optimizer minimizes eq. 9.
enum class Optimizer {
  GuidedProjection,  ///< our engine: regularized Gauss–Newton on the residual form of eq. 9
  Lbfgs,             ///< L-BFGS on the objective, as the paper does
};
const char* optimizerName(Optimizer optimizer);

/// Weights and switches; every field has a documented default.
struct QuasiStripOptions {
  double lambda1 = 100.0;  ///< λ1, weight of F_Dvlp (eq. 9) on input normalized to a unit box
  double lambda2 = 1.0;    ///< λ2, weight of F_Reg = Σ(|N_i|² − 1)²
  MappingMethod method = MappingMethod::BSpline;
  /// L-BFGS by default: on the twisted pair guided projection (Gauss–Newton, even with LM control
  /// of ε_reg) drives runs of ε_k towards 0 and stalls in a flat-σ local minimum (8° left) where
  /// L-BFGS reaches 1e-4°; on the exact case guided projection is ~20× faster (bench/quasi_strip.cpp).
  Optimizer optimizer = Optimizer::Lbfgs;
  /// Guided projection: iterations, ε_reg (Tikhonov weight of the step), tolerances.
  int maxIterations = 200;
  double regularization = 1e-4;
  double normalRegularizationScale = 1.0;  ///< multiplier of ε_reg² for the normals
  double residualTolerance = 1e-24;        ///< stop when λ1F_Dvlp + λ2F_Reg (+ end points) is below
  double relativeChangeTolerance = 1e-12;  ///< stop when the objective changes less (relatively)
  LbfgsOptions lbfgs;                      ///< when optimizer = Lbfgs
  /// L-BFGS also stops (termination "warp_tolerance") once the largest warp angle over the sample
  /// rulings is at or below this, checked every 10 iterations; 0 = off (run to the tolerances
  /// above). The objective keeps falling geometrically long after the strip is visibly
  /// developable: on the twisted pair of bench/quasi_strip.cpp 0.05° takes ~150 iterations, 1e-4°
  /// needs the full 3000.
  double warpToleranceDeg = 0.05;
  /// L-BFGS also stops (termination "warp_stalled") when that largest sample warp has not fallen
  /// below (1 − warpStallDecrease) × its smallest value of warpStallIterations iterations before;
  /// x is then the iterate where it was smallest. The objective creeps on long after the worst
  /// ruling stopped improving (hull preset: 0.84° from iteration 50 on, at the first ruling, which
  /// σ(t_begin) = T_begin keeps); 0 iterations = off.
  int warpStallIterations = 200;
  double warpStallDecrease = 0.01;
  /// After L-BFGS: at most this many guided-projection steps (Gauss–Newton with the LM control
  /// above), which converge quadratically from where L-BFGS stopped; 0 = none.
  int polishIterations = 10;
  /// When the first round has no acceptable result (see solve()), solve() tries once more with
  /// end-point fixing (§5.4, weight endPoints.weight) and the design's extension before it falls
  /// back to the initial mapping.
  bool fixEndPointsRetry = true;
  double timeBudgetMs = 0.0;               ///< per solve round (0 = none)
  int denseRulings = 1000;                 ///< rulings of the *_dense warp metrics (Fig. 7 f)
  /// Whoever builds and solves the model gives up here (a job's time limit, a session's budget):
  /// checked while the model is built, between optimizer iterations and rounds, and in the loops
  /// over the samples and dense rulings; once passed, the constructor or solve() throws
  /// engine::DeadlineExceeded (the model is then not to be used). Unlike timeBudgetMs, which ends
  /// a round normally. Default: never.
  engine::Deadline deadline;
};

/// One iteration as the summary records it (iteration 0 = initial state).
struct QuasiStripIteration {
  int iteration = 0;
  double objective = 0.0;     ///< λ1 F_Dvlp + λ2 F_Reg (+ end-point term)
  double stepNorm = 0.0;      ///< guided projection: ‖δ‖; L-BFGS: 0
  double gradientNorm = 0.0;  ///< L-BFGS: ‖∇f‖∞; guided projection: 0
  double elapsedMs = 0.0;     ///< since the start of this round
  int round = 0;              ///< extension round
};

/// Name of QuasiStripSummary::termination when solve() returns the initial mapping.
inline constexpr const char* kIdentityFallback = "identity_fallback";

/// What solve() did.
struct QuasiStripSummary {
  Optimizer optimizer = Optimizer::GuidedProjection;
  /// Why the optimizer stopped in the returned state's round (engine::terminationReasonName or
  /// lbfgsTerminationName; "A, then guided projection: B" with the polish), or kIdentityFallback
  /// when no optimized state beat the initial mapping (see QuasiStripModel::solve).
  std::string termination;
  bool converged = false;     ///< the returned state's optimizer stopped on a tolerance (false for the fallback)
  std::vector<QuasiStripIteration> iterations;
  int rounds = 1;             ///< solve rounds (> 1 when automatic extension re-solved)
  /// Which state solve() returned: 0 = the initial mapping (σ(t) = t on the design's curves, with
  /// the design's explicit extension), k ≥ 1 = the result of round k.
  int selectedRound = 0;
  /// Why that state: "last round" when it is the last round's result; otherwise the comparison
  /// that decided (largest warp over the dense rulings, reach past C2's end), in words.
  std::string selection;
  double totalMs = 0.0;       ///< the whole solve() including extension rounds and results
};

/// Results (design coordinates and parameters).
struct QuasiStripResults {
  /// Warp angles (§5, metrics::warpAngleDeg) over the K sample rulings (report warp_angle_max_deg,
  /// warp_angle_mean_deg) and over `denseRulings` rulings equally spaced in t over the same range
  /// (warp_angle_max_deg_dense, warp_angle_mean_deg_dense).
  double warpAngleMaxDeg = 0.0, warpAngleMeanDeg = 0.0;
  double warpAngleMaxDegDense = 0.0, warpAngleMeanDegDense = 0.0;
  double objective = 0.0;  ///< eq. 9 at the result (normalized coordinates)
  /// σ in the input curves' parameters: σ(t) = Σ coefficients_i B_i(t) maps C1's t to C2's T.
  /// With C1 extended its domain reaches beyond C1's.
  Mapping mapping;
  std::vector<double> sampleParameters;  ///< t_i on C1
  std::vector<double> sampleWarpDeg;     ///< warp angle per sample ruling
  Eigen::MatrixX3d normals;              ///< N_i normalized, one row per sample
  /// Extension actually used (fractions of each domain), after automatic rounds.
  CurveExtension extension;
  /// Trimmed strip: t ∈ [trimBegin, trimEnd] on C1, the smallest range whose end rulings reach
  /// both input curves' end points (it contains all of C1 and of C2 that σ covers).
  double trimBegin = 0.0, trimEnd = 1.0;
  /// Algorithm 1 over [trimBegin, trimEnd]: degree 1 × p·d, bounded by C1 (side 0) and C2∘σ (side 1).
  RuledBSplineSurface surface;
};

/// Quasi-developable ruled strip between two given curves (Bo, Zheng, Zhang §3–4):
/// find a monotone mapping σ (eq. 5) minimizing λ1 F_Dvlp + λ2 F_Reg (eq. 9) over K sample rulings
/// C1(t_i)–C2(σ(t_i)) with one free normal N_i each, starting from T = t; then write the strip
/// S(s,t) = (1−s) C1(t) + s C2(σ(t)) as a B-spline surface (Algorithm 1).
///
/// Solving happens on working copies: both curves normalized to a unit box (centre of the
/// bounding box of all control points, scaled by its largest side), brought to a common degree
/// and knot vector (§4, when their domains agree), extended (§3.4) and reparametrized to [0, 1],
/// where T = t is the initialization. Results are reported in the design's coordinates and
/// parameters.
///
/// Variables: block "mapping shape" (ε_0..ε_n, or α_0..α_{K−1} for the discrete method) and
/// "normals" (3 per sample, eliminated per sample by the engine). Terms: "developability"
/// (MappingDevelopabilityTerm, weight √λ1), "unit_normal" (UnitNormalTerm, √λ2), "end_point"
/// (MappingEndPointTerm, √μ, two of them when end-point fixing is on). All are soft: eq. 9 is an
/// energy, minimized by either optimizer.
/// \note With T = t, ε_0 = 0 and its derivative 2ε_0(…) vanishes: σ(t_begin) stays at C2's begin
///       (the first ruling joins the curves' start points); move it with c2Begin extension.
class QuasiStripModel {
 public:
  /// Validates the design and builds the working curves and the problem.
  /// @throws std::invalid_argument naming the field ("c1.weights: …", "mapping.degree: …",
  ///         "samples: …", "extension.c1End: …", "endPoints.weight: …"); engine::DeadlineExceeded
  ///         once options.deadline has passed.
  explicit QuasiStripModel(QuasiStripDesign design, QuasiStripOptions options = {});
  ~QuasiStripModel();
  QuasiStripModel(const QuasiStripModel&) = delete;
  QuasiStripModel& operator=(const QuasiStripModel&) = delete;

  /// Minimizes eq. 9 from T = t (and re-solves after automatic extension), then fills results().
  ///
  /// solve() never returns a strip worse than the one it starts from. A state is acceptable if its
  /// largest warp over the `options.denseRulings` rulings (warpAngleMaxDegDense) is at most the
  /// initial mapping's and its end rulings are within `extension.maxLength` of C2's ends. A round's
  /// result is its final state if acceptable, else its L-BFGS state before the guided-projection
  /// polish, else its L-BFGS iterate with the smallest largest sample warp (not converged).
  /// Automatic extension continues only from an acceptable round, and an extension round whose
  /// result is worse than the round before (or not acceptable) is dropped and ends the extension.
  /// When the first round has no acceptable result, one more round runs with end-point fixing
  /// (§5.4, if `options.fixEndPointsRetry`) and the design's extension. When nothing is
  /// acceptable, the initial mapping is returned: termination kIdentityFallback, converged false.
  /// summary.selectedRound and summary.selection say which state was returned and why.
  /// Every call starts again from T = t.
  /// @throws engine::DeadlineExceeded once options.deadline has passed
  QuasiStripSummary solve();

  /// Results at the current state (before solve(): the initial mapping T = t).
  const QuasiStripResults& results() const { return results_; }
  const QuasiStripDesign& design() const { return design_; }
  const QuasiStripOptions& options() const { return options_; }
  /// Replaces options.deadline (for the next solve()).
  void setDeadline(engine::Deadline deadline) { options_.deadline = std::move(deadline); }

  /// The ruled surface (1−s) C1(t) + s C2(σ(t)) in design coordinates, t on C1 (extended where
  /// C1 is extended).
  Eigen::Vector3d ruledSurfacePoint(double s, double t) const;
  /// Unknowns of the current problem.
  int numUnknowns() const;

 private:
  struct Working;
  struct Candidate;
  void build();
  void computeResults();
  /// The current state as a candidate result of `round` (0 = the initial mapping).
  Candidate capture(int round, std::string termination, bool converged) const;
  /// Makes `c` the current state (rebuilding the working curves if its extension differs).
  void restore(const Candidate& c);
  /// Automatic extension of C1 after a round (Case 1 of §3.4), capped by extension.maxLength;
  /// false when nothing (more) may be extended.
  bool extendForNextRound();
  /// One optimizer run from the current state; appends its result (and, with the polish, the
  /// L-BFGS state before it) to `candidates`.
  void solveRound(int round, QuasiStripSummary& summary, std::vector<Candidate>& candidates);
  /// Guided projection with Levenberg–Marquardt control of ε_reg, at most maxIterations accepted
  /// or rejected steps; the main optimizer, or the polish after L-BFGS.
  double guidedProjectionSteps(int round, QuasiStripSummary& summary, int maxIterations, bool recordStart,
                               std::chrono::steady_clock::time_point start);

  QuasiStripDesign design_;
  QuasiStripOptions options_;
  CurveExtension extension_;  ///< the extension in use
  std::unique_ptr<Working> working_;
  bool pristine_ = true;      ///< the state is the initial one (nothing solved since build)
  bool fixEndPoints_ = false; ///< end-point fixing for the retry of solve() (weight endPoints.weight)
  QuasiStripResults results_;
};

}  // namespace devsurf::models::quasi_strip
