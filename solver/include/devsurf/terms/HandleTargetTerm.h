#pragma once

#include <Eigen/Core>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// A point of x pulled toward a target position: residual p − target (3 rows). The mechanism
/// behind handles and the browser's drag; the target may move between iterations without a
/// change of topology.
class HandleTargetTerm final : public engine::Term {
 public:
  /// @param[in] offset  index in x of the point's x coordinate
  HandleTargetTerm(std::string name, int offset, const Eigen::Vector3d& target);

  void setTarget(const Eigen::Vector3d& target) { target_ = target; }
  const Eigen::Vector3d& target() const { return target_; }
  int offset() const { return offset_; }

  int numResiduals() const override { return 3; }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  int offset_;
  Eigen::Vector3d target_;
};

}  // namespace devsurf::terms
