#pragma once

#include <vector>

#include <Eigen/Core>

#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::models::conical_strip {

/// A space curve with an arc-length table: equal-arc-length sampling (Chu et al. §3.3 Step 1),
/// plane intersections (Step 3) and closest points (deviation metrics).
///
/// The table holds `intervalsPerSpan` equal parameter intervals per knot span, each integrated with
/// 5-point Gauss–Legendre; parameterAt() refines by Newton steps on the integral, so arc lengths
/// are exact to about 1e-12 of the length for smooth curves.
class ArcLengthCurve {
 public:
  /// @param[in] curve  a clamped 3D B-spline (NURBS allowed) of positive length
  /// @param[in] intervalsPerSpan  ≥ 1
  /// @throws std::invalid_argument naming `curve` or `intervalsPerSpan` if they do not qualify.
  ArcLengthCurve(spline::BSplineCurve curve, int intervalsPerSpan);

  const spline::BSplineCurve& curve() const { return curve_; }
  double length() const { return cumulative_.back(); }
  double domainBegin() const { return nodes_.front(); }
  double domainEnd() const { return nodes_.back(); }

  Eigen::Vector3d point(double u) const;
  Eigen::Vector3d derivative(double u, int order = 1) const;
  /// Unit tangent (zero where the derivative vanishes).
  Eigen::Vector3d unitTangent(double u) const;

  /// Arc length from the start of the curve to parameter u.
  double arcLength(double u) const;
  /// Parameter u with arcLength(u) = s (s clamped into [0, length]).
  double parameterAt(double s) const;
  /// parameterAt(s) interpolated linearly in the arc-length table (no Newton solve): exact at the
  /// table's nodes, within the speed's variation over one table interval between them.
  double tableParameterAt(double s) const;
  /// `count` ≥ 2 parameters at equal arc-length spacing, both ends included.
  std::vector<double> equalArcLengthParameters(int count) const;

  /// Parameters u in [uBegin, uEnd] where the curve crosses the plane n·(x − x0) = 0, found by
  /// scanning `scanSteps` nearly equal arc-length steps for sign changes (tableParameterAt: an
  /// exact arc-length step costs a Newton solve of Gauss integrals) and refining each bracket to
  /// machine precision (Illinois regula falsi). Empty when the curve does not cross.
  std::vector<double> planeCrossings(const Eigen::Vector3d& x0, const Eigen::Vector3d& normal,
                                     double uBegin, double uEnd, int scanSteps) const;

  struct ClosestPoint {
    double parameter = 0.0;
    double distance = 0.0;
  };
  /// Closest curve point to x with parameter in [uBegin, uEnd] (coarse search on the table nodes,
  /// then safeguarded Newton in the intervals next to the best node).
  ClosestPoint closestPoint(const Eigen::Vector3d& x, double uBegin, double uEnd) const;

 private:
  double speed(double u) const { return derivative(u).norm(); }
  double integrate(double u0, double u1) const;
  int intervalIndex(double u) const;
  /// The table interval k with cumulative_[k] ≤ s < cumulative_[k+1] (clamped to the table).
  int lengthIntervalIndex(double s) const;

  spline::BSplineCurve curve_;
  std::vector<double> nodes_;       ///< table parameters, strictly increasing
  std::vector<double> cumulative_;  ///< arc length at each node
};

}  // namespace devsurf::models::conical_strip
