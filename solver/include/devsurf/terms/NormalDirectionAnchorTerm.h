#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Keeps vectors near the directions they started in, their lengths free: per vector n_i three
/// rows (I − u_i u_iᵀ) n_i with u_i a unit direction (rank 2; linear). The Gauss image's guard
/// against its degenerate solutions on developables (models::quad_mesh::solveGaussImage: on a cone
/// a constant normal satisfies eq. 3 and 5 of 004_… with zero fairness).
class NormalDirectionAnchorTerm final : public engine::Term {
 public:
  /// @param[in] directions    unit directions u_i, one row per vector
  /// @param[in] pointOffsets  index in x of each vector's first component (one per row)
  /// @throws std::invalid_argument on a count mismatch or a negative offset
  NormalDirectionAnchorTerm(std::string name, Eigen::MatrixX3d directions, std::vector<int> pointOffsets);

  int numResiduals() const override { return 3 * static_cast<int>(offsets_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  Eigen::MatrixX3d directions_;
  std::vector<int> offsets_;
};

}  // namespace devsurf::terms
