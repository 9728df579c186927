#include "devsurf/engine/GuidedProjectionSolver.h"

#include "devsurf/engine/ThreadCpuClock.h"

#include <chrono>
#include <sched.h>
#include <cmath>
#include <algorithm>
#include <limits>
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
    case TerminationReason::Stalled: return "stalled";
    case TerminationReason::HardTolerance: return "hard_tolerance";
    case TerminationReason::HardPlateau: return "hard_plateau";
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

namespace {

/// Whether the problem's free scalars split into two non-empty sides (VariableLayout::setAlternating).
bool splitsInTwo(const VariableLayout& layout) {
  return layout.hasAlternation() && layout.numFree(VariablePart::Main) > 0;
}

}  // namespace

GuidedProjectionSolver::GuidedProjectionSolver(Problem& problem, LinearSolverKind kind, const Deadline& deadline)
    : problem_(problem),
      equations_(problem, deadline, splitsInTwo(problem.layout()) ? VariablePart::Main : VariablePart::All),
      linear_(makeLinearSolver(kind)),
      kind_(kind) {
  deadline.check();
  linear_->analyzePattern(equations_.matrix());
  delta_.setZero(equations_.numReduced());
  previousX_.setZero(problem.x().size());
  if (splitsInTwo(problem.layout())) {
    alternate_ = std::make_unique<NormalEquations>(problem, deadline, VariablePart::Alternating);
    alternate_->setKeepEvaluations(false);  // its steps are judged by partResiduals
    alternateLinear_ = makeLinearSolver(kind);
    alternateLinear_->analyzePattern(alternate_->matrix());
    alternateDelta_.setZero(alternate_->numReduced());
  }
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

bool GuidedProjectionSolver::solveWithEarlierFactorization(const NormalEquations& equations, LinearSolver& linear,
                                                           Eigen::VectorXd& delta, PcgWork& work,
                                                           const FactorizationReuseOptions& reuse, int& solves) {
  const SymmetricUpper& H = equations.matrix();
  const Eigen::VectorXd& g = equations.rhs();
  const double target = reuse.tolerance * g.norm();
  Eigen::VectorXd& r = work.residual;
  Eigen::VectorXd& z = work.preconditioned;
  Eigen::VectorXd& p = work.direction;
  Eigen::VectorXd& Hp = work.product;
  linear.solve(g, delta);  // the earlier matrix's step: the start
  ++solves;
  r = g;
  r.noalias() -= H.selfadjointView<Eigen::Upper>() * delta;
  double rz = 0.0;
  for (int it = 0;; ++it) {
    if (!(r.norm() > target)) return std::isfinite(r.norm());
    if (it >= reuse.maxIterations) return false;
    linear.solve(r, z);
    ++solves;
    const double rzNext = r.dot(z);
    if (it == 0) p = z;
    else p = z + (rzNext / rz) * p;
    rz = rzNext;
    Hp.noalias() = H.selfadjointView<Eigen::Upper>() * p;
    const double curvature = p.dot(Hp);
    if (!(curvature > 0.0)) return false;
    const double alpha = rz / curvature;
    delta += alpha * p;
    r -= alpha * Hp;
  }
}

namespace {

/// The cores this process may run on (its affinity mask), as taskset and cgroup cpusets set it.
int availableCores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) != 0) return 1;
  return std::max(1, CPU_COUNT(&set));
}

}  // namespace

