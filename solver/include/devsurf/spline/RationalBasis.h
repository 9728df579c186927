#pragma once

#include <vector>

#include <Eigen/Core>

#include "devsurf/spline/Basis.h"

namespace devsurf::spline {

/// Evaluation matrix of the rational basis R_i = w_i N_i / Σ_j w_j N_j and its derivatives
/// (derivative ≤ 2): with weights held constant a NURBS curve is *linear* in its Cartesian
/// control points, c^{(l)}(u) = Σ_i R_i^{(l)}(u) P_i, so every term that is linear or quadratic in
/// control points stays so. With empty `weights` this is evaluationMatrix().
/// @param[in] weights  n positive weights, or empty
/// @throws std::invalid_argument if derivative > 2 for a rational basis or weights are wrong
EvaluationMatrix curveEvaluationMatrix(const KnotVector& knots, const Eigen::VectorXd& weights,
                                       const std::vector<double>& params, int derivative);

}  // namespace devsurf::spline
