#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "devsurf/spline/KnotVector.h"

namespace devsurf::spline {

/// Row-major sparse matrix: one row per parameter, one column per (distinct) control point.
using EvaluationMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

/// The p+1 B-spline basis functions that do not vanish at a parameter, with derivatives.
struct BasisValues {
  int span = 0;             ///< slot s with t_s ≤ u < t_{s+1}
  Eigen::MatrixXd values;   ///< (derivatives+1)×(p+1): values(l, j) = N^{(l)}_{s−p+j}(u)
  /// Control point index of column j (wrapped for periodic knot vectors).
  std::vector<int> controlIndex;
};

/// Non-vanishing basis functions and their derivatives up to `derivatives` at u
/// (The NURBS Book A2.3). Derivatives beyond the degree are zero.
/// @param[in] u  parameter, clamped into the domain
BasisValues basisFunctions(const KnotVector& knots, double u, int derivatives);

/// Largest degree whose basis functions are evaluated without touching the heap.
inline constexpr int kStackBasisDegree = 15;

/// basisFunctions into caller storage, for loops that evaluate many parameters (a drag's
/// per-iterate sampling): no allocation for degrees up to kStackBasisDegree.
/// @param[out] values  (derivatives+1)×(p+1), sized by the caller (e.g. a fixed-capacity matrix):
///                     values(l, j) = N^{(l)}_{s−p+j}(u); column j's control point is
///                     knots.controlIndex(s − p + j)
/// @return the span s
/// @throws std::invalid_argument for an unusable knot vector or a wrongly sized `values`
int basisFunctionsInto(const KnotVector& knots, double u, int derivatives, Eigen::Ref<Eigen::MatrixXd> values);

/// N^{(l)}: the |params|×n matrix whose row k evaluates the l-th derivative at params[k]
/// when multiplied with the n×dim control-point matrix (003_… §5.2.2 "Implementation").
/// Built once per topology; columns are wrapped for periodic knot vectors.
/// \note Row k stores the p+1 entries of the span of params[k] even where a value is zero
///       (e.g. derivative > degree), so the sparsity pattern depends only on the spans of params.
EvaluationMatrix evaluationMatrix(const KnotVector& knots, const std::vector<double>& params,
                                  int derivative);

/// de Boor auxiliary points of level r at u (000_… Fig. 4) as linear combinations of the control
/// points: an (r+1)×n matrix D whose rows give the points d_0^{(r)}(u) … d_r^{(r)}(u).
/// Level 0 is the curve point itself; level 1 are the two points spanning the tangent line
/// (d_1^{(1)} − d_0^{(1)} is parallel to the first derivative); level 2 the three points spanning
/// the osculating plane. Requires r ≤ degree.
/// \note These are the intermediate points of de Boor's algorithm after p−r rounds.
EvaluationMatrix deBoorPointMatrix(const KnotVector& knots, double u, int level);

}  // namespace devsurf::spline
