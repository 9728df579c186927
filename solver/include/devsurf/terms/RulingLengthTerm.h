#pragma once

#include <vector>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/Hinge.h"
#include "devsurf/terms/LinearPoints.h"

namespace devsurf::terms {

/// Degeneracy guard "no pinching" (ARCHITECTURE §8): the rulings r_k = b_k − a_k of a strip keep a
/// minimum length m_k. One row per guarded ruling, a hinge:
///   ρ_k = hinge(1 − |r_k|²/m_k²),
/// (hinge: terms::hingeResidual, zero for g ≤ 0 and a C¹ ramp above),
/// zero while the ruling is long enough, so the guard changes nothing until a ruling is about to
/// collapse — a collapse satisfies developability to first order (the twisted strip of
/// docs/architecture.md) and is what a pull that asks for stretching produces.
/// Hard; rulings with m_k = 0 (a degenerate ruling by design: a cone, an S R S face) get no row.
class RulingLengthTerm final : public engine::Term {
 public:
  /// @param[in] a, b        K points each (a: may have no nonzeros, then b holds b − a); the two
  ///                        must not share variables in one row
  /// @param[in] minLength   K minimum lengths m_k ≥ 0 (normalized units); m_k = 0: not guarded
  RulingLengthTerm(std::string name, LinearPoints a, LinearPoints b, std::vector<double> minLength);

  int numResiduals() const override { return static_cast<int>(rows_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

  /// The smallest |r_k| / m_k over the guarded rulings times `ratio` (m_k = ratio · reference
  /// length): the narrowest ruling against its reference; 1 with no guarded ruling.
  double lengthRatioMin(const Eigen::VectorXd& x, double ratio) const;

 private:
  LinearPoints a_, b_;
  std::vector<int> rows_;         ///< guarded ruling index k per row
  std::vector<double> inverseSquared_;  ///< 1/m_k² per row
};

}  // namespace devsurf::terms