SolveSummary GuidedProjectionSolver::solve(const SolverOptions& options) {
  const Clock::time_point start = Clock::now();
  const ThreadCpuClock::time_point cpuStart = ThreadCpuClock::now();
  // What the time budget measures (SolverOptions::budgetClock): on the thread's CPU clock, plus
  // the time this thread waited for a second assembly thread (its share of an assembly's work).
  auto assemblyWaitMs = [this]() { return equations_.assemblyWaitMs() + (alternate_ ? alternate_->assemblyWaitMs() : 0.0); };
  const double waitStart = assemblyWaitMs();
  auto budgetSpent = [&options, start, cpuStart, waitStart, &assemblyWaitMs]() {
    if (options.budgetClock == BudgetClock::Wall) return millisecondsSince(start) >= options.timeBudgetMs;
    const double cpuMs = std::chrono::duration<double, std::milli>(ThreadCpuClock::now() - cpuStart).count();
    return cpuMs + assemblyWaitMs() - waitStart >= options.timeBudgetMs ||
           (options.budgetWallCapMs > 0.0 && millisecondsSince(start) >= options.budgetWallCapMs);
  };
  // Targets, weights and term data may have changed since the last solve: nothing evaluated before
  // it is taken for this one's first assembly.
  equations_.setKeepEvaluations(options.keepEvaluations);  // and forgets what was kept
  equations_.setAssemblyThreads(options.assemblyThreads > 0 ? options.assemblyThreads : availableCores());
  if (alternate_) alternate_->setAssemblyThreads(options.assemblyThreads > 0 ? options.assemblyThreads : availableCores());
  SolveSummary summary;
  summary.alternating = alternate_ != nullptr;
  for (int t = 0; t < problem_.numTerms(); ++t) summary.termNames.push_back(problem_.term(t).term->name());
  summary.iterations.reserve(static_cast<std::size_t>(std::max(0, options.maxIterations)) + 1);

  // Per-iteration work buffers, allocated once; so is every record's residual vector (the loop
  // itself allocates nothing).
  const int numTerms = problem_.numTerms();
  std::vector<double> weights(numTerms);
  std::vector<double> assembled(numTerms), trial(numTerms);
  std::vector<std::vector<double>> residualStore(
      static_cast<std::size_t>(std::max(0, options.maxIterations)),
      std::vector<double>(static_cast<std::size_t>(numTerms), 0.0));
  termMaxAbs_.assign(static_cast<std::size_t>(numTerms), 0.0);
  step_.setZero(problem_.x().size());
  correctedX_.setZero(problem_.x().size());
  plainX_.setZero(problem_.x().size());
  const StepControlOptions& control = options.stepControl;
  if (pullLimit_ <= 0.0) pullLimit_ = control.initialPullLimit;
  bool anyRelaxable = false;
  for (int t = 0; t < numTerms; ++t)
    anyRelaxable = anyRelaxable || (problem_.term(t).relaxable && problem_.term(t).weight > 0.0);

  auto fillWeights = [this, &options, &weights, numTerms](int k) {
    const double fairness = options.fairness * std::pow(options.fairnessDecay, k);
    for (int t = 0; t < numTerms; ++t) {
      const TermSlot& slot = problem_.term(t);
      weights[t] = slot.weight * (slot.schedule == WeightSchedule::Fairness ? fairness : 1.0);
    }
  };
  // Sums of the record from per-term residuals (and the per-term row maxima in termMaxAbs_).
  auto record = [this, &weights, numTerms](IterationRecord& rec, const std::vector<double>& residuals) {
    rec.hardResidual = rec.objective = rec.totalResidual = rec.hardResidualMax = 0.0;
    for (int t = 0; t < numTerms; ++t) {
      const TermSlot& slot = problem_.term(t);
      const double r = residuals[t];
      rec.totalResidual += r;
      if (slot.strength == Strength::Hard) {
        rec.hardResidual += r;
        const double m = std::abs(weights[t]) * termMaxAbs_[t];
        rec.hardResidualMax = std::isnan(m) ? m : std::max(rec.hardResidualMax, m);
      }
      if (slot.schedule == WeightSchedule::Constant) rec.objective += r;
    }
    if (std::isnan(rec.hardResidualMax)) rec.totalResidual = rec.hardResidualMax;
  };
  double evaluationMs = 0.0;  // this iteration's residual evaluations (IterationRecord::evaluationMs)
  auto evaluate = [this, &weights, &evaluationMs](const Eigen::VectorXd& x, std::vector<double>& out) {
    const Clock::time_point t0 = Clock::now();
    equations_.residuals(problem_, x, weights, out, &termMaxAbs_);
    evaluationMs += millisecondsSince(t0);
  };

  // The weights of a projection step: the targets (handles) drop out. Fairness stays: the hard
  // rows alone leave many directions of the control polygons undetermined, and a step along
  // them (held only by ε_reg) breaks the rows it was to restore (measured: every projection step
  // without fairness rejected on the two-creases preset).
  std::vector<double> projectionWeights(numTerms);
  auto fillProjectionWeights = [this, &weights, &projectionWeights, numTerms, &options]() {
    for (int t = 0; t < numTerms; ++t) {
      const TermSlot& slot = problem_.term(t);
      const bool held = options.holdTargetsInProjection && slot.heldInProjection;
      projectionWeights[t] = slot.relaxable && !held ? 0.0 : weights[t];
    }
  };

  // The constants a term holds for an iteration (foot points, row scales) taken at the initial
  // state, as the first assembly takes them: a term built since the last solve (a rebuild) has
  // none of its own yet, and one solved before holds those of an earlier iterate. Evaluated with
  // stale ones, the initial hard rows measured what they do not mean (a new tangent-distance row
  // measured a vertex's x against the foot (0, 0): 0.9 where the vertex lay on its curve), and
  // the first step was judged against that (step control let a step tear the sheet by 0.39).
  for (int t = 0; t < numTerms; ++t) problem_.term(t).term->linearizeAt(problem_.x());

  // Iteration 0: the initial state, weighed with the first iteration's weights.
  {
    IterationRecord rec;
    fillWeights(0);
    rec.fairnessWeight = options.fairness;
    rec.pullLimit = anyRelaxable ? pullLimit_ : 0.0;
    evaluate(problem_.x(), rec.termResiduals);
    record(rec, rec.termResiduals);
    rec.evaluationMs = evaluationMs;  // iteration 0 is this evaluation
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

  // The alternating blocks' step at the current iterate, the others held (block Gauss–Seidel;
  // VariableLayout::setAlternating), after the iteration's step; `mainRejected`: that step was not
  // taken (x is the last iterate). Updates x, rec's residuals and records; false if the step
  // diverged with step control off (the caller restores x).
  auto alternateStep = [this, &options, &control, &assembled, &trial, &weights, &evaluate, &record](
                           IterationRecord& rec, const std::vector<double>& systemWeights, bool mainRejected) {
    const FactorizationReuseOptions& reuse = options.alternatingReuse;
    if (alternateFactorAge_ >= 0) ++alternateFactorAge_;
    bool factored = false, reused = false;
    // A system that is numerically not positive definite is damped and factorized again (as the
    // step's own, SolverOptions::stepControl).
    for (int attempt = 0; attempt < 4 && !factored; ++attempt) {
      if (attempt > 0) {
        if (!control.enabled) break;
        alternateDampingScale_ *= 100.0;
      }
      Clock::time_point t0 = Clock::now();
      alternate_->assemble(problem_, systemWeights, options.regularization * std::sqrt(alternateDampingScale_),
                           assembled, control.enabled ? pullLimit_ : std::numeric_limits<double>::infinity());
      rec.assemblyMs += millisecondsSince(t0);
      t0 = Clock::now();
      if (!alternate_->eliminate()) {
        rec.factorizationMs += millisecondsSince(t0);
        continue;
      }
      if (attempt == 0 && reuse.maxAge > 0 && alternateFactorAge_ >= 0 && alternateFactorAge_ <= reuse.maxAge) {
        rec.factorizationMs += millisecondsSince(t0);
        t0 = Clock::now();
        reused = solveWithEarlierFactorization(*alternate_, *alternateLinear_, alternateDelta_, alternateWork_, reuse,
                                               rec.pcgIterations);
        rec.solveMs += millisecondsSince(t0);
        t0 = Clock::now();
      }
      factored = reused || alternateLinear_->factorize(alternate_->matrix());
      if (!reused) {
        alternateFactorAge_ = factored ? 0 : -1;
        rec.alternatingFactorized = factored;
      }
      rec.factorizationMs += millisecondsSince(t0);
    }
    if (!factored) return control.enabled;  // no step; without step control the solve diverged
    Clock::time_point t0 = Clock::now();
    if (!reused) alternateLinear_->solve(alternate_->rhs(), alternateDelta_);
    correctedX_ = problem_.x();  // the iterate before this step
    const double norm = std::sqrt(alternate_->applyStep(alternateDelta_, problem_.x()));
    step_ = problem_.x() - correctedX_;
    rec.solveMs += millisecondsSince(t0);
    if (!std::isfinite(norm) && !control.enabled) return false;
    if (mainRejected && control.enabled) {
      // rec holds the last iterate's residuals, weighed with the last iteration's weights, and
      // termMaxAbs_ the rejected trial's rows: both of x again, with this iteration's weights.
      evaluate(correctedX_, rec.termResiduals);
      record(rec, rec.termResiduals);
    }
    const double rowLimit = std::max(control.hardBand, rec.hardResidualMax);
    const double hardBefore = rec.hardResidual;
    double alpha = 1.0;
    for (int h = 0; h <= control.maxHalvings && std::isfinite(norm); ++h) {
      if (h > 0) {
        alpha *= 0.5;
        problem_.x() = correctedX_ + alpha * step_;
      }
      std::copy(rec.termResiduals.begin(), rec.termResiduals.end(), trial.begin());
      alternate_->partResiduals(problem_, problem_.x(), weights, trial, termMaxAbs_);
      IterationRecord probe;
      record(probe, trial);
      const bool acceptable = std::isfinite(probe.totalResidual) && probe.hardResidualMax <= rowLimit &&
                              (probe.hardResidualMax <= control.hardBand || probe.hardResidual <= hardBefore);
      if (acceptable || !control.enabled) {
        if (!control.enabled && !std::isfinite(probe.totalResidual)) return false;
        std::copy(trial.begin(), trial.end(), rec.termResiduals.begin());
        record(rec, rec.termResiduals);
        const double moved = alpha * norm;
        rec.stepNorm = std::sqrt(rec.stepNorm * rec.stepNorm + moved * moved);
        rec.alternatingStepScale = alpha;
        // Damping of this system: eased after a full step, raised after a shortened one.
        alternateDampingScale_ = alpha == 1.0 ? std::max(1.0, 0.25 * alternateDampingScale_) : 2.0 * alternateDampingScale_;
        return true;
      }
    }
    problem_.x() = correctedX_;  // not taken
    std::copy(rec.termResiduals.begin(), rec.termResiduals.end(), trial.begin());
    alternate_->partResiduals(problem_, problem_.x(), weights, trial, termMaxAbs_);  // termMaxAbs_ of x
    alternateDampingScale_ *= 4.0;
    return true;
  };

  int rejectedInARow = 0;
  // Iterations since the linear solver's factorization was made in this solve() (−1: none yet;
  // FactorizationReuseOptions).
  int factorAge = -1;
  summary.reason = TerminationReason::MaxIterations;
  for (int k = 0; k < options.maxIterations; ++k) {
    options.deadline.check();  // throws: x is the last iterate
    if (factorAge >= 0) ++factorAge;
    const Clock::time_point iterStart = Clock::now();
    evaluationMs = 0.0;
    const IterationRecord& previous = summary.iterations.back();
    const double previousObjective = previous.objective;
    const double previousHard = previous.hardResidual;
    IterationRecord rec;
    rec.iteration = k + 1;
    rec.termResiduals = std::move(residualStore[static_cast<std::size_t>(k)]);
    const int scheduleK = options.firstIteration + k;
    fillWeights(scheduleK);
    rec.fairnessWeight = options.fairness * std::pow(options.fairnessDecay, scheduleK);
    rec.pullLimit = anyRelaxable ? pullLimit_ : 0.0;
    previousX_ = problem_.x();

    // One Gauss–Newton step with the given system weights from previousX_; with step control,
    // shortened until acceptable. Returns false if the system could not be factorized; `taken` is
    // the accepted α (0: x is previousX_ again).
    auto step = [&](const std::vector<double>& systemWeights, double limit, bool strict, double& taken) {
      Clock::time_point t0 = Clock::now();
      equations_.assemble(problem_, systemWeights, options.regularization * std::sqrt(dampingScale_), assembled,
                          limit);
      summary.keptEvaluations += equations_.reusedTerms();
      rec.assemblyMs += millisecondsSince(t0);
      // Factorization of H: block elimination of the elimination groups (Schur complement, see
      // NormalEquations), then the sparse factorization of the reduced matrix — or, with
      // factorization reuse, CG on the reduced matrix preconditioned with an earlier factorization.
      t0 = Clock::now();
      bool factored = equations_.eliminate();
      bool reused = false;
      const FactorizationReuseOptions& reuse = options.factorizationReuse;
      if (factored && reuse.maxAge > 0 && factorAge >= 0 && factorAge <= reuse.maxAge) {
        rec.factorizationMs += millisecondsSince(t0);
        t0 = Clock::now();
        reused = solveWithEarlierFactorization(equations_, *linear_, delta_, work_, reuse, rec.pcgIterations);
        rec.solveMs += millisecondsSince(t0);
        t0 = Clock::now();
      }
      if (factored && !reused) {
        factored = linear_->factorize(equations_.matrix());
        factorAge = factored ? 0 : -1;
        rec.factorized = rec.factorized || factored;
      }
      rec.factorizationMs += millisecondsSince(t0);
      // With step control, a system that is numerically not positive definite (ε_reg² D tiny
      // against JᵀJ of stiff rows) is damped and factorized again rather than ending the solve.
      for (int retry = 0; !factored && control.enabled && retry < 3; ++retry) {
        dampingScale_ *= 100.0;
        t0 = Clock::now();
        equations_.assemble(problem_, systemWeights, options.regularization * std::sqrt(dampingScale_), assembled,
                            limit);
        rec.assemblyMs += millisecondsSince(t0);
        t0 = Clock::now();
        factored = equations_.eliminate() && linear_->factorize(equations_.matrix());
        factorAge = factored ? 0 : -1;
        rec.factorized = rec.factorized || factored;
        rec.factorizationMs += millisecondsSince(t0);
      }
      if (!factored) return false;
      t0 = Clock::now();
      if (!reused) linear_->solve(equations_.rhs(), delta_);
      problem_.x() = previousX_;
      // Kept variables from delta_, eliminated ones by back-substitution; ‖δ‖ over all of them.
      const double norm = std::sqrt(equations_.applyStep(delta_, problem_.x()));
      rec.solveMs += millisecondsSince(t0);
      rec.stepNorm = norm;
      // Residuals at the new iterate, with this iteration's nominal weights (residual-only path).
      evaluate(problem_.x(), rec.termResiduals);
      record(rec, rec.termResiduals);
      // No row may leave the band (or, above it already, grow); above the band the hard
      // residual must not grow either. A sum alone would let one row tear while many others fall.
      const double rowLimit = std::max(control.hardBand, previous.hardResidualMax);
      auto acceptable = [&control, previousHard, rowLimit, strict](const IterationRecord& r) {
        if (!std::isfinite(r.totalResidual) || r.hardResidualMax > rowLimit) return false;
        if (strict) return r.hardResidual < previousHard || r.hardResidual == 0.0;
        return r.hardResidualMax <= control.hardBand || r.hardResidual <= previousHard;
      };
      // Correction steps: the same system solved again with the hard rows' residuals at the new
      // iterate (SolverOptions::correctionSteps), kept while each lowers the hard residual and
      // lifts no row above what step control allows.
      rec.corrections = 0;
      const double plainNorm = norm;
      if (options.correctionSteps > 0 && !reused && std::isfinite(rec.totalResidual) && rec.hardResidual > 0.0)
        plainX_ = problem_.x();
      for (int c = 0; c < options.correctionSteps && !reused && std::isfinite(rec.totalResidual) &&
                      rec.hardResidual > 0.0;
           ++c) {
        t0 = Clock::now();
        equations_.correctionRhs(problem_, problem_.x());
        correctedX_ = problem_.x();
        linear_->solve(equations_.rhs(), delta_);
        equations_.applyStep(delta_, problem_.x());
        rec.solveMs += millisecondsSince(t0);
        evaluate(problem_.x(), trial);
        IterationRecord probe;
        record(probe, trial);
        const bool rowsKept = !control.enabled || probe.hardResidualMax <= std::max(rowLimit, rec.hardResidualMax);
        if (!std::isfinite(probe.totalResidual) || !(probe.hardResidual < rec.hardResidual) || !rowsKept) {
          problem_.x() = correctedX_;
          evaluate(problem_.x(), trial);  // termMaxAbs_ of the iterate kept
          break;
        }
        std::copy(trial.begin(), trial.end(), rec.termResiduals.begin());
        record(rec, rec.termResiduals);
        rec.stepNorm = (problem_.x() - previousX_).norm();
        ++rec.corrections;
      }
      taken = 1.0;
      if (!control.enabled) return true;
      if (acceptable(rec)) return true;
      if (rec.corrections > 0) {
        // The corrected step is not acceptable: judge and shorten the plain step (a correction
        // belongs to the full step, not to a fraction of it).
        problem_.x() = plainX_;
        evaluate(problem_.x(), rec.termResiduals);
        record(rec, rec.termResiduals);
        rec.stepNorm = plainNorm;
        rec.corrections = 0;
        if (acceptable(rec)) return true;
      }
      const double stepNorm = rec.stepNorm;
      const bool finiteStep = std::isfinite(stepNorm);
      step_ = problem_.x() - previousX_;
      double alpha = 1.0;
      for (int h = 0; h < control.maxHalvings && finiteStep; ++h) {
        alpha *= 0.5;
        problem_.x() = previousX_ + alpha * step_;
        evaluate(problem_.x(), trial);
        IterationRecord probe;
        record(probe, trial);
        if (acceptable(probe)) {
          std::copy(trial.begin(), trial.end(), rec.termResiduals.begin());
          record(rec, rec.termResiduals);
          rec.stepNorm = alpha * stepNorm;
          taken = alpha;
          return true;
        }
      }
      taken = 0.0;
      return true;
    };

    double alpha = 0.0;
    if (options.projectionOnly) fillProjectionWeights();
    bool factored = step(options.projectionOnly ? projectionWeights : weights,
                         control.enabled ? pullLimit_ : std::numeric_limits<double>::infinity(), false, alpha);
    rec.projected = options.projectionOnly;
    const bool pulling = anyRelaxable && !options.projectionOnly;
    if (factored && control.enabled && alpha < 1.0) {
      // The step tore the shape: the targets are approached more slowly from now on, or — without
      // targets — the steps are damped.
      if (pulling) pullLimit_ = std::max(control.minPullLimit, pullLimit_ * (alpha > 0.0 ? 0.5 : 0.25));
      else dampingScale_ *= alpha > 0.0 ? 2.0 : 4.0;
      if (alpha == 0.0 && pulling) {
        // Instead of this step, a projection step (no targets) from the last good iterate. Known:
        // it is linearized at the rejected step's last, shortest trial (where x still is), and
        // applied from previousX_ (docs/architecture.md, "Stop 44").
        fillProjectionWeights();
        factored = step(projectionWeights, std::numeric_limits<double>::infinity(), true, alpha);
        rec.projected = true;
        if (factored && alpha == 0.0) dampingScale_ *= 4.0;  // not even that: damp what follows
      }
    } else if (factored && control.enabled) {
      pullLimit_ = std::min(control.maxPullLimit, 2.0 * pullLimit_);
      dampingScale_ = std::max(1.0, 0.25 * dampingScale_);
    }
    if (!factored) {
      problem_.x() = previousX_;
      summary.reason = TerminationReason::Diverged;
      break;
    }
    if (alpha == 0.0 && control.enabled) {  // back to the last good iterate
      problem_.x() = previousX_;
      std::copy(previous.termResiduals.begin(), previous.termResiduals.end(), rec.termResiduals.begin());
      rec.hardResidual = previous.hardResidual;
      rec.hardResidualMax = previous.hardResidualMax;
      rec.objective = previous.objective;
      rec.totalResidual = previous.totalResidual;
      rec.stepNorm = 0.0;
    }
    if (alternate_ && !alternateStep(rec, rec.projected ? projectionWeights : weights, alpha == 0.0)) {
      problem_.x() = previousX_;
      summary.reason = TerminationReason::Diverged;
      break;
    }
    rec.stepScale = alpha;
    // Something moved: the step, or the alternating blocks' step after it.
    const bool moved = alpha > 0.0 || rec.alternatingStepScale > 0.0;
    rejectedInARow = moved ? 0 : rejectedInARow + 1;
    if (!control.enabled && (!std::isfinite(rec.stepNorm) || !std::isfinite(rec.totalResidual))) {
      problem_.x() = previousX_;
      summary.reason = TerminationReason::Diverged;
      break;
    }
    rec.evaluationMs = evaluationMs;
    rec.totalMs = millisecondsSince(iterStart);
    summary.iterations.push_back(std::move(rec));
    const IterationRecord& last = summary.iterations.back();

    if (options.callback && !options.callback(last)) {
      summary.reason = TerminationReason::Aborted;
      break;
    }
    if (rejectedInARow >= kStallRejections) {
      summary.reason = TerminationReason::Stalled;
      break;
    }
    if (!moved) continue;  // nothing moved: no tolerance can have been reached
    if (last.objective <= options.residualTolerance) {
      summary.reason = TerminationReason::ResidualTolerance;
      break;
    }
    if (options.hardTolerance > 0.0 && last.hardResidualMax <= options.hardTolerance) {
      summary.reason = TerminationReason::HardTolerance;
      break;
    }
    if (options.projectionOnly && options.hardTolerance > 0.0 && options.hardPlateau.steps > 0 &&
        last.hardResidualMax <=
            (alternate_ ? options.hardPlateau.alternatingRange : options.hardPlateau.range) * options.hardTolerance &&
        summary.iterations.size() > static_cast<std::size_t>(options.hardPlateau.steps)) {
      const double before =
          summary.iterations[summary.iterations.size() - 1 - static_cast<std::size_t>(options.hardPlateau.steps)]
              .hardResidualMax;
      if (last.hardResidualMax > (1.0 - options.hardPlateau.decrease) * before) {
        summary.reason = TerminationReason::HardPlateau;
        break;
      }
    }
    if (k >= 1 && last.stepScale == 1.0 && (!alternate_ || last.alternatingStepScale == 1.0) && !last.projected &&
        previousObjective > 0.0 &&
        std::abs(previousObjective - last.objective) <= options.relativeChangeTolerance * previousObjective) {
      summary.reason = TerminationReason::RelativeChange;
      break;
    }
    if (options.timeBudgetMs > 0.0 && budgetSpent()) {
      summary.reason = TerminationReason::TimeBudget;
      break;
    }
  }
  summary.converged = summary.reason == TerminationReason::ResidualTolerance ||
                      summary.reason == TerminationReason::RelativeChange ||
                      summary.reason == TerminationReason::HardTolerance ||
                      summary.reason == TerminationReason::HardPlateau;
  summary.totalMs = millisecondsSince(start);
  return summary;
}

}  // namespace devsurf::engine
