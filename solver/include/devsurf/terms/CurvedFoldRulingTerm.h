#pragma once

#include <array>
#include <string>
#include <vector>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/CurvedFoldTerm.h"
#include "devsurf/terms/LinearPoints.h"

namespace devsurf::terms {

/// Crease condition of CurvedFoldTerm (000_… §3.3 eqs. 7/8) with the two faces' normals taken
/// from the geometry instead of from free normal variables: for every evaluation parameter u_k
/// one row
///   m_k s ⟨a″(u_k), o1_k ĝ1_k ± o2_k ĝ2_k⟩,   ĝi = (a′ × d_i) / |a′ × d_i|,
/// where a is the crease, d_i(u_k) a vector across face i from the crease (the composite passes
/// its ruling b − a at u_k) and o_i,k = ±1 orients ĝi like face i's normal. The tangent
/// plane of a ruled surface along a is spanned by a′ and the ruling, so ĝi is face i's unit normal
/// at the crease; ⟨a′, ĝi⟩ ≡ 0 and CurvedFoldTerm's tangent row has no counterpart here.
///
/// Why: CurvedFoldTerm's rows couple the free normals of the two faces at every sample, which
/// chains the normals of one sample across all strips of a sheet and keeps them in the
/// factorized system (issue 17, architecture "Growth of the iteration", stop 40). These rows use
/// control points only — the crease's and each face's other curve — so every face's free normals
/// are coupled to their own face alone and the assembler eliminates them per sample, as a strip's.
///
/// - s_k = 1 / (|a′(u_k)|² max(κ_k, κ_ref)), κ_k the crease's curvature at u_k and κ_ref its 90th
///   percentile over the parameters, is refreshed at every linearization and held within an
///   iteration; 1 where that vanishes (a straight crease imposes nothing beyond both faces'
///   developability). As ĝi ⟂ a′, the row is ⟨N_k, o1 ĝ1 ± o2 ĝ2⟩ (N the crease's principal
///   normal) where the crease is as curved as κ_ref or more, and that times κ_k / κ_ref where it
///   straightens. CurvedFoldTerm's 1/|a″| (003_… §5.2.4) keeps the row ⟨N, …⟩ everywhere, whose
///   direction N is undefined where the crease straightens; with free normals such a row moves the
///   normals, here only the crease (a drawn sheet's drag stalled near a crease's flat end). A
///   percentile rather than the largest curvature: after a group of vertices was turned, a kinked
///   crease end made the largest curvature huge, every other row tiny, and the solve wandered off
///   (strips at their width guard, the handles not reached).
/// - m_k are optional constant row multipliers (softeningWeight of 003_… §5.5).
/// - A row whose a′ × d_i vanishes for a side (degenerate geometry, which the model's guards keep
///   away) is 0 with a zero Jacobian rather than undefined.
/// Non-polynomial (ĝ is normalized); the Jacobian is exact.
class CurvedFoldRulingTerm final : public engine::Term {
 public:
  using Mode = CurvedFoldTerm::Mode;

  /// @param[in] da, dda  a′(u_k), a″(u_k) as linear functions of control points (K rows each)
  /// @param[in] across1, across2  d_1, d_2 (K rows each), linear in control points; any of the four
  ///            may share control points with the others (entries of one point are merged)
  /// @param[in] orientation1, orientation2  o_1,k and o_2,k: K values, each +1 or −1
  /// @param[in] rowMultipliers  empty (all 1) or K constants m_k
  /// @throws std::invalid_argument on mismatched row counts or an orientation other than ±1
  CurvedFoldRulingTerm(std::string name, const LinearPoints& da, const LinearPoints& dda, const LinearPoints& across1,
                       const LinearPoints& across2, std::vector<double> orientation1,
                       std::vector<double> orientation2, Mode mode = Mode::CurvedFold,
                       std::vector<double> rowMultipliers = {});

  int numResiduals() const override { return count_; }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  void linearizeAt(const Eigen::VectorXd& x) override;
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

  Mode mode() const { return mode_; }
  /// s of the last linearization, per parameter (without m_k).
  const std::vector<double>& rowScales() const { return scales_; }
  /// The constant multipliers m_k (K values).
  const std::vector<double>& rowMultipliers() const { return multipliers_; }

 private:
  /// One control point of a row: x index of its x coordinate and its weights in a′, a″, d_1, d_2.
  struct RowPoint {
    int variable = 0;
    std::array<double, 4> weight{};
  };
  /// a′, a″, d_1, d_2 of row k at x.
  std::array<Eigen::Vector3d, 4> vectorsAt(const Eigen::VectorXd& x, int k) const;

  /// A nonzero weight of one of the four vectors: x index of the point's x coordinate, weight.
  struct SetEntry {
    int variable = 0;
    double weight = 0.0;
  };
  /// Vector s ∈ {a′, a″, d_1, d_2} of row k: setEntries_[setStart_[4k + s] … setStart_[4k + s + 1]).
  Eigen::Vector3d vectorAt(const Eigen::VectorXd& x, int k, int s) const;

  int count_ = 0;
  std::vector<int> rowStart_;  ///< K + 1 offsets into points_
  std::vector<int> setStart_;  ///< 4K + 1 offsets into setEntries_
  std::vector<SetEntry> setEntries_;
  std::vector<RowPoint> points_;
  std::vector<double> orientation1_, orientation2_;
  Mode mode_;
  std::vector<double> multipliers_;
  std::vector<double> scales_;
  std::vector<double> curvatureScratch_, sortedScratch_;  ///< linearizeAt's, per parameter
  static constexpr double kReferenceQuantile = 0.9;
};

}  // namespace devsurf::terms
