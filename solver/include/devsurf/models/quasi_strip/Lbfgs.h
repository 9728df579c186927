#pragma once

#include <functional>
#include <string>

#include <Eigen/Core>

namespace devsurf::models::quasi_strip {

/// Options of minimizeLbfgs; every field has a documented default.
struct LbfgsOptions {
  int memory = 10;                    ///< correction pairs kept (m)
  int maxIterations = 3000;           ///< iterations at most
  double gradientTolerance = 1e-10;   ///< stop when ‖∇f‖₂ ≤ this · max(1, ‖x‖₂) (libLBFGS' ε)
  /// stop when f_{k−5} − f_k ≤ this · |f_k| (libLBFGS' delta test over past = 5 iterations)
  double relativeDecreaseTolerance = 5e-13;
  double absoluteTolerance = 1e-24;   ///< stop when f ≤ this
  double wolfeDecrease = 1e-4;        ///< c1 of the sufficient-decrease (Armijo) condition (ftol)
  double wolfeCurvature = 0.9;        ///< c2 of the curvature condition (gtol)
  int maxLineSearchEvaluations = 40;  ///< per line search
  double timeBudgetMs = 0.0;          ///< 0 = none
};

/// Why minimizeLbfgs stopped.
enum class LbfgsTermination {
  GradientTolerance,
  RelativeDecrease,
  AbsoluteTolerance,
  MaxIterations,
  TimeBudget,
  LineSearchFailed,  ///< the line search found no acceptable step (x is the last iterate)
  Aborted,           ///< the callback returned false
};
const char* lbfgsTerminationName(LbfgsTermination reason);

/// f(x) with its gradient written into `gradient` (already sized).
using ObjectiveWithGradient = std::function<double(const Eigen::VectorXd& x, Eigen::VectorXd& gradient)>;
/// Called after every iteration with (iteration, f, ‖∇f‖∞), x already updated; return false to stop.
using LbfgsCallback = std::function<bool(int iteration, double value, double gradientNorm)>;

struct LbfgsResult {
  LbfgsTermination reason = LbfgsTermination::MaxIterations;
  double value = 0.0;
  double gradientNorm = 0.0;  ///< ‖∇f‖∞ at the result
  int iterations = 0;
  int evaluations = 0;
};

/// Limited-memory BFGS by libLBFGS (Debian's liblbfgs-dev, Okazaki's port of Nocedal's code) with
/// its Moré–Thuente line search (sufficient decrease wolfeDecrease, curvature wolfeCurvature).
/// The first step has length 1/‖∇f‖. x is updated in place: the last iterate, also after a failed
/// line search (libLBFGS reverts to it) and when the callback stops the run.
/// @throws std::runtime_error when libLBFGS rejects its parameters or runs out of memory
LbfgsResult minimizeLbfgs(const ObjectiveWithGradient& objective, Eigen::VectorXd& x,
                          const LbfgsOptions& options = {}, const LbfgsCallback& callback = {});

}  // namespace devsurf::models::quasi_strip
