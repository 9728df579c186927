#include "devsurf/models/conical_strip/ArcLengthCurve.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <stdexcept>
#include <string>

namespace devsurf::models::conical_strip {

namespace {

// 5-point Gauss–Legendre nodes and weights on [-1, 1].
constexpr double kGaussNodes[5] = {-0.9061798459386640, -0.5384693101056831, 0.0,
                                   0.5384693101056831, 0.9061798459386640};
constexpr double kGaussWeights[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                     0.4786286704993665, 0.2369268850561891};

}  // namespace

ArcLengthCurve::ArcLengthCurve(spline::BSplineCurve curve, int intervalsPerSpan)
    : curve_(std::move(curve)) {
  curve_.validate();
  if (curve_.dimension() != 3) {
    throw std::invalid_argument("curve: expected 3D control points, got " +
                                std::to_string(curve_.dimension()) + " columns");
  }
  if (curve_.knots.kind() != spline::KnotKind::Clamped) {
    throw std::invalid_argument("curve: only clamped (open) curves are supported");
  }
  if (intervalsPerSpan < 1) {
    throw std::invalid_argument("intervalsPerSpan: must be >= 1, got " +
                                std::to_string(intervalsPerSpan));
  }
  const std::vector<double> breaks = curve_.knots.breakpoints();
  nodes_.push_back(breaks.front());
  for (size_t k = 0; k + 1 < breaks.size(); ++k) {
    for (int j = 1; j <= intervalsPerSpan; ++j) {
      nodes_.push_back(breaks[k] + (breaks[k + 1] - breaks[k]) * j / intervalsPerSpan);
    }
  }
  cumulative_.assign(nodes_.size(), 0.0);
  for (size_t k = 1; k < nodes_.size(); ++k) {
    cumulative_[k] = cumulative_[k - 1] + integrate(nodes_[k - 1], nodes_[k]);
  }
  if (!(length() > 0.0) || !std::isfinite(length())) {
    throw std::invalid_argument("curve: must have positive finite length");
  }
}

// Through derivatives() into stack storage: evaluate() allocates its result, and the greedy march,
// the plane crossings and the closest points call these some 10⁵ times a strip.
Eigen::Vector3d ArcLengthCurve::point(double u) const {
  Eigen::Matrix<double, 3, 1> out;
  curve_.derivatives(u, 0, out);
  return out;
}

Eigen::Vector3d ArcLengthCurve::derivative(double u, int order) const {
  if (order > 3) return curve_.evaluate(u, order);
  Eigen::Matrix<double, 3, 4> out;
  curve_.derivatives(u, order, out.leftCols(order + 1));
  return out.col(order);
}

Eigen::Vector3d ArcLengthCurve::unitTangent(double u) const {
  const Eigen::Vector3d d = derivative(u);
  const double n = d.norm();
  return n > 0.0 ? Eigen::Vector3d(d / n) : Eigen::Vector3d::Zero();
}

double ArcLengthCurve::integrate(double u0, double u1) const {
  const double half = 0.5 * (u1 - u0), mid = 0.5 * (u0 + u1);
  double sum = 0.0;
  for (int g = 0; g < 5; ++g) sum += kGaussWeights[g] * speed(mid + half * kGaussNodes[g]);
  return sum * half;
}

int ArcLengthCurve::intervalIndex(double u) const {
  const auto it = std::upper_bound(nodes_.begin(), nodes_.end(), u);
  const int k = static_cast<int>(it - nodes_.begin()) - 1;
  return std::clamp(k, 0, static_cast<int>(nodes_.size()) - 2);
}

double ArcLengthCurve::arcLength(double u) const {
  u = std::clamp(u, domainBegin(), domainEnd());
  const int k = intervalIndex(u);
  return cumulative_[k] + integrate(nodes_[k], u);
}

double ArcLengthCurve::parameterAt(double s) const {
  s = std::clamp(s, 0.0, length());
  if (s <= 0.0) return domainBegin();
  if (s >= length()) return domainEnd();
  const int k = lengthIntervalIndex(s);
  double lo = nodes_[k], hi = nodes_[k + 1];
  // Initial guess by linear interpolation in the table, then safeguarded Newton.
  double u = tableParameterAt(s);
  for (int iter = 0; iter < 50; ++iter) {
    const double f = cumulative_[k] + integrate(nodes_[k], u) - s;
    if (f > 0.0) hi = u; else lo = u;
    const double v = speed(u);
    double next = v > 0.0 ? u - f / v : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - u) <= 1e-15 * (1.0 + std::abs(u))) return next;
    u = next;
  }
  return u;
}

int ArcLengthCurve::lengthIntervalIndex(double s) const {
  const auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), s);
  return std::clamp(static_cast<int>(it - cumulative_.begin()) - 1, 0,
                    static_cast<int>(nodes_.size()) - 2);
}

