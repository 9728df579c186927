#pragma once

#include <vector>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/LinearPoints.h"

namespace devsurf::terms {

/// Straight unfolding of a strip boundary a(u) (000_… §3.3): a has zero geodesic curvature on
/// the strip iff its osculating plane is orthogonal to the strip's tangent plane. With an
/// auxiliary normal n_osc of the osculating plane, for every evaluation parameter u_k three rows
///   s₁ ⟨a′(u_k), n_osc,k⟩,   s₂ ⟨a″(u_k), n_osc,k⟩,   ⟨n_left,k, n_osc,k⟩,
/// quadratic. s₁ = 1/|a′|, s₂ = 1/|a″| are refreshed at every linearization and held constant
/// within an iteration (as in CurvedFoldTerm; 1 where the vector vanishes).
/// \note n_osc = 0 solves all rows: register UnitNormalTerm on the n_osc variables. The third
///       row couples n_osc with the strip's normal, so n_osc and n_left cannot be Schur-eliminated
///       as separate groups.
class StraightUnfoldingTerm final : public engine::Term {
 public:
  /// @param[in] da, dda   a′(u_k), a″(u_k) of the boundary's control points (K rows each)
  /// @param[in] nLeft     unit normals of the strip at u_k (K rows): free vectors or a normal
  ///                      spline's evaluation
  /// @param[in] nOsc      the auxiliary osculating-plane normals, usually free vectors
  ///                      (LinearPoints::identity(K, offset): 3 variables per parameter)
  /// @throws std::invalid_argument on mismatched row counts or shared variables within a row
  StraightUnfoldingTerm(std::string name, LinearPoints da, LinearPoints dda, LinearPoints nLeft,
                        LinearPoints nOsc);

  int numResiduals() const override { return 3 * count_; }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  void linearizeAt(const Eigen::VectorXd& x) override;
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

  /// s₁, s₂ (2 per parameter) of the last linearization.
  const std::vector<double>& rowScales() const { return scales_; }

 private:
  int count_ = 0;
  LinearPoints da_, dda_, left_, osc_;
  std::vector<double> scales_;
};

}  // namespace devsurf::terms
