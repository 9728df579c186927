#pragma once

#include <vector>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Unit length of selected 3-vectors in x (003_… §5.2.3): one row ⟨n_i, n_i⟩ − 1 per vector.
/// The model registers it twice: hard for the first normal (or the normal spline's end control
/// points) and soft with a small weight for the rest (000_… §2.2).
class UnitNormalTerm final : public engine::Term {
 public:
  /// @param[in] offsets  index in x of each vector's x coordinate
  UnitNormalTerm(std::string name, std::vector<int> offsets);

  int numResiduals() const override { return static_cast<int>(offsets_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  std::vector<int> offsets_;
};

}  // namespace devsurf::terms
