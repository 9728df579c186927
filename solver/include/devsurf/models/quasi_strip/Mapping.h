#pragma once

#include <vector>

#include <Eigen/Core>

#include "devsurf/spline/Basis.h"
#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/KnotVector.h"

namespace devsurf::models::quasi_strip {

/// A parametrization mapping T = σ(t) = Σ_i coefficients_i B_{i,degree}(t) (001_… eq. 3) on a
/// clamped knot vector: t is the parameter of C1, T the parameter of C2. Non-decreasing
/// coefficients make σ non-decreasing (eq. 4).
struct Mapping {
  int degree = 2;
  std::vector<double> knots;     ///< full clamped knot vector (coefficients + degree + 1 values)
  Eigen::VectorXd coefficients;  ///< β_i

  /// σ as a 1-D B-spline curve (points (n+1)×1).
  spline::BSplineCurve curve() const;
  double domainBegin() const { return knots[degree]; }
  double domainEnd() const { return knots[knots.size() - degree - 1]; }
  /// σ^{(derivative)}(t), t clamped into the domain.
  double evaluate(double t, int derivative = 0) const;
  /// The smallest t in the domain with σ(t) ≥ T (bisection to 1e-15 of the domain; σ must be
  /// non-decreasing). Returns the domain's begin/end if T is below/above the range of σ.
  double inverse(double T) const;
};

/// β_i = Σ_{j≤i} ε_j² (eq. 5): mapping coefficients from shape parameters.
Eigen::VectorXd mappingCoefficients(const Eigen::VectorXd& shape);

/// Shape parameters with mappingCoefficients(ε) = β for non-decreasing β with β_0 ≥ 0:
/// ε_0 = √β_0, ε_i = √(β_i − β_{i−1}).
Eigen::VectorXd shapeParameters(const Eigen::VectorXd& coefficients);

/// Greville abscissae: the coefficients of the identity σ(t) = t (the initialization T = t).
Eigen::VectorXd identityCoefficients(const spline::KnotVector& knots);

/// S(i, k) = Σ_{j≥k} B_{j,d}(params[i]): σ(params[i]) = Σ_k S(i,k) ε_k² (rows hold only the
/// nonzero tail sums: k ≤ last basis function that does not vanish).
spline::EvaluationMatrix tailSumMatrix(const spline::KnotVector& knots,
                                       const std::vector<double>& params);

}  // namespace devsurf::models::quasi_strip
