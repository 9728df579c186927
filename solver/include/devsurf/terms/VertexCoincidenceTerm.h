#pragma once

#include <string>
#include <utility>
#include <vector>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Gluing (004_… §2.3.1, the pair part of E_pos): per pair (i, j) three rows v_i − v_j, pulling
/// two vertices of one mesh onto each other. Linear, units of length. Handles (v_i − a_i) are
/// HandleTargetTerm.
class VertexCoincidenceTerm final : public engine::Term {
 public:
  /// @param[in] pairs         (i, j) indices into pointOffsets, i ≠ j
  /// @param[in] pointOffsets  index in x of point i's x coordinate (y at +1, z at +2)
  /// @throws std::invalid_argument on an index out of range, i = j, a negative offset or
  ///         overlapping point blocks
  VertexCoincidenceTerm(std::string name, std::vector<std::pair<int, int>> pairs,
                        std::vector<int> pointOffsets);

  int numResiduals() const override { return 3 * static_cast<int>(pairs_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  std::vector<std::pair<int, int>> pairs_;  ///< as offsets into x
};

}  // namespace devsurf::terms
