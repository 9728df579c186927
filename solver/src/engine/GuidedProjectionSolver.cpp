#include "devsurf/engine/GuidedProjectionSolver.h"

#include <chrono>
#include <cmath>
#include <algorithm>
#include <map>
#include <utility>

namespace devsurf::engine {
namespace {

using Clock = std::chrono::steady_clock;

double millisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

const char* terminationReasonName(TerminationReason reason) {
  switch (reason) {
    case TerminationReason::MaxIterations: return "max_iterations";
    case TerminationReason::ResidualTolerance: return "residual_tolerance";
    case TerminationReason::RelativeChange: return "relative_change";
    case TerminationReason::TimeBudget: return "time_budget";
    case TerminationReason::Aborted: return "aborted";
    case TerminationReason::Diverged: return "diverged";
  }
  return "unknown";
}

std::vector<std::pair<std::string, double>> SolveSummary::finalResidualsByName() const {
  std::vector<std::pair<std::string, double>> out;
  if (iterations.empty()) return out;
  const IterationRecord& last = iterations.back();
  for (std::size_t t = 0; t < termNames.size(); ++t) {
    auto it = std::find_if(out.begin(), out.end(),
                           [&name = termNames[t]](const auto& p) { return p.first == name; });
    if (it == out.end()) out.emplace_back(termNames[t], last.termResiduals[t]);
    else it->second += last.termResiduals[t];
  }
  return out;
}

GuidedProjectionSolver::GuidedProjectionSolver(Problem& problem, LinearSolverKind kind)
    : problem_(problem), equations_(problem), linear_(makeLinearSolver(kind)), kind_(kind) {
  linear_->analyzePattern(equations_.matrix());
  delta_.setZero(equations_.numReduced());
  previousX_.setZero(problem.x().size());
}

std::vector<double> GuidedProjectionSolver::effectiveWeights(const SolverOptions& options,
                                                             int k) const {
  std::vector<double> weights(problem_.numTerms());
  const double fairness = options.fairness * std::pow(options.fairnessDecay, k);
  for (int t = 0; t < problem_.numTerms(); ++t) {
    const TermSlot& slot = problem_.term(t);
    weights[t] = slot.weight * (slot.schedule == WeightSchedule::Fairness ? fairness : 1.0);
  }
  return weights;
}

std::vector<double> GuidedProjectionSolver::termResiduals(const Eigen::VectorXd& x,
                                                          const std::vector<double>& weights) {
  std::vector<double> out;
  equations_.residuals(problem_, x, weights, out);
  return out;
}

SolveSummary GuidedProjectionSolver::solve(const SolverOptions& options) {
  const Clock::time_point start = Clock::now();
  SolveSummary summary;
  for (int t = 0; t < problem_.numTerms(); ++t) summary.termNames.push_back(problem_.term(t).term->name());
  summary.iterations.reserve(static_cast<std::size_t>(std::max(0, options.maxIterations)) + 1);

  // Per-iteration work buffers, allocated once; so is every record's residual vector (the loop
  // itself allocates nothing).
  std::vector<double> weights(problem_.numTerms());
  std::vector<double> assembled(problem_.numTerms());
  std::vector<std::vector<double>> residualStore(
      static_cast<std::size_t>(std::max(0, options.maxIterations)),
      std::vector<double>(static_cast<std::size_t>(problem_.numTerms()), 0.0));
  auto fillWeights = [this, &options, &weights](int k) {
    const double fairness = options.fairness * std::pow(options.fairnessDecay, k);
    for (int t = 0; t < problem_.numTerms(); ++t) {
      const TermSlot& slot = problem_.term(t);
      weights[t] = slot.weight * (slot.schedule == WeightSchedule::Fairness ? fairness : 1.0);
    }
  };
  auto record = [this](IterationRecord& rec) {
    rec.hardResidual = rec.objective = rec.totalResidual = 0.0;
    for (int t = 0; t < problem_.numTerms(); ++t) {
      const TermSlot& slot = problem_.term(t);
      const double r = rec.termResiduals[t];
      rec.totalResidual += r;
      if (slot.strength == Strength::Hard) rec.hardResidual += r;
      if (slot.schedule == WeightSchedule::Constant) rec.objective += r;
    }
  };

  // Iteration 0: the initial state, weighed with the first iteration's weights.
  {
    IterationRecord rec;
    fillWeights(0);
    rec.fairnessWeight = options.fairness;
    equations_.residuals(problem_, problem_.x(), weights, rec.termResiduals);
    record(rec);
    rec.totalMs = millisecondsSince(start);
    summary.iterations.push_back(std::move(rec));
    if (options.callback && !options.callback(summary.iterations.back())) {
      summary.reason = TerminationReason::Aborted;
      summary.totalMs = millisecondsSince(start);
      return summary;
    }
    if (!std::isfinite(summary.iterations.back().totalResidual)) {
      summary.reason = TerminationReason::Diverged;
      summary.totalMs = millisecondsSince(start);
      return summary;
    }
  }

  summary.reason = TerminationReason::MaxIterations;
  for (int k = 0; k < options.maxIterations; ++k) {
    const Clock::time_point iterStart = Clock::now();
    IterationRecord rec;
    rec.iteration = k + 1;
    rec.termResiduals = std::move(residualStore[static_cast<std::size_t>(k)]);
    fillWeights(k);
    rec.fairnessWeight = options.fairness * std::pow(options.fairnessDecay, k);

    Clock::time_point t0 = Clock::now();
    equations_.assemble(problem_, weights, options.regularization, assembled);
    rec.assemblyMs = millisecondsSince(t0);

    // Factorization of H: block elimination of the elimination groups (Schur complement, see
    // NormalEquations), then the sparse factorization of the reduced matrix.
    t0 = Clock::now();
    const bool factored = equations_.eliminate() && linear_->factorize(equations_.matrix());
    rec.factorizationMs = millisecondsSince(t0);
    if (!factored) {
      summary.reason = TerminationReason::Diverged;
      break;
    }

    t0 = Clock::now();
    linear_->solve(equations_.rhs(), delta_);
    previousX_ = problem_.x();
    // Kept variables from delta_, eliminated ones by back-substitution; ‖δ‖ over all of them.
    rec.stepNorm = std::sqrt(equations_.applyStep(delta_, problem_.x()));
    if (!std::isfinite(rec.stepNorm)) {
      problem_.x() = previousX_;
      summary.reason = TerminationReason::Diverged;
      break;
    }
    rec.solveMs = millisecondsSince(t0);

    // Residuals at the new iterate, with this iteration's weights (residual-only path).
    equations_.residuals(problem_, problem_.x(), weights, rec.termResiduals);
    record(rec);
    if (!std::isfinite(rec.totalResidual)) {
      problem_.x() = previousX_;
      summary.reason = TerminationReason::Diverged;
      break;
    }
    rec.totalMs = millisecondsSince(iterStart);
    const double previousObjective = summary.iterations.back().objective;
    summary.iterations.push_back(std::move(rec));

    if (options.callback && !options.callback(summary.iterations.back())) {
      summary.reason = TerminationReason::Aborted;
      break;
    }
    if (rec.objective <= options.residualTolerance) {
      summary.reason = TerminationReason::ResidualTolerance;
      break;
    }
    if (k >= 1 && previousObjective > 0.0 &&
        std::abs(previousObjective - rec.objective) <=
                      options.relativeChangeTolerance * previousObjective) {
      summary.reason = TerminationReason::RelativeChange;
      break;
    }
    if (options.timeBudgetMs > 0.0 && millisecondsSince(start) >= options.timeBudgetMs) {
      summary.reason = TerminationReason::TimeBudget;
      break;
    }
  }
  summary.converged = summary.reason == TerminationReason::ResidualTolerance ||
                      summary.reason == TerminationReason::RelativeChange;
  summary.totalMs = millisecondsSince(start);
  return summary;
}

}  // namespace devsurf::engine
