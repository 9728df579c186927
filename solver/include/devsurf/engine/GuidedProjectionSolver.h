#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Deadline.h"
#include "devsurf/engine/LinearSolver.h"
#include "devsurf/engine/NormalEquations.h"
#include "devsurf/engine/Problem.h"

namespace devsurf::engine {

/// Why a solve stopped.
enum class TerminationReason {
  MaxIterations,      ///< ran the requested number of iterations
  ResidualTolerance,  ///< objective (unscheduled terms) below residualTolerance
  RelativeChange,     ///< relative change of the objective below the tolerance
  HardTolerance,      ///< every hard row within SolverOptions::hardTolerance, no longer improving
  TimeBudget,         ///< the time budget ran out
  Aborted,            ///< the iteration callback asked to stop
  Diverged,           ///< a step produced non-finite values or a singular system; x was restored
  Stalled,            ///< step control rejected kStallRejections steps in a row (x is the last good
                      ///< iterate: the hard rows cannot be kept while moving toward the targets)
  HardPlateau,        ///< projection steps near SolverOptions::hardTolerance no longer lower the
                      ///< largest hard row (see SolverOptions::hardPlateau)
};
const char* terminationReasonName(TerminationReason reason);

/// One guided-projection iteration as the summary records it.
struct IterationRecord {
  int iteration = 0;                   ///< 0 = the initial state, k = after k steps
  std::vector<double> termResiduals;   ///< per term id: Σ (w r)², weights of this iteration
  double hardResidual = 0.0;           ///< Σ over hard terms
  double hardResidualMax = 0.0;        ///< largest |w r| of a single hard row
  double objective = 0.0;              ///< Σ over terms whose weight is not scheduled (hard and
                                       ///< soft targets such as handles): what termination watches
  double totalResidual = 0.0;          ///< Σ over all terms
  double stepNorm = 0.0;               ///< ‖δ‖ (0 for iteration 0)
  double fairnessWeight = 0.0;         ///< ε_fair · decay^k used for this step
  double stepScale = 1.0;              ///< α of the accepted step x + αδ (0: rejected, x unchanged by
                                       ///< it; with alternation the alternating step may still move)
  /// α of the step of the alternating blocks (VariableLayout::setAlternating), taken after the
  /// step of the others with them held; 0: rejected (or no block alternates).
  double alternatingStepScale = 0.0;
  /// The alternating blocks' system was factorized in this iteration (false: CG with its earlier
  /// factorization, SolverOptions::alternatingReuse, or no alternation).
  bool alternatingFactorized = false;
  bool projected = false;              ///< step control replaced a rejected step by a projection
                                       ///< step (hard rows only)
  double pullLimit = 0.0;              ///< step control: the largest residual norm of a relaxable term
                                       ///< (a handle's distance to its target) this step aimed to
                                       ///< remove (0: no relaxable terms)
  double assemblyMs = 0.0;             ///< linearize, evaluate, fill H and g
  double factorizationMs = 0.0;        ///< numeric factorization (incl. the block elimination
                                       ///< of elimination groups, see NormalEquations)
  double solveMs = 0.0;                ///< triangular solves and the update of x (with
                                       ///< factorization reuse: the whole PCG solve)
  double evaluationMs = 0.0;           ///< residual evaluations that judge the step (step control,
                                       ///< corrections; NormalEquations::residuals)
  /// Triangular-solve pairs spent on conjugate gradients preconditioned with an earlier
  /// factorization (FactorizationReuseOptions; also when CG gave up and the matrix was then
  /// factorized); 0: none.
  int pcgIterations = 0;
  bool factorized = false;             ///< the step's matrix was factorized in this iteration
  int corrections = 0;                 ///< correction steps kept (SolverOptions::correctionSteps)
  double totalMs = 0.0;                ///< whole iteration including residual evaluation
};

/// Step control on the hard rows (ARCHITECTURE §8 "a drag cannot tear"): a step is accepted when
/// it leaves every hard row within the band or, from a state already outside it, raises neither
/// the largest row nor the hard residual Σ(w r)²; otherwise it is shortened (x + αδ, α = 1, ½, ¼ …) and, if no α is accepted, rejected:
/// x stays the last good iterate, and the iteration takes a projection step instead: the same
/// system without the targets (handles), accepted if it lowers the hard residual.
///
/// The relaxable terms (handles, TermSlot::relaxable) are approached gradually: in the linear
/// system a relaxable term's residual vector is shortened to at most the pull limit — for a handle,
/// its target is moved to at most that distance from the point — so a step aims at a reachable
/// intermediate target and corrects the hard rows fully. The limit is a trust region: halved by a
/// shortened step, quartered by a rejected one, doubled by a full one (within [min, max]). A handle
/// that asks for the impossible thus lags behind its target instead of tearing the shape. Reports
/// and termination always use the true residuals. Without relaxable terms a rejection raises the
/// damping (ε_reg ×2 per rejection) instead. Limit and damping persist across solve() calls of one
/// solver (a drag is many short solves); resetStepControl() starts afresh.
struct StepControlOptions {
  bool enabled = true;      ///< off: every step is taken whole (the plain method of 000_… eq. 6)
  /// Largest weighted residual |w r| of one hard row (normalized coordinates, rows scaled as the
  /// terms scale them) a step may leave behind. The default 0.1 is a safety net for batch solves,
  /// which only need their last iterate to be good: it stops wild steps and lets handles move
  /// fast. Interactive sessions, which stream every iterate, hold 1e-3 (SessionSettings).
  double hardBand = 0.1;
  int maxHalvings = 5;      ///< α down to 2^−maxHalvings before the step is rejected
  double initialPullLimit = 0.05;  ///< pull limit of a fresh solver (normalized units: the model is ~1)
  double minPullLimit = 1e-4;      ///< the limit never falls below this
  double maxPullLimit = 1.0;       ///< nor rises above this
};

/// Reuse of a factorization across the iterations of one solve() (off by default): H changes
/// little from one step to the next, so instead of factorizing H_k the step solves H_k δ = −g_k
/// by conjugate gradients preconditioned with the factorization of an earlier H_j of the same
/// solve() — each CG iteration costs a pair of triangular solves and a product with H_k, far less
/// than a factorization of a large 2D-like system (quad meshes of 10⁵ unknowns: bench/
/// quad_mesh_iteration). The step is H_k's own up to `tolerance` (relative residual), not a
/// different method. If CG has not converged after `maxIterations` (or meets a direction of
/// non-positive curvature), H_k is factorized and solved directly, and that factorization is
/// reused from then on. The first iteration of every solve() factorizes, so a solve does not
/// depend on what the solver did before.
struct FactorizationReuseOptions {
  int maxAge = 0;           ///< reuse a factorization for at most this many later iterations (0: off)
  int maxIterations = 10;   ///< CG iterations before giving up and factorizing
  double tolerance = 1e-8;  ///< ‖H δ + g‖ ≤ tolerance · ‖g‖ (reduced system)
};

/// What SolverOptions::timeBudgetMs measures.
enum class BudgetClock {
  Wall,       ///< elapsed wall time: a limit someone waits for (a batch job, a command-line run)
  ThreadCpu,  ///< CPU time of the solving thread (ThreadCpuClock) and the time it waited for a
              ///< second assembly thread: a busy machine gets the same result later instead of a
              ///< worse one on time (a session's interactive budgets); see budgetWallCapMs
};

/// Options of a guided-projection solve; every field has a documented default
/// (000_… §3.2 eq. 6 and §7; 003_… §4.1, §5.6).
struct SolverOptions {
  int maxIterations = 20;                ///< iterations to run at most
  double fairness = 0.01;                ///< ε_fair: weight of Fairness-scheduled terms at k = 0
  double fairnessDecay = 0.8;            ///< ε_fair is multiplied by this every iteration
  double regularization = 1e-2;          ///< ε_reg: Tikhonov weight of ‖x − x_k‖² (Tang Fig. 17)
  double timeBudgetMs = 0.0;             ///< stop after this much time (0 = no budget) …
  BudgetClock budgetClock = BudgetClock::Wall;  ///< … measured by this clock (default: wall time)
  /// With BudgetClock::ThreadCpu and a time budget: the solve also ends (TimeBudget) once this
  /// much wall time has passed, so a starved thread does not hold its caller indefinitely
  /// (0 = no cap; default 0).
  double budgetWallCapMs = 0.0;
  /// A hard limit of whoever runs the solve (a job's time limit): checked before every iteration;
  /// once passed, solve() throws DeadlineExceeded with x at the last iterate. Unlike
  /// timeBudgetMs, which ends a solve normally (TimeBudget). Default: never.
  Deadline deadline;
  double residualTolerance = 1e-14;      ///< stop when the objective Σ(w r)² falls below
  double relativeChangeTolerance = 1e-9; ///< stop when |E_k − E_{k−1}| ≤ tol · E_{k−1}
                                         ///< (E = objective; checked from the second step on,
                                         ///< after accepted full steps only)
  /// Stop when every hard row is within this (largest weighted |w r| after a step; 0 = not used):
  /// "release runs to quality" — the constraints are met, what is left is the slow approach of
  /// the soft targets.
  double hardTolerance = 0.0;
  /// A projection-only solve with a hardTolerance stops (HardPlateau) once the largest hard row,
  /// already within `range` × hardTolerance, fell by less than `decrease` over the last `steps`
  /// steps. Fairness stays in projection steps and holds the rows at an equilibrium just above a
  /// tolerance it may never let them reach: the folded annulus's polish crept from 1.9e-7 to
  /// 1.3e-7 (0.3 % a step) for 1.5 s of a release's 2 s budget. steps = 0: off.
  struct HardPlateau {
    int steps = 10;
    double decrease = 0.05;
    double range = 10.0;
    /// `range` of a solve that alternates (VariableLayout::setAlternating). Block Gauss–Seidel
    /// creeps where the two sides are stiffly coupled: a folded annulus's release with its
    /// development apart held the development's isometry rows at 5e-6 to 8e-6 — fifty times the
    /// session's tolerance — falling 0.5 % in twenty steps, and ran its whole 2 s budget on every
    /// drag. Coupled steps would close that gap; alternating ones do not in any time a user waits.
    /// Not wider: at 1e3 (stop 46) a release of the same annulus stopped on a ten-step stall at
    /// 2.6e-5 with its development's lengths 0.57 % off; it runs on from there and converges
    /// (lengths 0.035 %, 1.4 s; stop 47, once the factorization got faster).
    double alternatingRange = 1e2;
  } hardPlateau;
  /// Correction steps after each Gauss–Newton step (0 = none): the hard rows are evaluated again at
  /// the new iterate and the step's own system is solved once more with their residuals alone,
  /// its Jacobian and factorization held (the second-order correction of SQP methods: back onto
  /// the hard rows along the step's linearization, soft rows resisting but not pulling). A linear
  /// step leaves a second-order error on every quadratic hard row (|δ|² × curvature); the
  /// correction removes most of it. A correction is kept only if it lowers the hard residual
  /// Σ(w r)². Each costs a residual evaluation, a right-hand side and a pair of triangular solves:
  /// no assembly, no factorization. Steps solved with an earlier factorization
  /// (factorizationReuse) take none.
  int correctionSteps = 0;
  /// Threads that accumulate the normal equations' products (NormalEquations::setAssemblyThreads:
  /// a second one only for large systems). 0 = the cores this process may run on (its CPU
  /// affinity; `taskset -c 0` makes it one), at most 2; 1 = one thread.
  int assemblyThreads = 0;
  StepControlOptions stepControl;        ///< see StepControlOptions
  FactorizationReuseOptions factorizationReuse;  ///< off by default; see there
  /// Factorization reuse of the alternating blocks' system (VariableLayout::setAlternating), on by
  /// default and, unlike factorizationReuse, across solves: a composite's development system
  /// depends on the 2D vertices alone (the rows' Jacobian is 2(v̄_j − v̄_i)), which a step moves
  /// little, so CG preconditioned with an earlier factorization reaches 1e-10 in a few triangular
  /// solves. The matrix is factorized again when CG does not converge, or once maxAge iterations
  /// old. The step equals the factorized one up to the tolerance.
  FactorizationReuseOptions alternatingReuse{50, 10, 1e-10};
  /// The evaluation that judges a step also serves the next iteration's assembly for the terms
  /// that evaluate from x alone (Term::evaluatesFromXAlone; NormalEquations::residuals): the same
  /// iterates bit for bit, one evaluation of those terms per iteration instead of two. Off only to
  /// compare.
  bool keepEvaluations = true;
  /// The schedule's iteration of the first step: the fairness weight of step k is
  /// ε_fair·decay^(firstIteration + k), so a session's many short solves of one drag continue one
  /// schedule instead of restarting it.
  int firstIteration = 0;
  /// Every step a projection step: without the handles (relaxable terms) — restores feasibility
  /// without pulling anything (a session's polish after a drag).
  bool projectionOnly = false;
  /// With projectionOnly: keep the relaxable terms marked TermSlot::heldInProjection (the fold
  /// slider's targets at the release of a fold gesture; a drag's release lets them go like
  /// handles, so a dragged corner stays where it was put).
  bool holdTargetsInProjection = false;
  /// Called after every iteration (and for iteration 0); return false to abort the solve.
  std::function<bool(const IterationRecord&)> callback;
};

/// What a solve did (Ceres `Summary`): per-iteration records and the reason it stopped.
struct SolveSummary {
  std::vector<std::string> termNames;       ///< per term id
  std::vector<IterationRecord> iterations;  ///< [0] is the initial state
  TerminationReason reason = TerminationReason::MaxIterations;
  bool converged = false;                   ///< reason is a tolerance (not max iterations/abort)
  bool alternating = false;                 ///< the solver alternated (VariableLayout::setAlternating)
  /// Terms the assemblies took from the evaluation that judged the step before, summed over the
  /// iterations (SolverOptions::keepEvaluations).
  long keptEvaluations = 0;
  double totalMs = 0.0;
  int stepsTaken() const { return iterations.empty() ? 0 : static_cast<int>(iterations.size()) - 1; }
  /// Per-term residuals of the last iterate summed by term name.
  std::vector<std::pair<std::string, double>> finalResidualsByName() const;
};

/// Guided projection (Tang et al. 2014/2016, eq. 6): regularized Gauss–Newton on hard
/// constraints guided by decaying soft energies. Each step minimizes
/// ‖W(J δ + r)‖² + ε_reg² ‖δ‖² over the free variables, i.e. solves
/// (JᵀW²J + ε_reg² I) δ = −JᵀW²r, where fairness terms' weights are ε_fair·decay^k.
///
/// Setup/solve split: the constructor analyzes the topology (pattern, ordering, scatter map,
/// symbolic factorization); solve() runs iterations that only fill numbers and factorize.
///
/// Alternation (VariableLayout::setAlternating): when some free block alternates, the solver
/// analyzes two systems, one over the other blocks (the alternating ones held) and one over the
/// alternating blocks (the others held). Each iteration takes the step described above on the
/// first — with its step control — and then one on the second at the new iterate, with the same
/// weights, shortened (½, ¼ …) until it raises neither the largest hard row beyond the band nor
/// the hard residual, else not taken; that system has its own damping (ε_reg × 2 per shortened,
/// × 4 per rejected step, eased after a full one; ×100 retries when it is not positive definite).
/// Terms that touch only one side are linearized and assembled only in that side's system (step
/// control still evaluates all of them). The alternating system's factorization carries over
/// between solves (SolverOptions::alternatingReuse): a solve then depends on the solver's history
/// up to CG's tolerance.
class GuidedProjectionSolver {
 public:
  /// Analyzes `problem`'s topology. The problem must outlive the solver and keep its topology.
  /// @throws DeadlineExceeded once `deadline` has passed (checked while the pattern is analyzed)
  explicit GuidedProjectionSolver(Problem& problem,
                                  LinearSolverKind kind = LinearSolverKind::SimplicialLDLT,
                                  const Deadline& deadline = {});