double ArcLengthCurve::tableParameterAt(double s) const {
  s = std::clamp(s, 0.0, length());
  const int k = lengthIntervalIndex(s);
  const double ds = cumulative_[k + 1] - cumulative_[k];
  return ds > 0.0 ? nodes_[k] + (nodes_[k + 1] - nodes_[k]) * (s - cumulative_[k]) / ds : nodes_[k];
}

std::vector<double> ArcLengthCurve::equalArcLengthParameters(int count) const {
  if (count < 2) throw std::invalid_argument("count: need at least 2 samples");
  std::vector<double> params(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) params[i] = parameterAt(length() * i / (count - 1));
  params.front() = domainBegin();
  params.back() = domainEnd();
  return params;
}

std::vector<double> ArcLengthCurve::planeCrossings(const Eigen::Vector3d& x0,
                                                   const Eigen::Vector3d& normal, double uBegin,
                                                   double uEnd, int scanSteps) const {
  std::vector<double> roots;
  if (!(uEnd > uBegin) || scanSteps < 1) return roots;
  const auto signedDistance = [this, &x0, &normal](double u) {
    return normal.dot(point(u) - x0);
  };
  const double s0 = arcLength(uBegin), s1 = arcLength(uEnd);
  double uPrev = uBegin, gPrev = signedDistance(uBegin);
  for (int k = 1; k <= scanSteps; ++k) {
    const double u = k == scanSteps ? uEnd : tableParameterAt(s0 + (s1 - s0) * k / scanSteps);
    const double g = signedDistance(u);
    if (gPrev == 0.0) {
      roots.push_back(uPrev);
    } else if (g != 0.0 && (g > 0.0) != (gPrev > 0.0)) {
      // Illinois regula falsi on [uPrev, u].
      double a = uPrev, b = u, ga = gPrev, gb = g;
      int side = 0;
      double c = a;
      for (int iter = 0; iter < 100; ++iter) {
        c = (a * gb - b * ga) / (gb - ga);
        const double gc = signedDistance(c);
        if (gc == 0.0 || std::abs(b - a) <= 1e-15 * (1.0 + std::abs(c))) break;
        if ((gc > 0.0) == (gb > 0.0)) {
          b = c;
          gb = gc;
          if (side == -1) ga *= 0.5;
          side = -1;
        } else {
          a = c;
          ga = gc;
          if (side == +1) gb *= 0.5;
          side = +1;
        }
      }
      roots.push_back(c);
    }
    uPrev = u;
    gPrev = g;
  }
  if (gPrev == 0.0) roots.push_back(uPrev);
  return roots;
}

ArcLengthCurve::ClosestPoint ArcLengthCurve::closestPoint(const Eigen::Vector3d& x, double uBegin,
                                                          double uEnd) const {
  uBegin = std::clamp(uBegin, domainBegin(), domainEnd());
  uEnd = std::clamp(uEnd, uBegin, domainEnd());
  const auto distance = [this, &x](double u) { return (point(u) - x).norm(); };
  // Coarse: the table nodes inside the range plus the range ends.
  std::vector<double> candidates{uBegin};
  for (double u : nodes_) {
    if (u > uBegin && u < uEnd) candidates.push_back(u);
  }
  candidates.push_back(uEnd);
  size_t best = 0;
  double bestDistance = distance(candidates[0]);
  for (size_t k = 1; k < candidates.size(); ++k) {
    const double d = distance(candidates[k]);
    if (d < bestDistance) {
      bestDistance = d;
      best = k;
    }
  }
  // Safeguarded Newton on g(u) = (C(u) − x)·C′(u), the derivative of half the squared distance,
  // in the neighbouring intervals: bisection on the sign of g where a step leaves the bracket or
  // g′ ≤ 0. A minimum at a bracket end converges to that end.
  double lo = candidates[best > 0 ? best - 1 : 0];
  double hi = candidates[std::min(best + 1, candidates.size() - 1)];
  double u = candidates[best];
  Eigen::Matrix<double, 3, 3> d;  // point, first and second derivative
  for (int iter = 0; iter < 60 && hi - lo > 1e-15 * (1.0 + std::abs(hi)); ++iter) {
    curve_.derivatives(u, 2, d);
    const Eigen::Vector3d r = d.col(0) - x;
    const double g = r.dot(d.col(1)), gPrime = d.col(1).squaredNorm() + r.dot(d.col(2));
    if (g == 0.0) {
      if (gPrime > 0.0) break;  // a minimum
      // Stationary but no minimum (a point of zero speed, or a maximum): keep the nearer half.
      if (distance(0.5 * (lo + u)) < distance(0.5 * (u + hi))) hi = u; else lo = u;
      u = 0.5 * (lo + hi);
      continue;
    }
    if (g < 0.0) lo = u; else hi = u;
    double next = gPrime > 0.0 ? u - g / gPrime : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const bool converged = std::abs(next - u) <= 1e-15 * (1.0 + std::abs(u));
    u = next;
    if (converged) break;
  }
  ClosestPoint result{u, distance(u)};
  if (bestDistance < result.distance) result = {candidates[best], bestDistance};
  return result;
}

}  // namespace devsurf::models::conical_strip
