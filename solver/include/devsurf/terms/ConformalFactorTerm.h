#pragma once

#include <string>
#include <vector>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Conformal factors kept near 1 (004_… §2.3.1, E_λ): one row λ_f − 1 per face, λ_f at
/// x[factorOffset + f]. Linear, dimensionless; with a large weight it makes the conformal map of
/// CheckerboardConformalityTerm as isometric as possible.
class ConformalFactorTerm final : public engine::Term {
 public:
  /// @param[in] factorOffset  index in x of λ_0 (the factors are contiguous)
  /// @param[in] faceCount     number of factors (≥ 0)
  /// @throws std::invalid_argument on a negative offset or count
  ConformalFactorTerm(std::string name, int factorOffset, int faceCount);

  int numResiduals() const override { return faceCount_; }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  int factorOffset_;
  int faceCount_;
};

}  // namespace devsurf::terms
