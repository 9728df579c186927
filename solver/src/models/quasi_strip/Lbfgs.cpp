#include "devsurf/models/quasi_strip/Lbfgs.h"

#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>

#include <lbfgs.h>

namespace devsurf::models::quasi_strip {

static_assert(sizeof(lbfgsfloatval_t) == sizeof(double), "liblbfgs must be built with double precision");

const char* lbfgsTerminationName(LbfgsTermination reason) {
  switch (reason) {
    case LbfgsTermination::GradientTolerance: return "gradient_tolerance";
    case LbfgsTermination::RelativeDecrease: return "relative_decrease";
    case LbfgsTermination::AbsoluteTolerance: return "absolute_tolerance";
    case LbfgsTermination::MaxIterations: return "max_iterations";
    case LbfgsTermination::TimeBudget: return "time_budget";
    case LbfgsTermination::LineSearchFailed: return "line_search_failed";
    case LbfgsTermination::Aborted: return "aborted";
  }
  return "unknown";
}

namespace {

using Clock = std::chrono::steady_clock;

/// What libLBFGS' callbacks need (passed as its `instance`).
struct Run {
  const ObjectiveWithGradient& objective;
  const LbfgsCallback& callback;
  const LbfgsOptions& options;
  Eigen::VectorXd& x;  ///< the caller's x: kept at the current iterate for the callback
  Eigen::VectorXd point, gradient;
  Clock::time_point start = Clock::now();
  LbfgsResult result;
  bool stopped = false;  ///< the progress callback ended the run; result.reason says why
};

/// Return value of the progress callback that ends the run (positive: not a libLBFGS code).
constexpr int kStop = 1000;

lbfgsfloatval_t evaluate(void* instance, const lbfgsfloatval_t* x, lbfgsfloatval_t* g, const int n,
                         const lbfgsfloatval_t /*step*/) {
  Run& run = *static_cast<Run*>(instance);
  run.point = Eigen::Map<const Eigen::VectorXd>(x, n);
  const double f = run.objective(run.point, run.gradient);
  Eigen::Map<Eigen::VectorXd>(g, n) = run.gradient;
  ++run.result.evaluations;
  return f;
}

int progress(void* instance, const lbfgsfloatval_t* x, const lbfgsfloatval_t* g, const lbfgsfloatval_t fx,
             const lbfgsfloatval_t /*xnorm*/, const lbfgsfloatval_t /*gnorm*/, const lbfgsfloatval_t /*step*/, int n,
             int k, int /*ls*/) {
  Run& run = *static_cast<Run*>(instance);
  run.x = Eigen::Map<const Eigen::VectorXd>(x, n);
  run.result.iterations = k;
  run.result.value = fx;
  run.result.gradientNorm = n ? Eigen::Map<const Eigen::VectorXd>(g, n).cwiseAbs().maxCoeff() : 0.0;
  auto stop = [&run](LbfgsTermination reason) {
    run.result.reason = reason;
    run.stopped = true;
    return kStop;
  };
  if (run.callback && !run.callback(k, fx, run.result.gradientNorm)) return stop(LbfgsTermination::Aborted);
  if (fx <= run.options.absoluteTolerance) return stop(LbfgsTermination::AbsoluteTolerance);
  if (run.options.timeBudgetMs > 0.0 &&
      std::chrono::duration<double, std::milli>(Clock::now() - run.start).count() > run.options.timeBudgetMs)
    return stop(LbfgsTermination::TimeBudget);
  return 0;
}

}  // namespace

LbfgsResult minimizeLbfgs(const ObjectiveWithGradient& objective, Eigen::VectorXd& x, const LbfgsOptions& options,
                          const LbfgsCallback& callback) {
  const int n = static_cast<int>(x.size());
  Run run{objective, callback, options, x, Eigen::VectorXd(n), Eigen::VectorXd(n)};
  if (n == 0) {
    run.result.reason = LbfgsTermination::GradientTolerance;
    run.result.value = objective(x, run.gradient);
    return run.result;
  }
  lbfgs_parameter_t param;
  lbfgs_parameter_init(&param);
  param.m = options.memory;
  param.max_iterations = options.maxIterations;
  param.epsilon = options.gradientTolerance;
  param.past = 5;
  param.delta = options.relativeDecreaseTolerance;
  param.linesearch = LBFGS_LINESEARCH_MORETHUENTE;
  param.ftol = options.wolfeDecrease;
  param.gtol = options.wolfeCurvature;
  param.max_linesearch = options.maxLineSearchEvaluations;
  // libLBFGS may use SSE on its own buffer: x lives in lbfgs_malloc'd memory during the run.
  const std::unique_ptr<lbfgsfloatval_t, void (*)(lbfgsfloatval_t*)> buffer(lbfgs_malloc(n), lbfgs_free);
  if (!buffer) throw std::runtime_error("L-BFGS: out of memory for " + std::to_string(n) + " variables");
  Eigen::Map<Eigen::VectorXd>(buffer.get(), n) = x;
  lbfgsfloatval_t f = 0.0;
  const int code = lbfgs(n, buffer.get(), &f, evaluate, progress, &run, &param);
  x = Eigen::Map<const Eigen::VectorXd>(buffer.get(), n);
  run.result.value = f;
  if (run.stopped && code == kStop) return run.result;
  switch (code) {
    case LBFGS_SUCCESS:
    case LBFGS_ALREADY_MINIMIZED:
      run.result.reason = LbfgsTermination::GradientTolerance;
      break;
    case LBFGS_STOP:
      run.result.reason = LbfgsTermination::RelativeDecrease;
      break;
    case LBFGSERR_MAXIMUMITERATION:
      run.result.reason = LbfgsTermination::MaxIterations;
      break;
    case LBFGSERR_ROUNDING_ERROR:
    case LBFGSERR_MINIMUMSTEP:
    case LBFGSERR_MAXIMUMSTEP:
    case LBFGSERR_MAXIMUMLINESEARCH:
    case LBFGSERR_WIDTHTOOSMALL:
    case LBFGSERR_INVALIDPARAMETERS:
    case LBFGSERR_INCREASEGRADIENT:
    case LBFGSERR_OUTOFINTERVAL:
    case LBFGSERR_INCORRECT_TMINMAX:
      run.result.reason = LbfgsTermination::LineSearchFailed;
      break;
    default:
      throw std::runtime_error("L-BFGS: libLBFGS stopped with error code " + std::to_string(code));
  }
  // The gradient at the returned x (libLBFGS reverts x after a failed line search).
  Eigen::VectorXd g(n);
  run.result.value = objective(x, g);
  run.result.gradientNorm = g.cwiseAbs().maxCoeff();
  return run.result;
}

}  // namespace devsurf::models::quasi_strip
