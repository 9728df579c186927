#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Signed fold angle of a hinge (radians, FOLD's convention: + valley, − mountain, 0 flat).
///
/// The hinge axis runs a → b; c lies in the face to the left of the axis and d in the face to its
/// right (seen from the normals' side, faces counter-clockwise), so the faces' normals are
/// nL = (b − a) × (c − a) and nR = (d − a) × (b − a), and
///   θ = atan2(((nR × nL) · ê), nR · nL),  ê = (b − a)/|b − a|:
/// valley when the right face turns up towards the left face's normal side. θ ∈ (−π, π].
double hingeFoldAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                      const Eigen::Vector3d& d);

/// Fold-angle targets (the fold slider, FOLD's edges_foldAngle): per hinge one soft row
/// θ − θ*, wrapped into (−π, π], with θ from hingeFoldAngle. A straight crease (R edge) is one hinge
/// — along a ruling the tangent planes of a developable do not turn, so any point of each face's
/// tangent plane at the ruling serves as c, d; a curved crease is a hinge at each end, its axis the
/// crease's first control-polygon leg. Units: radians. The targets may change between iterations
/// without a change of topology (the slider moves them).
class HingeFoldAngleTerm final : public engine::Term {
 public:
  /// @param[in] hinges   per hinge the offsets in x of the x coordinates of a, b, c, d
  /// @param[in] targets  θ* per hinge, radians, finite
  /// @throws std::invalid_argument on a negative offset, a hinge using one point twice, or sizes
  ///         that differ
  HingeFoldAngleTerm(std::string name, std::vector<std::array<int, 4>> hinges, std::vector<double> targets);

  /// @throws std::invalid_argument when the size differs or a target is not finite
  void setTargets(const std::vector<double>& targets);
  const std::vector<double>& targets() const { return targets_; }

  int numResiduals() const override { return static_cast<int>(hinges_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  std::vector<std::array<int, 4>> hinges_;
  std::vector<double> targets_;
};

}  // namespace devsurf::terms
