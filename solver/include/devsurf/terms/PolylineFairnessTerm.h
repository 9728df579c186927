#pragma once

#include <array>
#include <string>
#include <vector>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Fairness of mesh polylines (004_… §2.3.3, E_fair): per triple (i, j, k) of successive vertices
/// on a polyline three rows (x, y, z of) v_i − 2 v_j + v_k. Linear, units of length; used for M,
/// M′ and for vertex normals alike (points anywhere in x, 3 scalars each).
class PolylineFairnessTerm final : public engine::Term {
 public:
  /// @param[in] triples       (i, j, k) indices into pointOffsets, pairwise distinct
  /// @param[in] pointOffsets  index in x of point i's x coordinate (y at +1, z at +2)
  /// @throws std::invalid_argument on an index out of range, a repeated index in a triple, a
  ///         negative offset or overlapping point blocks
  PolylineFairnessTerm(std::string name, std::vector<std::array<int, 3>> triples,
                       std::vector<int> pointOffsets);

  int numResiduals() const override { return 3 * static_cast<int>(triples_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  std::vector<std::array<int, 3>> triples_;  ///< as offsets into x
};

}  // namespace devsurf::terms
