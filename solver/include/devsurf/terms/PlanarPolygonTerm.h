#pragma once

#include <vector>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Planarity of an R…R face (000_… §3.1): with the face's auxiliary normal n_f, one row
///   ⟨n_f, v_{i+1} − v_i⟩
/// per edge of the closed polygon v_0 … v_{N−1} (N rows, v_N = v_0). Quadratic, unscaled (units
/// of length). One row is redundant (the edges sum to zero); the paper keeps all of them.
/// \note n_f = 0 solves all rows: the unit length n_fᵀn_f = 1 is left to UnitNormalTerm.
class PlanarPolygonTerm final : public engine::Term {
 public:
  /// @param[in] normalOffset    index in x of n_f's x coordinate
  /// @param[in] vertexOffsets   index in x of each vertex's x coordinate, in boundary order (≥ 3)
  /// @throws std::invalid_argument for fewer than 3 vertices or overlapping variables
  PlanarPolygonTerm(std::string name, int normalOffset, std::vector<int> vertexOffsets);

  int numResiduals() const override { return static_cast<int>(vertices_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  int normal_;
  std::vector<int> vertices_;
};

}  // namespace devsurf::terms