  /// Runs guided projection on problem.x() in place.
  SolveSummary solve(const SolverOptions& options);

  /// Effective per-term weights at iteration k (schedules applied).
  std::vector<double> effectiveWeights(const SolverOptions& options, int k) const;
  /// Residual-only evaluation of every term at x with the given weights: per term Σ(w r)².
  std::vector<double> termResiduals(const Eigen::VectorXd& x, const std::vector<double>& weights);
  /// Starts step control afresh: relaxable terms at full weight, no extra damping.
  void resetStepControl() {
    pullLimit_ = 0.0;  // the next solve starts at its options' initialPullLimit
    dampingScale_ = 1.0;
    alternateDampingScale_ = 1.0;
  }
  /// The current pull limit of step control (0 before the first solve).
  double pullLimit() const { return pullLimit_; }
  /// Consecutive rejected steps after which a solve ends with Stalled.
  static constexpr int kStallRejections = 12;

  /// Free scalars of the problem (both systems' with alternation).
  int numFree() const { return equations_.numFree() + (alternate_ ? alternate_->numFree() : 0); }
  /// Upper-triangular nonzeros of the normal matrix (both systems' with alternation).
  long normalMatrixNonZeros() const { return equations_.nonZeros() + (alternate_ ? alternate_->nonZeros() : 0); }
  /// True if the solver alternates between two systems (VariableLayout::setAlternating).
  bool alternates() const { return alternate_ != nullptr; }
  const std::string linearSolverName() const { return linear_->name(); }
  /// Threads of the last solve's assembly (1 or 2; SolverOptions::assemblyThreads).
  int assemblyThreads() const { return equations_.assemblyThreads(); }

