#include "devsurf/spline/KnotVector.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace devsurf::spline {

namespace {

[[noreturn]] void failKnots(const std::string& message) { throw std::invalid_argument(message); }

void requireDegreeAndCount(int degree, int numControlPoints) {
  if (degree < 1) {
    failKnots("degree: must be at least 1, got " + std::to_string(degree));
  }
  if (numControlPoints < degree + 1) {
    failKnots("control points: need at least degree+1 = " + std::to_string(degree + 1) + ", got " +
         std::to_string(numControlPoints));
  }
}

std::string formatValue(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

}  // namespace

KnotVector KnotVector::clampedUniform(int degree, int numControlPoints) {
  requireDegreeAndCount(degree, numControlPoints);
  const int p = degree;
  const int n = numControlPoints;
  const int spans = n - p;
  std::vector<double> knots(static_cast<size_t>(n + p + 1));
  for (int i = 0; i <= p; ++i) {
    knots[i] = 0.0;
    knots[n + i] = 1.0;
  }
  for (int i = 1; i < spans; ++i) {
    knots[p + i] = static_cast<double>(i) / spans;
  }
  return KnotVector(p, n, KnotKind::Clamped, std::move(knots));
}

KnotVector KnotVector::clamped(int degree, std::vector<double> knots, int numControlPoints) {
  requireDegreeAndCount(degree, numControlPoints);
  const int p = degree;
  const int n = numControlPoints;
  const int expected = n + p + 1;
  const int count = static_cast<int>(knots.size());
  if (count != expected) {
    failKnots("knots: expected " + std::to_string(expected) +
         " values (control points + degree + 1), got " + std::to_string(count));
  }
  for (int i = 0; i < count; ++i) {
    if (!std::isfinite(knots[i])) {
      failKnots("knots: must be finite (knots[" + std::to_string(i) + "] = " + formatValue(knots[i]) +
           ")");
    }
  }
  for (int i = 1; i < count; ++i) {
    if (knots[i] < knots[i - 1]) {
      failKnots("knots: must be non-decreasing (knots[" + std::to_string(i) + "] < knots[" +
           std::to_string(i - 1) + "])");
    }
  }
  if (!(knots.front() < knots.back())) {
    failKnots("knots: domain must be non-empty (first knot equals last knot, " +
         formatValue(knots.front()) + ")");
  }
  // Multiplicities of the end values: both must be exactly p+1 (a larger one would create a
  // basis function that vanishes identically).
  int first = 1;
  while (first < count && knots[first] == knots[0]) ++first;
  int last = 1;
  while (last < count && knots[count - 1 - last] == knots[count - 1]) ++last;
  if (first != p + 1 || last != p + 1) {
    failKnots("knots: clamped ends need multiplicity degree+1 = " + std::to_string(p + 1) +
         " (first knot repeated " + std::to_string(first) + " times, last knot repeated " +
         std::to_string(last) + " times)");
  }
  for (int i = p + 1; i < n;) {
    int j = i + 1;
    while (j < n && knots[j] == knots[i]) ++j;
    if (j - i > p) {
      failKnots("knots: interior multiplicity must not exceed degree " + std::to_string(p) + " (knot " +
           formatValue(knots[i]) + " repeated " + std::to_string(j - i) + " times)");
    }
    i = j;
  }
  return KnotVector(p, n, KnotKind::Clamped, std::move(knots));
}

KnotVector KnotVector::periodicUniform(int degree, int numControlPoints) {
  requireDegreeAndCount(degree, numControlPoints);
  const int p = degree;
  const int n = numControlPoints;
  // n+p slots → n+2p+1 knots, t_i = (i − p)/n, so that t_p = 0 and t_{n+p} = 1.
  std::vector<double> knots(static_cast<size_t>(n + 2 * p + 1));
  for (int i = 0; i < static_cast<int>(knots.size()); ++i) {
    knots[i] = static_cast<double>(i - p) / n;
  }
  knots[p] = 0.0;
  knots[n + p] = 1.0;
  return KnotVector(p, n, KnotKind::Periodic, std::move(knots));
}

namespace {
void requireInitialised(const std::vector<double>& knots) {
  if (knots.empty()) failKnots("knot vector: empty (default-constructed; use a factory function)");
}
}  // namespace

std::vector<double> KnotVector::breakpoints() const {
  requireInitialised(knots_);
  std::vector<double> result;
  const int end = numSlots();
  for (int i = degree_; i <= end; ++i) {
    if (result.empty() || knots_[i] != result.back()) result.push_back(knots_[i]);
  }
  return result;
}

int KnotVector::numSpans() const { return static_cast<int>(breakpoints().size()) - 1; }

int KnotVector::spanIndex(double u) const {
  requireInitialised(knots_);
  if (std::isnan(u)) failKnots("spanIndex: parameter u must not be NaN");
  const int end = numSlots();
  if (u >= knots_[end]) {
    int s = end - 1;
    while (s > degree_ && knots_[s] == knots_[end]) --s;
    assert(knots_[s] < knots_[s + 1] && "the domain has a non-empty last span");
    return s;
  }
  if (u <= knots_[degree_]) {
    int s = degree_;
    while (knots_[s + 1] == knots_[s]) ++s;
    return s;
  }
  // First knot in [t_p, t_end] strictly greater than u; the span starts one before it.
  const auto first = knots_.begin() + degree_;
  const auto last = knots_.begin() + end + 1;
  const int s = static_cast<int>(std::upper_bound(first, last, u) - knots_.begin()) - 1;
  assert(s >= degree_ && s < end && knots_[s] <= u && u < knots_[s + 1] && "span search");
  return s;
}

int KnotVector::multiplicity(double u) const {
  if (knots_.empty()) return 0;
  const double tol = 1e-14 * (domainEnd() - domainBegin());
  int count = 0;
  for (double k : knots_) {
    if (std::abs(k - u) <= tol) ++count;
  }
  return count;
}

std::vector<double> KnotVector::spanSamples(int perSpan) const {
  if (perSpan < 1) failKnots("spanSamples: perSpan must be at least 1, got " + std::to_string(perSpan));
  const std::vector<double> bp = breakpoints();
  std::vector<double> result;
  result.reserve((bp.size() - 1) * static_cast<size_t>(perSpan));
  for (size_t i = 0; i + 1 < bp.size(); ++i) {
    const double a = bp[i];
    const double h = bp[i + 1] - bp[i];
    for (int j = 0; j < perSpan; ++j) {
      result.push_back(a + (j + 0.5) / perSpan * h);
    }
  }
  return result;
}

std::vector<double> KnotVector::uniformSamples(int count) const {
  requireInitialised(knots_);
  if (count < 2) failKnots("uniformSamples: count must be at least 2, got " + std::to_string(count));
  const double a = domainBegin();
  const double b = domainEnd();
  std::vector<double> result(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    result[i] = a + (b - a) * static_cast<double>(i) / (count - 1);
  }
  result.back() = b;
  return result;
}

}  // namespace devsurf::spline
