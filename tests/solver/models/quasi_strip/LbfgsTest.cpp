// The small L-BFGS of the quasi-strip model.

#include <gtest/gtest.h>

#include <cmath>

#include "devsurf/models/quasi_strip/Lbfgs.h"

namespace devsurf::models::quasi_strip {
namespace {

/// Extended Rosenbrock in n dimensions, minimum 0 at (1, …, 1).
double rosenbrock(const Eigen::VectorXd& x, Eigen::VectorXd& g) {
  double f = 0.0;
  g.setZero();
  for (Eigen::Index i = 0; i + 1 < x.size(); ++i) {
    const double a = x[i + 1] - x[i] * x[i], b = 1.0 - x[i];
    f += 100.0 * a * a + b * b;
    g[i] += -400.0 * a * x[i] - 2.0 * b;
    g[i + 1] += 200.0 * a;
  }
  return f;
}

TEST(Lbfgs, FindsTheMinimumOfTheRosenbrockFunction) {
  Eigen::VectorXd x = Eigen::VectorXd::Constant(10, -1.2);
  const LbfgsResult r = minimizeLbfgs(rosenbrock, x);
  EXPECT_TRUE(r.reason == LbfgsTermination::GradientTolerance ||
              r.reason == LbfgsTermination::AbsoluteTolerance)
      << lbfgsTerminationName(r.reason);
  EXPECT_LE((x - Eigen::VectorXd::Ones(10)).cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_LT(r.iterations, 200);
}

TEST(Lbfgs, MinimizesAnIllConditionedQuadraticInFewIterations) {
  const int n = 50;
  Eigen::VectorXd diag = Eigen::VectorXd::LinSpaced(n, 1.0, 1e4);
  auto quadratic = [&diag](const Eigen::VectorXd& x, Eigen::VectorXd& g) {
    g = diag.cwiseProduct(x - Eigen::VectorXd::Ones(x.size()));
    return 0.5 * (x - Eigen::VectorXd::Ones(x.size())).dot(g);
  };
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  const LbfgsResult r = minimizeLbfgs(quadratic, x);
  EXPECT_LE((x - Eigen::VectorXd::Ones(n)).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT(r.iterations, 400);
}

TEST(Lbfgs, CallbackCanStopTheSolve) {
  Eigen::VectorXd x = Eigen::VectorXd::Constant(4, -1.2);
  int calls = 0;
  const LbfgsResult r = minimizeLbfgs(rosenbrock, x, {}, [&calls](int, double, double) {
    return ++calls < 3;
  });
  EXPECT_EQ(r.reason, LbfgsTermination::Aborted);
  EXPECT_EQ(r.iterations, 3);
}

}  // namespace
}  // namespace devsurf::models::quasi_strip
