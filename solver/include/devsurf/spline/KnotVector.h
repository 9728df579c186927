#pragma once

#include <string>
#include <vector>

namespace devsurf::spline {

/// How a knot vector was made; decides how control points wrap.
enum class KnotKind {
  Clamped,   ///< first and last knot repeated degree+1 times (open curve)
  Periodic,  ///< uniform, unclamped; control points wrap around (closed curve, C^{degree-1} at the seam)
};

/// A B-spline knot vector t_0 ≤ … ≤ t_{n+p} for n control points of degree p.
///
/// For a periodic knot vector the curve has `numControlPoints()` *distinct* control points;
/// internally the knot vector is the unwrapped one with n+p control-point slots, slot i using
/// control point i mod n. Every function that returns per-control-point data (basis index,
/// evaluation matrices) already reports the wrapped index in [0, numControlPoints()).
/// \note The parameter domain is [t_p, t_n] (unwrapped n). Clamped uniform knot vectors and
///       periodic ones built here use the domain [0, 1].
class KnotVector {
 public:
  KnotVector() = default;

  /// Clamped uniform knots on [0,1]: the default when a scene gives no knots.
  /// @throws std::invalid_argument if degree < 1 or numControlPoints < degree+1.
  static KnotVector clampedUniform(int degree, int numControlPoints);

  /// Arbitrary clamped knots (full vector, length numControlPoints + degree + 1).
  /// @throws std::invalid_argument naming the rule broken: wrong length, decreasing knots,
  ///         non-finite knots, ends not repeated degree+1 times, interior multiplicity > degree,
  ///         empty domain.
  static KnotVector clamped(int degree, std::vector<double> knots, int numControlPoints);

  /// Closed curve with numControlPoints distinct control points, uniform knots, domain [0,1].
  /// @throws std::invalid_argument if numControlPoints < degree + 1.
  static KnotVector periodicUniform(int degree, int numControlPoints);

  int degree() const { return degree_; }
  KnotKind kind() const { return kind_; }
  /// Distinct control points (wrapped count for periodic knot vectors).
  int numControlPoints() const { return numControlPoints_; }
  /// Number of basis-function slots in the (unwrapped) knot vector: n for clamped, n+p for periodic.
  int numSlots() const { return static_cast<int>(knots_.size()) - degree_ - 1; }
  /// The full (unwrapped) knot vector.
  const std::vector<double>& knots() const { return knots_; }
  double domainBegin() const { return knots_[degree_]; }
  double domainEnd() const { return knots_[numSlots()]; }

  /// Distinct knot values in the domain, begin and end included (spans + 1 values).
  std::vector<double> breakpoints() const;
  /// Non-empty knot spans in the domain.
  int numSpans() const;
  /// Slot index s with t_s ≤ u < t_{s+1} (u clamped into the domain; the last span for u = end).
  int spanIndex(double u) const;
  /// Control point index used by slot `slot` (slot mod n for periodic, slot otherwise).
  int controlIndex(int slot) const { return kind_ == KnotKind::Periodic ? slot % numControlPoints_ : slot; }
  /// Multiplicity of knot value u in the vector (0 if absent), with tolerance 1e-14·(domain length).
  int multiplicity(double u) const;

  /// Parameters dividing every span into `perSpan` equal parts: for each span [u_i, u_{i+1}] the
  /// points u_i + (j + 1/2)/perSpan · (u_{i+1} − u_i), j = 0..perSpan−1 (interior, never on a knot).
  std::vector<double> spanSamples(int perSpan) const;
  /// `count` parameters equally spaced over the whole domain, both ends included (count ≥ 2).
  std::vector<double> uniformSamples(int count) const;

 private:
  KnotVector(int degree, int numControlPoints, KnotKind kind, std::vector<double> knots)
      : degree_(degree), numControlPoints_(numControlPoints), kind_(kind), knots_(std::move(knots)) {}

  int degree_ = 0;
  int numControlPoints_ = 0;
  KnotKind kind_ = KnotKind::Clamped;
  std::vector<double> knots_;
};

}  // namespace devsurf::spline
