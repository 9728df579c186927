#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "devsurf/models/quasi_strip/Mapping.h"
#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::models::quasi_strip {

/// A B-spline surface of degree 1 × degree (001_… eq. 16):
///   S(s, t) = Σ_{k=0,1} Σ_i P^k_i N_{i,degree}(t) N_{k,1}(s),  s ∈ [0,1], t ∈ [knots.front(), knots.back()].
/// Row i of `side0`/`side1` is P^0_i / P^1_i: side0 is the boundary s = 0 (on C1), side1 the
/// boundary s = 1 (on C2). The s knots are [0, 0, 1, 1].
struct RuledBSplineSurface {
  int degree = 0;               ///< degree in t (p·d for Algorithm 1)
  std::vector<double> knots;    ///< clamped knot vector in t, side0.rows() + degree + 1 values
  Eigen::MatrixX3d side0, side1;

  /// The boundary curve of side 0 (s = 0) or 1 (s = 1).
  spline::BSplineCurve boundary(int side) const;
  /// S(s, t).
  Eigen::Vector3d evaluate(double s, double t) const;
};

/// §4 preprocessing: brings two clamped, non-rational curves on the same parameter domain to one
/// degree (the larger, by degree elevation A5.9) and one knot vector (the union of both knot
/// vectors with the larger multiplicity of every value, by knot insertion). Neither curve changes
/// as a point set or as a parametrization.
/// @throws std::invalid_argument ("c2.knots: …") if the domains differ or a curve is rational/periodic
std::pair<spline::BSplineCurve, spline::BSplineCurve> makeCompatible(const spline::BSplineCurve& c1,
                                                                     const spline::BSplineCurve& c2);

/// §3.4 curve extension: the curve on [begin − beginLength, end + endLength], continuing its first
/// and last polynomial spans (the "unclamping" extension of ref. [32]); unchanged on the old domain.
/// The result has interior knots of multiplicity = degree (it is assembled from Bézier pieces).
spline::BSplineCurve extendCurve(const spline::BSplineCurve& curve, double beginLength,
                                 double endLength);

/// The curve reparametrized affinely onto [0, 1] (knots mapped, control points unchanged).
spline::BSplineCurve reparametrizeToUnit(const spline::BSplineCurve& curve);

/// Algorithm 1 (001_… §4): the ruled surface S(s,t) = (1−s) C1(t) + s C2(σ(t)), t ∈ [tBegin, tEnd],
/// written exactly as a B-spline surface of degree 1 × max(p1, p2·d): the parameter range is split
/// at the knots of σ and C1 and at σ⁻¹ of the knots of C2 (Step 1), each piece of σ, C1 and C2 is
/// taken in Bézier form (Step 2), C2's piece is composed with the normalized piece of σ
/// (Step 3, spline::composeBezier), C1's piece is degree-elevated (Step 4), and the pieces are
/// joined with interior knots of multiplicity p·d (Step 5). The t parameter is kept (no uniform
/// reparametrization), so S(s, t) equals the ruled surface at the same (s, t).
/// Where σ leaves C2's domain, C2's end polynomial is continued (as the solver evaluates it).
/// @param[in] c1, c2  clamped, non-rational 3D curves
/// @param[in] sigma   a non-decreasing mapping from C1's parameter to C2's
/// @param[in] tBegin, tEnd  sub-range of σ's and C1's domains, tBegin < tEnd
RuledBSplineSurface convertRuledSurface(const spline::BSplineCurve& c1, const spline::BSplineCurve& c2,
                                        const Mapping& sigma, double tBegin, double tEnd);

}  // namespace devsurf::models::quasi_strip
