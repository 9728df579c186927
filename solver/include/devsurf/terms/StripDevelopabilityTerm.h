#pragma once

#include <vector>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/LinearPoints.h"

namespace devsurf::terms {

/// Developability of the ruled surface s(u,v) = (1−v)a(u) + v b(u) through normals
/// (000_… eq. 3, 003_… §5.2.1): for every evaluation parameter u_k three rows
///   s₁ ⟨b(u_k) − a(u_k), n_k⟩,   s₂ ⟨a′(u_k), n_k⟩,   s₃ ⟨b′(u_k), n_k⟩,
/// quadratic in the unknowns. The row scales s₁ = 1/|b−a|, s₂ = 1/|a′|, s₃ = 1/|b′| are refreshed
/// at every linearization and held constant within an iteration (003_… §5.2.1).
/// Enforced at 3m−2 parameters per span of degree-m curves the rows vanish iff the surface is
/// developable (000_… §2.1); the model chooses the parameters.
/// \note Normals are unconstrained in length here; UnitNormalTerm keeps them away from zero.
class StripDevelopabilityTerm final : public engine::Term {
 public:
  /// @param[in] a, da  a(u_k) and a′(u_k) as linear functions of a's control points (K rows each)
  /// @param[in] b, db  b(u_k) and b′(u_k) (K rows each)
  /// @param[in] normals  n_k (K rows): free vectors (identity) or a normal spline's evaluation
  StripDevelopabilityTerm(std::string name, LinearPoints a, LinearPoints da, LinearPoints b,
                          LinearPoints db, LinearPoints normals);

  int numResiduals() const override { return 3 * count_; }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  void linearizeAt(const Eigen::VectorXd& x) override;
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

  /// Row scales (3 per parameter) of the last linearization.
  const std::vector<double>& rowScales() const { return scales_; }

 private:
  int count_ = 0;
  LinearPoints a_, da_, b_, db_, n_;
  std::vector<double> scales_;
};

}  // namespace devsurf::terms
