#pragma once

#include <vector>

#include <Eigen/Core>

#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/KnotVector.h"

namespace devsurf::spline {

/// The non-vanishing basis functions of one knot vector at fixed parameters, with derivatives,
/// evaluated once (per topology) for loops that sample curves on those knots every iterate: the
/// dense warp metric's 1 000 rulings per face of a composite, say. Evaluating a curve at a
/// tabled parameter is then p+1 multiply-adds per derivative and coordinate — no span search, no
/// basis recursion.
class BasisTable {
 public:
  BasisTable() = default;
  /// @param[in] knots        the knot vector every curve evaluated with this table has
  /// @param[in] params       parameters (clamped into the domain, as basisFunctions does)
  /// @param[in] derivatives  highest derivative tabled (≥ 0)
  /// @throws std::invalid_argument for an unusable knot vector or derivatives < 0
  BasisTable(const KnotVector& knots, std::vector<double> params, int derivatives);

  int size() const { return static_cast<int>(params_.size()); }
  double param(int k) const { return params_[static_cast<std::size_t>(k)]; }
  int derivatives() const { return derivatives_; }
  /// Whether `curve` is a polynomial curve on this table's knot vector (what evaluate() needs).
  bool fits(const BSplineCurve& curve) const;
  /// Column l of `out` = the l-th derivative of the curve with control points `points` (n×dim,
  /// n = the knot vector's control points) at param(k), l ≤ upTo ≤ derivatives().
  /// @param[out] out  dim×(upTo+1), sized by the caller
  void evaluate(int k, const Eigen::MatrixXd& points, int upTo, Eigen::Ref<Eigen::MatrixXd> out) const;

 private:
  KnotVector knots_;
  std::vector<double> params_;
  int degree_ = 0;
  int derivatives_ = 0;
  std::vector<int> control_;   ///< (p+1) control point indices per parameter
  std::vector<double> values_; ///< (derivatives+1)×(p+1) per parameter, derivative-major
};

}  // namespace devsurf::spline
