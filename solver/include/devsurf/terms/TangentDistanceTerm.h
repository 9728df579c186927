#pragma once

#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Keeps development vertices on a prescribed planar curve (000_… §5 "Isometric mapping",
/// 003_… §5.2.5 TDM): for every 2D vertex v̄_i one row
///   (v̄_i − f̄_i) · n̄_i,
/// the signed distance from the tangent line of the curve at the foot point f̄_i. The curve is a
/// polyline (open or closed); f̄_i is the point of the polyline closest to v̄_i and n̄_i the unit
/// normal there. Both are recomputed in linearizeAt() and are constants within an iteration, so
/// the row is linear with Jacobian n̄_iᵀ. A finite-difference check must hold them fixed too —
/// engine::checkJacobian does, by calling linearizeAt() once before differencing.
///
/// Normals: n̄ = (t_y, −t_x) for the unit direction t of travel along the polyline (outward for
/// a counter-clockwise closed polyline). A foot point inside a segment takes that segment's
/// normal; a foot point on an interior polyline vertex the normalized sum of the two adjacent
/// segment normals (the discrete tangent of the curve the polyline samples); a foot point on an
/// end of an open polyline the end segment's normal (the curve extended by its end tangent).
class TangentDistanceTerm final : public engine::Term {
 public:
  /// @param[in] developedOffsets  index in x of each constrained vertex's x̄ (ȳ at +1)
  /// @param[in] polyline          curve points in order (≥ 2; ≥ 3 if closed), consecutive
  ///                              points distinct; a closed polyline does not repeat point 0
  /// @param[in] closed            the segment from the last point back to the first belongs to
  ///                              the curve
  /// @throws std::invalid_argument on too few points or a zero-length segment
  TangentDistanceTerm(std::string name, std::vector<int> developedOffsets,
                      std::vector<Eigen::Vector2d> polyline, bool closed);

  int numResiduals() const override { return static_cast<int>(offsets_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  /// Foot points and normals of the vertices at x.
  void linearizeAt(const Eigen::VectorXd& x) override;
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

  /// Foot point and normal of vertex i from the last linearization.
  const Eigen::Vector2d& footPoint(int i) const { return feet_[i]; }
  const Eigen::Vector2d& normal(int i) const { return normals_[i]; }

  /// Closest point of the polyline to p and the unit normal there (the rule above).
  void project(const Eigen::Vector2d& p, Eigen::Vector2d& foot, Eigen::Vector2d& normal) const;

 private:
  int numSegments() const;
  std::vector<int> offsets_;
  std::vector<Eigen::Vector2d> points_;
  std::vector<Eigen::Vector2d> segmentNormals_;
  bool closed_;
  std::vector<Eigen::Vector2d> feet_, normals_;
};

}  // namespace devsurf::terms
