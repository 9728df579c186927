#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Term.h"
#include "devsurf/spline/Basis.h"
#include "devsurf/terms/ExtendedCurve.h"

namespace devsurf::terms {

/// Developability of sampled rulings C1(t_i)–C2(σ_i) of a parameter mapping (001_… eq. 8/9),
/// three rows per sample i:
///   N_i·C1′(t_i),   N_i·C2′(σ_i),   N_i·(C1(t_i) − C2(σ_i)),
/// where the mapped parameter is a quadratic form in the shape parameters ε (x[shapeOffset + k]):
///   σ_i = Σ_k S(i,k) ε_k².
/// With S(i,k) = Σ_{j≥k} B_{j,d}(t_i) this is eq. 5 (σ = Σ_j (Σ_{k≤j} ε_k²) B_{j,d}); with
/// S(i,k) = [k ≤ i] it is the discrete mapping T_i = Σ_{k≤i} α_k² of §3.1. Squared with weight
/// √λ1 the rows give λ1·F_Dvlp of eq. 9. C1 is fixed (its points and tangents at t_i are
/// constants); C2 is evaluated with its polynomial extension outside its domain.
class MappingDevelopabilityTerm final : public engine::Term {
 public:
  /// @param[in] shapeOffset    index in x of ε_0
  /// @param[in] tailWeights    S, K×(n+1) (K samples, n+1 shape parameters)
  /// @param[in] normalOffsets  K indices in x of N_i's x coordinate
  /// @param[in] c1Points       C1(t_i), K×3
  /// @param[in] c1Tangents     C1′(t_i), K×3
  /// @param[in] c2             the other curve
  /// @throws std::invalid_argument if the sizes disagree
  MappingDevelopabilityTerm(std::string name, int shapeOffset, spline::EvaluationMatrix tailWeights,
                            std::vector<int> normalOffsets, Eigen::MatrixX3d c1Points,
                            Eigen::MatrixX3d c1Tangents, std::shared_ptr<const ExtendedCurve> c2);

  int numResiduals() const override { return 3 * static_cast<int>(normalOffsets_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

  /// σ_i at x.
  double mappedParameter(const Eigen::VectorXd& x, int sample) const;

 private:
  int shapeOffset_;
  spline::EvaluationMatrix tailWeights_;
  std::vector<int> normalOffsets_;
  Eigen::MatrixX3d c1Points_, c1Tangents_;
  std::shared_ptr<const ExtendedCurve> c2_;
};

}  // namespace devsurf::terms
