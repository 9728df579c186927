#include "devsurf/models/quasi_strip/Lbfgs.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>

namespace devsurf::models::quasi_strip {

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

/// Minimizer of the cubic through (a, fa, da), (b, fb, db), safeguarded into the middle 80% of
/// [a, b]; bisection when the cubic has no minimizer there.
double cubicStep(double a, double fa, double da, double b, double fb, double db) {
  const double lo = std::min(a, b), hi = std::max(a, b), width = hi - lo;
  const double d1 = da + db - 3.0 * (fa - fb) / (a - b);
  const double disc = d1 * d1 - da * db;
  double t = 0.5 * (a + b);
  if (disc >= 0.0 && std::isfinite(disc)) {
    const double d2 = std::copysign(std::sqrt(disc), b - a);
    const double denom = db - da + 2.0 * d2;
    if (denom != 0.0) {
      const double c = b - (b - a) * (db + d2 - d1) / denom;
      if (std::isfinite(c)) t = c;
    }
  }
  return std::clamp(t, lo + 0.1 * width, hi - 0.1 * width);
}

struct LinePoint {
  double alpha = 0.0, value = 0.0, slope = 0.0;
};

}  // namespace

LbfgsResult minimizeLbfgs(const ObjectiveWithGradient& objective, Eigen::VectorXd& x,
                          const LbfgsOptions& options, const LbfgsCallback& callback) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const Eigen::Index n = x.size();
  LbfgsResult result;
  Eigen::VectorXd g(n), trialG(n), trialX(n), direction(n);
  double f = objective(x, g);
  ++result.evaluations;
  std::deque<Eigen::VectorXd> sList, yList;
  std::deque<double> rhoList;
  std::vector<double> alphaBuffer(static_cast<size_t>(options.memory));
  int smallDecreases = 0;

  auto finish = [&result, &f, &g](LbfgsTermination reason) {
    result.reason = reason;
    result.value = f;
    result.gradientNorm = g.size() ? g.cwiseAbs().maxCoeff() : 0.0;
    return result;
  };

  for (int k = 0;; ++k) {
    const double gNorm = n ? g.cwiseAbs().maxCoeff() : 0.0;
    if (f <= options.absoluteTolerance) return finish(LbfgsTermination::AbsoluteTolerance);
    if (gNorm <= options.gradientTolerance) return finish(LbfgsTermination::GradientTolerance);
    if (k >= options.maxIterations) return finish(LbfgsTermination::MaxIterations);
    if (options.timeBudgetMs > 0.0 &&
        std::chrono::duration<double, std::milli>(Clock::now() - start).count() > options.timeBudgetMs)
      return finish(LbfgsTermination::TimeBudget);

    // Two-loop recursion: direction = −H_k g.
    direction = -g;
    const int m = static_cast<int>(sList.size());
    for (int i = m - 1; i >= 0; --i) {
      alphaBuffer[i] = rhoList[i] * sList[i].dot(direction);
      direction -= alphaBuffer[i] * yList[i];
    }
    if (m > 0) direction *= sList.back().dot(yList.back()) / yList.back().squaredNorm();
    for (int i = 0; i < m; ++i) {
      const double beta = rhoList[i] * yList[i].dot(direction);
      direction += (alphaBuffer[i] - beta) * sList[i];
    }
    double slope0 = g.dot(direction);
    if (!(slope0 < 0.0)) {  // not a descent direction: restart with steepest descent
      sList.clear(), yList.clear(), rhoList.clear();
      direction = -g;
      slope0 = -g.squaredNorm();
    }

    // Strong Wolfe line search.
    const LinePoint origin{0.0, f, slope0};
    double lastValue = f;  // value at trialX
    auto probe = [&objective, &x, &direction, &trialX, &trialG, &result, &lastValue](double alpha) {
      trialX = x + alpha * direction;
      const double value = objective(trialX, trialG);
      lastValue = value;
      ++result.evaluations;
      return LinePoint{alpha, std::isfinite(value) ? value : std::numeric_limits<double>::infinity(),
                       trialG.dot(direction)};
    };
    const double c1 = options.wolfeDecrease, c2 = options.wolfeCurvature;
    auto armijo = [&origin, c1](const LinePoint& p) {
      return p.value <= origin.value + c1 * p.alpha * origin.slope;
    };
    auto curvature = [&origin, c2](const LinePoint& p) {
      return std::abs(p.slope) <= -c2 * origin.slope;
    };
    double alpha = m == 0 ? std::min(1.0, 1.0 / std::sqrt(-slope0)) : 1.0;
    LinePoint previous = origin;
    bool accepted = false;
    LinePoint lo, hi;
    bool zoom = false;
    int evaluations = 0;
    for (; evaluations < options.maxLineSearchEvaluations; ++evaluations) {
      const LinePoint p = probe(alpha);
      if (!armijo(p) || (evaluations > 0 && p.value >= previous.value)) {
        lo = previous, hi = p, zoom = true;
        break;
      }
      if (curvature(p)) {
        accepted = true;
        break;
      }
      if (p.slope >= 0.0) {
        lo = p, hi = previous, zoom = true;
        break;
      }
      previous = p;
      alpha *= 2.0;
    }
    if (zoom) {
      // Invariant: lo satisfies Armijo with the lowest value so far; the minimizer lies between.
      for (++evaluations; evaluations < options.maxLineSearchEvaluations; ++evaluations) {
        const double a = cubicStep(lo.alpha, lo.value, lo.slope, hi.alpha,
                                   std::isfinite(hi.value) ? hi.value : lo.value + 1e300, hi.slope);
        if (!(std::abs(hi.alpha - lo.alpha) > 1e-16 * std::max(1.0, std::abs(lo.alpha)))) break;
        const LinePoint p = probe(a);
        if (!armijo(p) || p.value >= lo.value) {
          hi = p;
        } else {
          if (curvature(p)) {
            accepted = true;
            break;
          }
          if (p.slope * (hi.alpha - lo.alpha) >= 0.0) hi = lo;
          lo = p;
        }
      }
      if (!accepted && lo.alpha > 0.0) {
        // Fall back to the best Armijo point of the bracket.
        const LinePoint p = probe(lo.alpha);
        accepted = armijo(p);
      }
    }
    if (!accepted) return finish(LbfgsTermination::LineSearchFailed);

    // trialX/trialG hold the accepted point.
    Eigen::VectorXd s = trialX - x;
    Eigen::VectorXd y = trialG - g;
    const double previousF = f;
    x = trialX;
    g = trialG;
    f = lastValue;
    result.iterations = k + 1;
    const double sy = s.dot(y);
    if (sy > 1e-16 * s.norm() * y.norm()) {
      if (static_cast<int>(sList.size()) == options.memory) {
        sList.pop_front(), yList.pop_front(), rhoList.pop_front();
      }
      sList.push_back(std::move(s));
      yList.push_back(std::move(y));
      rhoList.push_back(1.0 / sy);
    }
    if (callback && !callback(k + 1, f, g.cwiseAbs().maxCoeff())) {
      return finish(LbfgsTermination::Aborted);
    }
    if (previousF - f <= options.relativeDecreaseTolerance * std::max(std::abs(f), 1e-300)) {
      if (++smallDecreases >= 5) return finish(LbfgsTermination::RelativeDecrease);
    } else {
      smallDecreases = 0;
    }
  }
}

}  // namespace devsurf::models::quasi_strip
