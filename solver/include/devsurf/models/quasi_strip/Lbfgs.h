#pragma once

#include <functional>
#include <string>

#include <Eigen/Core>

namespace devsurf::models::quasi_strip {

/// Options of minimizeLbfgs; every field has a documented default.
struct LbfgsOptions {
  int memory = 10;                    ///< correction pairs kept (m)
  int maxIterations = 3000;           ///< iterations at most
  double gradientTolerance = 1e-10;   ///< stop when ‖∇f‖∞ ≤ this
  /// stop when f_{k−1} − f_k ≤ this · max(|f_k|, 1e-300) for 5 iterations in a row
  double relativeDecreaseTolerance = 1e-13;
  double absoluteTolerance = 1e-24;   ///< stop when f ≤ this
  double wolfeDecrease = 1e-4;        ///< c1 of the sufficient-decrease (Armijo) condition
  double wolfeCurvature = 0.9;        ///< c2 of the strong curvature condition
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
  LineSearchFailed,  ///< no step satisfying the strong Wolfe conditions was found (x is the best point)
  Aborted,           ///< the callback returned false
};
const char* lbfgsTerminationName(LbfgsTermination reason);

/// f(x) with its gradient written into `gradient` (already sized).
using ObjectiveWithGradient = std::function<double(const Eigen::VectorXd& x, Eigen::VectorXd& gradient)>;
/// Called after every iteration with (iteration, f, ‖∇f‖∞); return false to stop.
using LbfgsCallback = std::function<bool(int iteration, double value, double gradientNorm)>;

struct LbfgsResult {
  LbfgsTermination reason = LbfgsTermination::MaxIterations;
  double value = 0.0;
  double gradientNorm = 0.0;  ///< ‖∇f‖∞ at the result
  int iterations = 0;
  int evaluations = 0;
};

/// Limited-memory BFGS (Nocedal & Wright, Algorithms 7.4/7.5) with a line search for the strong
/// Wolfe conditions (bracketing and zoom with safeguarded cubic interpolation, Algorithms 3.5/3.6).
/// The first step is scaled to length 1/‖∇f‖; later ones start from α = 1 with the usual
/// γ = sᵀy/yᵀy initial Hessian. x is updated in place and always holds the best point found.
LbfgsResult minimizeLbfgs(const ObjectiveWithGradient& objective, Eigen::VectorXd& x,
                          const LbfgsOptions& options = {}, const LbfgsCallback& callback = {});

}  // namespace devsurf::models::quasi_strip
