#pragma once

#include <Eigen/SparseCore>

namespace devsurf::spline {

/// The boundary-interpolating cubic B-spline subdivision of Jiang et al. 2020 (004_… §4, eq. 8):
/// the control polygon p_1 … p_M of a clamped cubic B-spline with uniform interior knots becomes
/// the 2M − 3 control points of the same curve after a knot is inserted in the middle of every
/// span (Boehm). The new knots are again clamped and uniform, so the rule is stationary and the
/// control polygons of k rounds converge to the curve. Away from the ends it is the cubic
/// Lane–Riesenfeld rule (edge points ½(p_j + p_{j+1}), vertex points ⅛(p_{j−1} + 6p_j + p_{j+1}));
/// at the ends p_1 stays and the stencils are ½ ½, ¾ ¼, 3/16 11/16 2/16 (for M ≥ 6; polygons of 4
/// and 5 points have their own, as knot insertion gives them).

/// Control points after `rounds` rounds on `count`: 2^rounds · (count − 3) + 3.
/// @throws std::invalid_argument if count < 4, rounds < 0, or the result exceeds 2^30.
int cubicSubdividedCount(int count, int rounds);

/// One round on a polygon of `count` ≥ 4 points: the (2·count − 3) × count matrix α of eq. 8
/// (rows sum to 1), so that new points = α · old points (points as rows).
/// @throws std::invalid_argument if count < 4.
Eigen::SparseMatrix<double> cubicSubdivisionMatrix(int count);

/// `rounds` rounds on a rows × columns grid of control points, each round applied to every row
/// and then to every column (eq. 8; away from the boundary rows this is Catmull–Clark on a
/// regular grid). Grid point (r, c) has index r·columns + c before and after; the result is an
/// (R·C) × (rows·columns) matrix with R = cubicSubdividedCount(rows, rounds) and C likewise. The
/// limit is the bicubic clamped B-spline surface with uniform interior knots whose control net
/// is the grid; every round's net is that surface's control net on the refined knots.
/// @throws std::invalid_argument if rows or columns < 4 or rounds < 0.
Eigen::SparseMatrix<double> cubicGridSubdivisionMatrix(int rows, int columns, int rounds);

}  // namespace devsurf::spline
