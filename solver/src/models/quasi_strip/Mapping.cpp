#include "devsurf/models/quasi_strip/Mapping.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace devsurf::models::quasi_strip {

spline::BSplineCurve Mapping::curve() const {
  spline::BSplineCurve c;
  c.knots = spline::KnotVector::clamped(degree, knots, static_cast<int>(coefficients.size()));
  c.points = coefficients;
  return c;
}

double Mapping::evaluate(double t, int derivative) const {
  const spline::BasisValues b = spline::basisFunctions(
      spline::KnotVector::clamped(degree, knots, static_cast<int>(coefficients.size())), t,
      derivative);
  double value = 0.0;
  for (int j = 0; j <= degree; ++j) value += b.values(derivative, j) * coefficients[b.controlIndex[j]];
  return value;
}

double Mapping::inverse(double T) const {
  const spline::BSplineCurve c = curve();
  double lo = domainBegin(), hi = domainEnd();
  if (c.evaluate(lo)[0] >= T) return lo;
  if (c.evaluate(hi)[0] < T) return hi;
  const double tol = 1e-15 * (hi - lo);
  while (hi - lo > tol) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (c.evaluate(mid)[0] >= T ? hi : lo) = mid;
  }
  return hi;
}

Eigen::VectorXd mappingCoefficients(const Eigen::VectorXd& shape) {
  Eigen::VectorXd beta(shape.size());
  double sum = 0.0;
  for (Eigen::Index i = 0; i < shape.size(); ++i) {
    sum += shape[i] * shape[i];
    beta[i] = sum;
  }
  return beta;
}

Eigen::VectorXd shapeParameters(const Eigen::VectorXd& coefficients) {
  Eigen::VectorXd eps(coefficients.size());
  double previous = 0.0;
  for (Eigen::Index i = 0; i < coefficients.size(); ++i) {
    eps[i] = std::sqrt(std::max(0.0, coefficients[i] - previous));
    previous = coefficients[i];
  }
  return eps;
}

Eigen::VectorXd identityCoefficients(const spline::KnotVector& knots) {
  const int n = knots.numControlPoints(), p = knots.degree();
  Eigen::VectorXd g(n);
  for (int i = 0; i < n; ++i) {
    double s = 0.0;
    for (int j = 1; j <= p; ++j) s += knots.knots()[i + j];
    g[i] = s / p;
  }
  return g;
}

spline::EvaluationMatrix tailSumMatrix(const spline::KnotVector& knots,
                                       const std::vector<double>& params) {
  const int n = knots.numControlPoints();
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < static_cast<int>(params.size()); ++i) {
    const spline::BasisValues b = spline::basisFunctions(knots, params[i], 0);
    const int first = b.controlIndex.front(), last = b.controlIndex.back();
    assert(last < n);
    // k < first: the whole partition of unity; first ≤ k ≤ last: partial tails.
    for (int k = 0; k < first; ++k) entries.emplace_back(i, k, 1.0);
    double tail = 0.0;
    std::vector<double> tails(static_cast<size_t>(last - first + 1));
    for (int j = knots.degree(); j >= 0; --j) {
      tail += b.values(0, j);
      tails[static_cast<size_t>(j)] = tail;
    }
    for (int k = first; k <= last; ++k) entries.emplace_back(i, k, tails[static_cast<size_t>(k - first)]);
  }
  spline::EvaluationMatrix s(static_cast<Eigen::Index>(params.size()), n);
  s.setFromTriplets(entries.begin(), entries.end());
  s.makeCompressed();
  return s;
}

}  // namespace devsurf::models::quasi_strip
