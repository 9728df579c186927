#pragma once

#include <memory>
#include <string>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/StripFootPoints.h"

namespace devsurf::terms {

/// Proximity of a ruled strip to reference points, 000_… eq. (9): per reference point q_j three
/// rows s(u_j, v_j) − q_j with s = (1 − v) a(u) + v b(u) and (u_j, v_j) the closest-point
/// parameters renewed in linearizeAt() (held constant within an iteration, so the rows are linear
/// in a's and b's control points). Given a low weight: enforced strictly it would stop the strip
/// from sliding along the target. Units of length.
class StripPointDistanceTerm final : public engine::Term {
 public:
  /// @param[in] feet  the shared projection (its points are the q_j)
  /// @throws std::invalid_argument on a null projection
  StripPointDistanceTerm(std::string name, std::shared_ptr<StripFootPoints> feet);

  int numResiduals() const override { return 3 * feet_->count(); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  /// Projects the reference points onto the strip at x.
  void linearizeAt(const Eigen::VectorXd& x) override;
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  std::shared_ptr<StripFootPoints> feet_;
};

}  // namespace devsurf::terms
