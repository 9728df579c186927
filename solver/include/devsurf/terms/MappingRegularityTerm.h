#pragma once

#include <array>
#include <string>
#include <vector>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/VertexProductRows.h"

namespace devsurf::terms {

/// Regularity of the mapping M → M′ (004_… §2.3.3, E_map, the discrete version of eq. 7: an
/// isometry maps the tangential part of a curve's second derivative to that of its image). Per
/// quadruple (i, j, k, l) — v_i, v_j, v_k successive on a mesh polyline, v_j v_l an edge — one row
///   ⟨v_i − 2v_j + v_k, v_l − v_j⟩ − ⟨v′_i − 2v′_j + v′_k, v′_l − v′_j⟩.
/// Quadratic, units of length². Regularizes the map (and through it a variable M′) without
/// fairing the polylines of M′ themselves.
class MappingRegularityTerm final : public engine::Term {
 public:
  /// @param[in] quadruples        (i, j, k, l) vertex indices; i, j, k pairwise distinct, l ≠ j
  ///                              (l may equal i or k: their coefficients are merged)
  /// @param[in] meshOffsets       index in x of vertex i's x coordinate in M (y at +1, z at +2)
  /// @param[in] unfoldingOffsets  the same for M′; as many as meshOffsets
  /// @throws std::invalid_argument on a count mismatch, an index out of range, repeated indices
  ///         as above, a negative offset, or overlapping vertex blocks (M and M′ together)
  MappingRegularityTerm(std::string name, const std::vector<std::array<int, 4>>& quadruples,
                        const std::vector<int>& meshOffsets,
                        const std::vector<int>& unfoldingOffsets);

  int numResiduals() const override { return rows_.size(); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override {
    rows_.jacobianStructure(entries);
  }
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override {
    rows_.evaluate(x, residuals, jacobian);
  }

 private:
  VertexProductRows rows_;
};

}  // namespace devsurf::terms
