#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/ExtendedCurve.h"

namespace devsurf::terms {

/// End-point fixing of 001_… §5.4: the end point C2(σ(t_e)) of the strip's boundary on C2 stays
/// at its original position, three rows C2(σ(t_e)) − target with σ(t_e) = Σ_k w_k ε_k² (the
/// tail sums of eq. 5 at t_e). Squared with weight √μ the rows add μ·|C2(σ(t_e)) − target|² to
/// eq. 9 (the paper uses μ = 1000).
class MappingEndPointTerm final : public engine::Term {
 public:
  /// @param[in] shapeOffset  index in x of ε_0
  /// @param[in] weights      (k, w_k) pairs: σ(t_e) = Σ w_k ε_k²
  /// @param[in] c2           the mapped curve
  /// @param[in] target       where C2(σ(t_e)) should be
  MappingEndPointTerm(std::string name, int shapeOffset, std::vector<std::pair<int, double>> weights,
                      std::shared_ptr<const ExtendedCurve> c2, Eigen::Vector3d target);

  int numResiduals() const override { return 3; }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  int shapeOffset_;
  std::vector<std::pair<int, double>> weights_;
  std::shared_ptr<const ExtendedCurve> c2_;
  Eigen::Vector3d target_;
};

}  // namespace devsurf::terms
