#pragma once

#include <vector>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/Hinge.h"

namespace devsurf::terms {

/// Degeneracy guard "a crease does not double back" (ARCHITECTURE §8): no two legs
/// d_i = p_{i+1} − p_i, d_j of a control polygon (an S edge from vertex to vertex, its points anywhere
/// in x) that are fewer than `window` legs apart point more than 90° apart. One row per such pair,
/// a hinge on the scaled inner product:
///   ρ_ij = hinge(−⟨d_i, d_j⟩ / (ℓ_i ℓ_j)),
/// (hinge: terms::hingeResidual, zero for g ≤ 0 and a C¹ ramp above),
/// with ℓ the legs' lengths in a reference state (the state the model was built from). A pair the
/// reference already has apart by more than 90° (by design) is not guarded.
/// With window = the curve's degree p, the p legs that make c′ on one span lie in one open half
/// space (pairwise positive inner products: their sum has a positive one with each), so c′ never
/// vanishes — no cusp, no curve folding back on itself; window = 2 guards consecutive legs only.
/// A polygon that turns back — the first interior control point of a crease solved behind its end
/// vertex, as a far pull does — makes a curve that folds back on itself (vertex curvature near π).
/// Hard; zero for every polygon that does not turn back.
class PolygonBacktrackTerm final : public engine::Term {
 public:
  /// @param[in] pointOffsets  index in x of each point's x coordinate, in polygon order (n ≥ 3,
  ///                          three consecutive ones distinct)
  /// @param[in] reference     the reference state of x (leg lengths; turns it already makes)
  /// @param[in] window        legs i, j with 0 < |i − j| < window are paired (≥ 2)
  /// @throws std::invalid_argument for fewer than 3 points or a stencil that repeats a point
  PolygonBacktrackTerm(std::string name, std::vector<int> pointOffsets, const Eigen::VectorXd& reference,
                       int window = 2);

  int numResiduals() const override;
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

  /// [crease_backtrack_max] max over consecutive legs of max(0, −cos θ), θ the turning angle
  /// between them: 0 unless the polygon turns by more than 90° somewhere, 1 for a full reversal.
  /// Zero-length legs are skipped.
  double backtrackMax(const Eigen::VectorXd& x) const;

 private:
  std::vector<int> points_;
  struct Pair {
    int i, j;  ///< legs (i < j): points i, i+1 and j, j+1
  };
  std::vector<Pair> rows_;           ///< guarded leg pairs
  std::vector<double> inverseLegs_;  ///< 1/(ℓ_i ℓ_j) per row
};

}  // namespace devsurf::terms
