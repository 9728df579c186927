#pragma once

#include <array>
#include <string>
#include <vector>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/VertexProductRows.h"

namespace devsurf::terms {

/// Checkerboard isometry between combinatorially equivalent meshes M and M′ (004_… §2.1 eq. 1):
/// the midpoint parallelograms inscribed in corresponding faces are congruent. Per quad
/// [v0, v1, v2, v3] with diagonals d0 = v0 − v2, d1 = v1 − v3 three rows
///   ‖d0‖² − ‖d0′‖²,   ‖d1‖² − ‖d1′‖²,   ⟨d0, d1⟩ − ⟨d0′, d1′⟩;
/// per triangle [v0, v1, v2, −1] three rows ‖v_a − v_b‖² − ‖v_a′ − v_b′‖² over its edges (0,1),
/// (1,2), (2,0) (the midpoint triangle is congruent). Quadratic, units of length², unscaled.
/// Rows are ordered face by face. Vertices of M and of M′ are 3 scalars each in x (a planar M′
/// keeps z fixed in the layout); a vertex and its image may both be variables.
class CheckerboardIsometryTerm final : public engine::Term {
 public:
  /// @param[in] faces             vertex indices counter-clockwise; [3] = −1 for a triangle
  /// @param[in] meshOffsets       index in x of vertex i's x coordinate in M (y at +1, z at +2)
  /// @param[in] unfoldingOffsets  the same for M′; as many as meshOffsets
  /// @throws std::invalid_argument on a count mismatch, a vertex index out of range or repeated
  ///         in a face, a negative offset, or overlapping vertex blocks (M and M′ together)
  CheckerboardIsometryTerm(std::string name, const std::vector<std::array<int, 4>>& faces,
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
