#pragma once

#include <vector>

#include <Eigen/Core>

#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::terms {

/// Point and first two derivatives of an extended curve at one parameter.
struct CurveJet {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d d1 = Eigen::Vector3d::Zero();  ///< first derivative
  Eigen::Vector3d d2 = Eigen::Vector3d::Zero();  ///< second derivative
};

/// A clamped, polynomial B-spline curve in 3D that can be evaluated at any parameter: inside the
/// domain it is the curve, before the first / after the last knot span it continues that span's
/// polynomial (the natural extension of a B-spline by "unclamping", 001_… §3.4 and its ref. [32]).
/// The mapping σ of Bo et al. may leave the domain of C2 while it is optimized; this keeps the
/// developability rows smooth there.
/// \note Each span's Bézier piece is converted once to the power basis in its local parameter;
///       evaluation is Horner's scheme for the point and both derivatives together (O(degree),
///       extrapolating outside the span for the extension); nothing allocates. The conversion
///       costs a few digits for high degrees (relative 1e-12 at degree 15), far below what the
///       developability rows resolve.
class ExtendedCurve {
 public:
  ExtendedCurve() = default;
  /// @param[in] curve  clamped, non-rational, 3 columns
  /// @throws std::invalid_argument naming the rule broken
  explicit ExtendedCurve(const spline::BSplineCurve& curve);

  CurveJet evaluate(double u) const;
  double domainBegin() const { return breaks_.front(); }
  double domainEnd() const { return breaks_.back(); }
  int degree() const { return degree_; }

 private:
  int degree_ = 0;
  std::vector<double> breaks_;  ///< piece j covers [breaks_[j], breaks_[j+1]]
  /// Per piece: power-basis coefficients in s = (u − begin)/(end − begin), and 1/(end − begin).
  std::vector<std::vector<Eigen::Vector3d>> coefficients_;
  std::vector<double> inverseLengths_;
};

}  // namespace devsurf::terms
