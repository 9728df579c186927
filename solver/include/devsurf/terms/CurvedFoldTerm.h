#pragma once

#include <vector>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/LinearPoints.h"

namespace devsurf::terms {

/// Crease condition between the two strips meeting along a crease a(u) (000_… §3.3 eqs. 7/8,
/// 003_… §5.2.4 in derivative form): for every evaluation parameter u_k two rows
///   m_k s₁ ⟨a′(u_k), n1_k ± n2_k⟩,   m_k s₂ ⟨a″(u_k), n1_k ± n2_k⟩,
/// with + for a curved fold (eq. 7: the crease unfolds to one planar curve on both sides) and −
/// for the geodesic property (eq. 8: the two developed boundaries are mirror images). Quadratic.
///
/// - s₁ = 1/|a′(u_k)|, s₂ = 1/|a″(u_k)| are row normalizations refreshed at every linearization
///   and held constant within an iteration (003_… §5.2.4); 1 where the vector vanishes (a straight
///   crease has a″ ≡ 0 and its second row is identically zero).
/// - m_k are optional per-parameter row multipliers fixed at construction, e.g. softeningWeight()
///   of 003_… §5.5 near ruling boundaries. They are a constant row scale, not a weight: the
///   assembler applies the term's weight on top of them.
///
/// a′, a″ may be any two vectors linear in the control points that span the osculating plane,
/// e.g. the de Boor differences c₀⁽²⁾ − c₁⁽²⁾, c₁⁽²⁾ − c₂⁽²⁾ of 000_… eq. 7.
/// \note The condition is meaningful only for unit normals of equal length (003_… §5.2.4);
///       UnitNormalTerm keeps them unit. The rows couple n1 and n2, so their blocks cannot be
///       Schur-eliminated as separate per-parameter groups.
class CurvedFoldTerm final : public engine::Term {
 public:
  enum class Mode {
    CurvedFold,  ///< n1 + n2 normal to the osculating plane (000_… eq. 7)
    Geodesic,    ///< n1 − n2 normal to the osculating plane (000_… eq. 8)
  };

  /// @param[in] da, dda  a′(u_k), a″(u_k) as linear functions of the crease's control points
  ///                     (K rows each)
  /// @param[in] n1, n2   unit normals of the two adjacent strips at u_k (K rows each): free
  ///                     vectors (identity) or normal-spline evaluations
  /// @param[in] rowMultipliers  empty (all 1) or K constants m_k
  /// @throws std::invalid_argument on mismatched row counts, or if a row would list a variable
  ///         twice (the crease and the two normals must use distinct variables)
  CurvedFoldTerm(std::string name, LinearPoints da, LinearPoints dda, LinearPoints n1,
                 LinearPoints n2, Mode mode = Mode::CurvedFold,
                 std::vector<double> rowMultipliers = {});

  int numResiduals() const override { return 2 * count_; }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  void linearizeAt(const Eigen::VectorXd& x) override;
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

  Mode mode() const { return mode_; }
  /// Normalizations s₁, s₂ (2 per parameter) of the last linearization, without m_k.
  const std::vector<double>& rowScales() const { return scales_; }
  /// The constant multipliers m_k (K values).
  const std::vector<double>& rowMultipliers() const { return multipliers_; }

 private:
  int count_ = 0;
  LinearPoints da_, dda_, n1_, n2_;
  Mode mode_;
  std::vector<double> multipliers_;
  std::vector<double> scales_;
};

}  // namespace devsurf::terms