 private:
  /// Work vectors of conjugate gradients over one reduced system.
  struct PcgWork {
    Eigen::VectorXd residual, preconditioned, direction, product;
  };
  /// delta = solution of equations.matrix() δ = equations.rhs() by CG preconditioned with
  /// `linear`'s current factorization (of an earlier matrix). False if it did not reach
  /// `reuse.tolerance` within `reuse.maxIterations` or met non-positive curvature. `solves`:
  /// preconditioner applications.
  static bool solveWithEarlierFactorization(const NormalEquations& equations, LinearSolver& linear,
                                            Eigen::VectorXd& delta, PcgWork& work,
                                            const FactorizationReuseOptions& reuse, int& solves);

  Problem& problem_;
  NormalEquations equations_;
  std::unique_ptr<LinearSolver> linear_;
  /// The system of the alternating blocks and its linear solver (null without alternation).
  std::unique_ptr<NormalEquations> alternate_;
  std::unique_ptr<LinearSolver> alternateLinear_;
  Eigen::VectorXd alternateDelta_;
  PcgWork alternateWork_;
  /// Iterations since alternateLinear_ factorized (−1: never); kept across solves
  /// (SolverOptions::alternatingReuse).
  int alternateFactorAge_ = -1;
  double alternateDampingScale_ = 1.0;  ///< step control of the alternating system: ε_reg multiplier
  LinearSolverKind kind_;
  Eigen::VectorXd delta_;
  Eigen::VectorXd previousX_;
  Eigen::VectorXd step_;             ///< x_{k+1} − x_k of the full step (for shortening it)
  Eigen::VectorXd correctedX_;       ///< the iterate before a correction step (restored if it fails)
  Eigen::VectorXd plainX_;           ///< the Gauss–Newton step's iterate before its corrections
  std::vector<double> termMaxAbs_;   ///< per term: largest |r| of the last residual evaluation
  double pullLimit_ = 0.0;           ///< step control: see StepControlOptions (0: not yet set)
  double dampingScale_ = 1.0;        ///< step control: ε_reg multiplier
  // Factorization reuse (FactorizationReuseOptions): PCG work vectors over the reduced system.
  PcgWork work_;
};

}  // namespace devsurf::engine
