#pragma once

#include <vector>

#include <Eigen/Core>

#include "devsurf/spline/KnotVector.h"

namespace devsurf::spline {

/// A (possibly rational) B-spline curve in any dimension.
/// Control points are rows of `points` (n×dim). `weights` is empty for a polynomial curve or
/// holds n positive weights for a NURBS curve.
struct BSplineCurve {
  KnotVector knots;
  Eigen::MatrixXd points;   ///< n×dim
  Eigen::VectorXd weights;  ///< empty, or n positive weights (rational curve)

  int degree() const { return knots.degree(); }
  int dimension() const { return static_cast<int>(points.cols()); }
  bool isRational() const { return weights.size() > 0; }

  /// Checks that the parts fit together: a non-empty knot vector, points.rows() ==
  /// knots.numControlPoints(), at least one column, finite points, and weights empty or n finite
  /// positive values. Every function below that processes the whole curve calls this.
  /// @throws std::invalid_argument naming the rule broken.
  void validate() const;

  /// Point (derivative = 0) or the l-th derivative at u, for rational curves too (NURBS Book A4.2).
  Eigen::VectorXd evaluate(double u, int derivative = 0) const;
  /// Rows are evaluate(params[k], derivative).
  Eigen::MatrixXd evaluate(const std::vector<double>& params, int derivative = 0) const;
  /// The point and its derivatives up to `upTo` at u from one basis evaluation: column k of
  /// `out` is evaluate(u, k). No allocation for polynomial curves up to kStackBasisDegree, so
  /// loops that sample a surface every iterate pass fixed-size storage (Eigen::Matrix3Xd-like).
  /// @param[out] out  dim×(upTo+1), sized by the caller
  /// @throws std::invalid_argument for a malformed curve or a wrongly sized `out`
  void derivatives(double u, int upTo, Eigen::Ref<Eigen::MatrixXd> out) const;
};

/// Two curves evaluated at the same parameters: a.derivatives(u, …) and b.derivatives(u, …) from
/// one basis evaluation when both are polynomial curves on equal knot vectors (the two boundaries
/// of a strip), which is checked once, here. Keeps references: the curves must outlive it.
class CurvePair {
 public:
  CurvePair(const BSplineCurve& a, const BSplineCurve& b);
  /// @param[out] outA, outB  dim×(upTo+1), sized by the caller: column k is the k-th derivative
  void derivatives(double u, int upTo, Eigen::Ref<Eigen::MatrixXd> outA, Eigen::Ref<Eigen::MatrixXd> outB) const;
  /// Whether one basis evaluation serves both curves.
  bool sharesBasis() const { return shared_; }

 private:
  const BSplineCurve& a_;
  const BSplineCurve& b_;
  bool shared_ = false;
};

/// A Bézier piece of degree p: p+1 control points as rows, parameter interval [begin, end].
struct BezierPiece {
  Eigen::MatrixXd points;  ///< (p+1)×dim
  double begin = 0.0;
  double end = 1.0;
};

/// Evaluate a Bézier curve (control points as rows) at local parameter t ∈ [0,1] (de Casteljau).
Eigen::VectorXd evaluateBezier(const Eigen::MatrixXd& points, double t);

/// Insert knot u `times` times (Boehm / NURBS Book A5.1). Rational curves are handled in
/// homogeneous coordinates. The curve is unchanged as a point set and as a parametrization.
/// @throws std::invalid_argument if u is outside the domain, multiplicity would exceed degree,
///         or the curve is periodic (only clamped knot vectors are supported).
BSplineCurve insertKnot(const BSplineCurve& curve, double u, int times = 1);

/// The part of the curve over [u0, u1] as a clamped curve of its own, exactly (knots inserted at u0
/// and u1 up to the degree, the control points between kept; NURBS Book §5.3): the same points at
/// the same parameters, the domain [u0, u1]. Two curves with one knot vector restricted to one
/// interval keep one knot vector.
/// @throws std::invalid_argument unless domainBegin ≤ u0 < u1 ≤ domainEnd, or for a periodic curve
BSplineCurve restrictToInterval(const BSplineCurve& curve, double u0, double u1);

/// Insert every knot in `newKnots` (sorted, with repetition) — knot refinement.
/// Same requirements and exceptions as insertKnot.
BSplineCurve refineKnots(const BSplineCurve& curve, const std::vector<double>& newKnots);

/// The curve approximated in another clamped spline space of the same degree and domain (e.g. one
/// interior knot fewer: a knot removal that cannot keep the shape exactly): the end points are kept
/// and the interior control points minimize Σ‖c′(u_k) − c(u_k)‖² over `samplesPerSpan` parameters
/// in every span of either knot vector. A space that contains the curve reproduces it.
/// @throws std::invalid_argument for rational or periodic curves, another degree or domain, or a
///         space with fewer than degree + 1 control points
BSplineCurve approximateInSpace(const BSplineCurve& curve, const KnotVector& knots, int samplesPerSpan = 12);

/// Greville abscissae of a knot vector: (t_{i+1} + … + t_{i+p}) / p per control point i, the
/// parameter each control point "sits at".
std::vector<double> grevilleAbscissae(const KnotVector& knots);

/// Split a clamped, non-rational curve into its Bézier pieces, one per non-empty span.
std::vector<BezierPiece> bezierPieces(const BSplineCurve& curve);

/// Degree elevation of a Bézier curve by t (control points as rows).
Eigen::MatrixXd elevateBezierDegree(const Eigen::MatrixXd& points, int t);

/// Degree elevation of a clamped, non-rational B-spline curve by t (continuity at interior knots
/// is preserved: every interior knot's multiplicity grows by t). The curve is unchanged.
BSplineCurve elevateDegree(const BSplineCurve& curve, int t);

/// Composition c(φ(t)) of a Bézier curve c of degree p (control points as rows, parameter
/// [0,1]) with a polynomial reparametrization φ of degree q given by its q+1 Bézier
/// coefficients on [0,1] (values of φ in [0,1] map into c's parameter interval [0,1]).
/// Returns the p·q+1 Bézier control points of the composite (exact, by blossoming/products).
Eigen::MatrixXd composeBezier(const Eigen::MatrixXd& points, const Eigen::VectorXd& phi);

}  // namespace devsurf::spline
