#pragma once

// Curve pairs of the quasi-strip tests: exact developables with a known mapping.

#include <Eigen/Core>

#include "devsurf/models/quasi_strip/QuasiStripModel.h"
#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/KnotVector.h"

namespace devsurf::models::quasi_strip::testing {

inline spline::BSplineCurve bezierCurve(const Eigen::MatrixXd& points) {
  spline::BSplineCurve c;
  c.knots = spline::KnotVector::clampedUniform(static_cast<int>(points.rows()) - 1,
                                               static_cast<int>(points.rows()));
  c.points = points;
  return c;
}

/// A non-planar cubic Bézier q.
inline Eigen::MatrixXd cubicQ() {
  Eigen::MatrixXd q(4, 3);
  q << 0, 0, 0, 1, 0.6, 0.3, 2, -0.4, 0.8, 3, 0.2, 0.1;
  return q;
}

/// Fig. 6 in spirit: C2 = q, C1(t) = q(t(1+t)/2) + d (degree 6, built exactly by composition):
/// the generalized cylinder C1(t)–C2(σ(t)) with σ(t) = t(1+t)/2 is developable.
inline QuasiStripDesign exactQuadraticDesign() {
  const Eigen::MatrixXd q = cubicQ();
  Eigen::VectorXd phi(3);
  phi << 0.0, 0.25, 1.0;  // t(1+t)/2 in Bernstein form
  Eigen::MatrixXd c1 = spline::composeBezier(q, phi);
  c1.rowwise() += Eigen::RowVector3d(0.3, 1.2, 0.5);
  QuasiStripDesign d;
  d.c1 = bezierCurve(c1);
  d.c2 = bezierCurve(q);
  d.mapping = {2, 3};
  d.samples = 100;
  return d;
}

/// A strongly twisted pair (Fig. 2 in spirit): a cone with apex A through a wavy quintic q,
/// C2 = q and C1 = A + 1.8 (q∘ψ − A) with ψ a cubic far from the identity; at T = t the rulings
/// cross the cone.
inline QuasiStripDesign twistedConeDesign() {
  Eigen::MatrixXd q(6, 3);
  q << 0, 0, 0, 1, 1.2, 0.4, 2, -0.8, 1.0, 3, 1.0, -0.6, 4, -0.6, 0.3, 5, 0.4, 0.0;
  Eigen::VectorXd psi(4);
  psi << 0.0, 0.08, 0.33, 1.0;  // slow start, fast end
  const Eigen::RowVector3d apex(2.5, 0.2, -3.0);
  Eigen::MatrixXd c1 = spline::composeBezier(q, psi);
  c1 = ((c1.rowwise() - apex) * 1.8).rowwise() + apex;
  QuasiStripDesign d;
  d.c1 = bezierCurve(c1);
  d.c2 = bezierCurve(q);
  return d;
}

}  // namespace devsurf::models::quasi_strip::testing
