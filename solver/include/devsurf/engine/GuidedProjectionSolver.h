#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/LinearSolver.h"
#include "devsurf/engine/NormalEquations.h"
#include "devsurf/engine/Problem.h"

namespace devsurf::engine {

/// Why a solve stopped.
enum class TerminationReason {
  MaxIterations,      ///< ran the requested number of iterations
  ResidualTolerance,  ///< objective (unscheduled terms) below residualTolerance
  RelativeChange,     ///< relative change of the objective below the tolerance
  TimeBudget,         ///< the time budget ran out
  Aborted,            ///< the iteration callback asked to stop
  Diverged,           ///< a step produced non-finite values or a singular system; x was restored
};
const char* terminationReasonName(TerminationReason reason);

/// One guided-projection iteration as the summary records it.
struct IterationRecord {
  int iteration = 0;                   ///< 0 = the initial state, k = after k steps
  std::vector<double> termResiduals;   ///< per term id: Σ (w r)², weights of this iteration
  double hardResidual = 0.0;           ///< Σ over hard terms
  double objective = 0.0;              ///< Σ over terms whose weight is not scheduled (hard and
                                       ///< soft targets such as handles): what termination watches
  double totalResidual = 0.0;          ///< Σ over all terms
  double stepNorm = 0.0;               ///< ‖δ‖ (0 for iteration 0)
  double fairnessWeight = 0.0;         ///< ε_fair · decay^k used for this step
  double assemblyMs = 0.0;             ///< linearize, evaluate, fill H and g
  double factorizationMs = 0.0;        ///< numeric factorization (incl. the block elimination
                                       ///< of elimination groups, see NormalEquations)
  double solveMs = 0.0;                ///< triangular solves and the update of x
  double totalMs = 0.0;                ///< whole iteration including residual evaluation
};

/// Options of a guided-projection solve; every field has a documented default
/// (000_… §3.2 eq. 6 and §7; 003_… §4.1, §5.6).
struct SolverOptions {
  int maxIterations = 20;                ///< iterations to run at most
  double fairness = 0.01;                ///< ε_fair: weight of Fairness-scheduled terms at k = 0
  double fairnessDecay = 0.8;            ///< ε_fair is multiplied by this every iteration
  double regularization = 1e-2;          ///< ε_reg: Tikhonov weight of ‖x − x_k‖² (Tang Fig. 17)
  double timeBudgetMs = 0.0;             ///< stop after this much wall time (0 = no budget)
  double residualTolerance = 1e-14;      ///< stop when the objective Σ(w r)² falls below
  double relativeChangeTolerance = 1e-9; ///< stop when |E_k − E_{k−1}| ≤ tol · E_{k−1}
                                         ///< (E = objective; checked from the second step on)
  /// Called after every iteration (and for iteration 0); return false to abort the solve.
  std::function<bool(const IterationRecord&)> callback;
};

/// What a solve did (Ceres `Summary`): per-iteration records and the reason it stopped.
struct SolveSummary {
  std::vector<std::string> termNames;       ///< per term id
  std::vector<IterationRecord> iterations;  ///< [0] is the initial state
  TerminationReason reason = TerminationReason::MaxIterations;
  bool converged = false;                   ///< reason is a tolerance (not max iterations/abort)
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
class GuidedProjectionSolver {
 public:
  /// Analyzes `problem`'s topology. The problem must outlive the solver and keep its topology.
  explicit GuidedProjectionSolver(Problem& problem,
                                  LinearSolverKind kind = LinearSolverKind::SimplicialLDLT);

  /// Runs guided projection on problem.x() in place.
  SolveSummary solve(const SolverOptions& options);

  /// Effective per-term weights at iteration k (schedules applied).
  std::vector<double> effectiveWeights(const SolverOptions& options, int k) const;
  /// Residual-only evaluation of every term at x with the given weights: per term Σ(w r)².
  std::vector<double> termResiduals(const Eigen::VectorXd& x, const std::vector<double>& weights);

  int numFree() const { return equations_.numFree(); }
  long normalMatrixNonZeros() const { return equations_.nonZeros(); }
  const std::string linearSolverName() const { return linear_->name(); }

 private:
  Problem& problem_;
  NormalEquations equations_;
  std::unique_ptr<LinearSolver> linear_;
  LinearSolverKind kind_;
  Eigen::VectorXd delta_;
  Eigen::VectorXd previousX_;
};

}  // namespace devsurf::engine
