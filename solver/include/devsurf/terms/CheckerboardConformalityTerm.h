#pragma once

#include <array>
#include <string>
#include <vector>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/VertexProductRows.h"

namespace devsurf::terms {

/// Checkerboard conformality between M and M′ (004_… §2.1 eq. 2): the midpoint parallelogram of
/// a face of M′ is similar to that of M, its squared lengths scaled by the face's conformal
/// factor λ_f = x[factorOffset + f] (a variable). Per quad, with d0 = v0 − v2, d1 = v1 − v3,
///   λ_f ‖d0‖² − ‖d0′‖²,   λ_f ‖d1‖² − ‖d1′‖²,   λ_f ⟨d0, d1⟩ − ⟨d0′, d1′⟩;
/// per triangle λ_f ‖v_a − v_b‖² − ‖v_a′ − v_b′‖² over the edges (0,1), (1,2), (2,0).
/// Three rows per face, face by face; cubic in the variables, units of length². Pair it with
/// ConformalFactorTerm (E_λ) as the paper does. Conventions as CheckerboardIsometryTerm.
class CheckerboardConformalityTerm final : public engine::Term {
 public:
  /// @param[in] faces             vertex indices counter-clockwise; [3] = −1 for a triangle
  /// @param[in] meshOffsets       index in x of vertex i's x coordinate in M (y at +1, z at +2)
  /// @param[in] unfoldingOffsets  the same for M′; as many as meshOffsets
  /// @param[in] factorOffset      λ_f at x[factorOffset + f], one per face
  /// @throws std::invalid_argument on a count mismatch, a vertex index out of range or repeated
  ///         in a face, a negative offset, or overlapping blocks (vertices of M, of M′, factors)
  CheckerboardConformalityTerm(std::string name, const std::vector<std::array<int, 4>>& faces,
                               const std::vector<int>& meshOffsets,
                               const std::vector<int>& unfoldingOffsets, int factorOffset);

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
