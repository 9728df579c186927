#pragma once

#include <Eigen/Core>

namespace devsurf::models::conical_strip {

/// Which input curve a boundary (or a projection point) belongs to.
enum class StripSide { P, Q };
const char* stripSideName(StripSide side);

/// Triangular (one boundary collapsed into the projection point, §3.1) or quadrilateral (§3.2).
enum class PatchType { Triangular, Quadrilateral };
const char* patchTypeName(PatchType type);

/// A ruled Bézier patch in generalized conical form (Chu et al. eq. 3):
///
///   s(u, v) = (1 − v) a(u) + v b(u),  u, v ∈ [0, 1],
///
/// a(u) on the P side and b(u) on the Q side are Bézier curves of the same degree (2 after the
/// greedy algorithm, 3 after degree elevation and the G1 adjustment), control points as rows.
/// One boundary, the *base*, is built from its curve (end points + tangent heuristic, or the G1
/// tangents); the other, the *scaled* boundary, is its image under eq. 3:
///
///   scaled_k − base_k = f · (O − base_k)   for every control point k,
///
/// i.e. every control pair (a_k, b_k) lies on a line through the projection point O and the
/// scaled polygon is a homothetic copy of the base polygon (centre O, ratio 1 − f). The patch is
/// then part of the cone with apex O over the base curve, hence developable.
///
/// * Triangular patch: f = 1, the scaled boundary is the point O (the apex), a sample point of
///   the other curve.
/// * Quadrilateral patch: 1 − f ∈ [1/ra, ra] (the boundary length ratio); f = 0 would be a
///   generalized cylinder (O at infinity; projectionPoint is then not finite).
struct ConicalPatch {
  PatchType type = PatchType::Triangular;
  StripSide baseSide = StripSide::P;  ///< the boundary built from its curve; the other is scaled
  Eigen::MatrixX3d a;                 ///< P-side control points, (degree+1)×3
  Eigen::MatrixX3d b;                 ///< Q-side control points, (degree+1)×3
  double scale = 1.0;                 ///< f of eq. 3
  Eigen::Vector3d projectionPoint = Eigen::Vector3d::Zero();  ///< O of eq. 3
  /// Sample indices (into the Np / Nq samples) the start and end rulings stand for.
  int pBegin = 0, pEnd = 0, qBegin = 0, qEnd = 0;
  /// Curve parameters of the four corners' nearest input-curve points (for tangents).
  double pParamBegin = 0.0, pParamEnd = 0.0, qParamBegin = 0.0, qParamEnd = 0.0;

  int degree() const { return static_cast<int>(a.rows()) - 1; }
  const Eigen::MatrixX3d& base() const { return baseSide == StripSide::P ? a : b; }
  const Eigen::MatrixX3d& scaled() const { return baseSide == StripSide::P ? b : a; }

  Eigen::Vector3d pointA(double u) const;
  Eigen::Vector3d pointB(double u) const;
  Eigen::Vector3d derivativeA(double u) const;
  Eigen::Vector3d derivativeB(double u) const;
  /// Unit normal along the ruling at u: ((a′ + b′)/2) × (b − a), normalized (constant along the
  /// ruling for a developable patch; defined for triangles since one of a′, b′ is zero).
  Eigen::Vector3d normal(double u) const;
  /// Surface area ∫∫|s_u × s_v| (Gauss–Legendre, 4 sub-intervals × 8 points in u, 4 in v).
  double area() const;
  /// Largest distance of the boundary curves (33 samples each) from the line through x0, x1.
  double momentArm(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1) const;
};

/// Builds the patch from its base boundary: scaled_k = base_k + f(base_0 − base_k) + (s0 − base_0)
/// with s0 the scaled boundary's first point. This is eq. 3 written without O, exact also when O
/// is far away (f → 0). Fills a, b, scale and projectionPoint = base_0 + (s0 − base_0)/f.
void setConicalForm(ConicalPatch& patch, const Eigen::MatrixX3d& base,
                    const Eigen::Vector3d& scaledStart, double f);

/// Relative residual of eq. 3: max_k |(scaled_k − base_k) − f(O − base_k)| / |scaled_k − base_k|
/// (for f = 0: |c_k − c_0| / |c_k| with c_k = scaled_k − base_k). Zero up to rounding for a patch
/// in conical form; it measures the projection-point/coplanarity conditions on the control points.
double projectionResidual(const ConicalPatch& patch);

/// Largest scale-free triple product |det(b − a, a′, b′)| / (|b − a||a′||b′|) (eq. 2) over
/// `samples` equally spaced rulings, ends included.
double coplanarityResidual(const ConicalPatch& patch, int samples = 33);

/// Degree elevation of both boundaries (eq. 4–5); the patch keeps O, f and its shape.
ConicalPatch elevateDegree(const ConicalPatch& patch);

/// §3.1 heuristic for the middle control point of a quadratic boundary from e0 to e1 with unit
/// curve tangents t0, t1 and the curve's point `middle` halfway (in arc length) between them:
/// the intersection of the tangent lines if they meet, else of their projections into the plane
/// through e0, e1, middle. Falls back to the quadratic through `middle` at u = ½ when the
/// projected lines are (nearly) parallel or meet behind either end or farther than the chord.
Eigen::Vector3d quadraticMiddleControl(const Eigen::Vector3d& e0, const Eigen::Vector3d& t0,
                                       const Eigen::Vector3d& e1, const Eigen::Vector3d& t1,
                                       const Eigen::Vector3d& middle);

}  // namespace devsurf::models::conical_strip
