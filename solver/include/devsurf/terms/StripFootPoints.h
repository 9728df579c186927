#pragma once

#include <vector>

#include <Eigen/Core>

#include "devsurf/spline/KnotVector.h"

namespace devsurf::terms {

/// Closest points of reference points q_j on a ruled strip s(u, v) = (1 − v) a(u) + v b(u)
/// (000_… §4.2: "for each q_j we apply closest point projection onto the developable, which
/// results in the point s(u_j, v_j)"). Shared by the approximation terms of eq. (9)–(11), which
/// hold (u_j, v_j) constant within an iteration.
///
/// The curves a and b share knots and weights and live in x as blocks of 3D control points. The
/// basis of each foot parameter is kept dense over all n control points (zeros outside the span),
/// so the terms' Jacobian structure does not change when u_j moves to another span.
///
/// Projection: a scan of the rulings at `scanSamples` parameters (closest point on each ruling
/// segment, v clamped to [0, 1]) picks a start, then damped Newton steps on ½|s − q|² in (u, v)
/// with u clamped to the domain (wrapped for closed curves) and v to [0, 1]. Points beyond the strip's boundary
/// project onto the boundary.
class StripFootPoints {
 public:
  /// @param[in] knots     the common knot vector of a and b (n control points)
  /// @param[in] weights   NURBS weights (n) or empty; held constant
  /// @param[in] offsetA   index in x of a's control point 0, coordinate x (b at offsetB)
  /// @param[in] points    reference points q_j, N×3 (same coordinates as x)
  /// @throws std::invalid_argument on an empty or non-finite point set or wrong weights
  StripFootPoints(spline::KnotVector knots, Eigen::VectorXd weights, int offsetA, int offsetB,
                  Eigen::MatrixX3d points);

  /// Projects every q_j onto the strip at x. Does nothing when a's and b's control points equal
  /// those of the previous update (several terms share one projection per iteration).
  void update(const Eigen::VectorXd& x);

  int count() const { return static_cast<int>(points_.rows()); }
  int controlPoints() const { return n_; }
  int offsetA() const { return offsetA_; }
  bool closed() const { return knots_.kind() == spline::KnotKind::Periodic; }
  int offsetB() const { return offsetB_; }
  const Eigen::MatrixX3d& points() const { return points_; }
  double u(int j) const { return u_[static_cast<std::size_t>(j)]; }
  double v(int j) const { return v_[static_cast<std::size_t>(j)]; }
  /// R_i(u_j), i = 0 … n−1 (the rational basis when weighted), from the last update.
  const double* basis(int j) const { return basis_.data() + static_cast<std::ptrdiff_t>(j) * n_; }
  /// R_i′(u_j), i = 0 … n−1.
  const double* basisDerivative(int j) const { return derivative_.data() + static_cast<std::ptrdiff_t>(j) * n_; }
  /// Σ_i w_i · x[offset + 3i .. +2] for a dense row w of n values.
  Eigen::Vector3d combine(const Eigen::VectorXd& x, int offset, const double* w) const;
  /// a(u_j), b(u_j), a′(u_j), b′(u_j) and s(u_j, v_j) at x with the stored parameters.
  Eigen::Vector3d a(const Eigen::VectorXd& x, int j) const { return combine(x, offsetA_, basis(j)); }
  Eigen::Vector3d b(const Eigen::VectorXd& x, int j) const { return combine(x, offsetB_, basis(j)); }
  Eigen::Vector3d da(const Eigen::VectorXd& x, int j) const { return combine(x, offsetA_, basisDerivative(j)); }
  Eigen::Vector3d db(const Eigen::VectorXd& x, int j) const { return combine(x, offsetB_, basisDerivative(j)); }
  Eigen::Vector3d surfacePoint(const Eigen::VectorXd& x, int j) const;
  /// Number of updates that projected (not skipped); for tests.
  int projections() const { return projections_; }

  /// Rulings scanned for a start (default: 8 per control point, at least 64).
  int scanSamples = 0;
  /// Newton steps after the scan (each backtracks until the distance decreases).
  int refinementSteps = 30;

 private:
  /// Dense R(u), R′(u) and (unless ddr is null) R″(u) over all n control points (n values each).
  void basisAt(double u, double* r, double* dr, double* ddr) const;
  double wrapOrClamp(double u) const;

  spline::KnotVector knots_;
  Eigen::VectorXd weights_;
  int n_ = 0;
  int offsetA_ = 0, offsetB_ = 0;
  Eigen::MatrixX3d points_;
  std::vector<double> u_, v_, basis_, derivative_;
  Eigen::VectorXd lastControl_;  ///< a's then b's control points at the last projection
  int projections_ = 0;
};

}  // namespace devsurf::terms
