#pragma once

#include <utility>
#include <vector>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/Hinge.h"
#include "devsurf/terms/LinearPoints.h"

namespace devsurf::terms {

/// Degeneracy guard "no pinching, no collapse" (ARCHITECTURE §8): the area element of a ruled
/// strip s(u, v) = (1 − v) a(u) + v b(u) along its rulings,
///   N_k = r_k × t_k,   r = b − a (the ruling),   t = a′ + b′,
/// keeps a minimum length m_k. One row per guarded parameter, a hinge:
///   ρ_k = hinge(1 − |N_k|²/m_k²),
/// (hinge: terms::hingeResidual, zero for g ≤ 0 and a C¹ ramp above). |N| vanishes when a ruling
/// shrinks, when the rulings turn into the curves' direction (the strip folds into a line: a
/// sideways pull on a crease's far boundary did this with every ruling still long, developability
/// trivially met and the warp angle undefined), and where the tangents vanish (a cusp) — all
/// states that satisfy the developability rows to first order and that a pull toward the
/// impossible produces. Hard; parameters with m_k = 0 get no row.
///
/// r and t are sums of signed point sets (r = b − a as {(a, −1), (b, +1)}, or one set holding
/// b − a; t = {(a′, +1), (b′, +1)}) that may share control points: each row merges their
/// coefficients per variable, so it lists every variable once.
class StripWidthTerm final : public engine::Term {
 public:
  using SignedPoints = std::pair<LinearPoints, double>;
  /// @param[in] ruling, tangent  signed point sets, each with K rows
  /// @param[in] minWidth         K minimum lengths of N (≤ 0: not guarded)
  StripWidthTerm(std::string name, std::vector<SignedPoints> ruling, std::vector<SignedPoints> tangent,
                 std::vector<double> minWidth);

  int numResiduals() const override { return static_cast<int>(inverseSquared_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

  /// |N_k| at x for every parameter of the constructor (guarded or not).
  static std::vector<double> widths(const std::vector<SignedPoints>& ruling, const std::vector<SignedPoints>& tangent,
                                    const Eigen::VectorXd& x);
  /// The smallest |N_k| / m_k over the guarded rows times `ratio` (m_k = ratio · reference): the
  /// narrowest the strip got against its reference; 1 with no guarded row.
  double widthRatioMin(const Eigen::VectorXd& x, double ratio) const;

 private:
  struct Entry {
    int offset;   ///< index in x of a 3D point
    double r, t;  ///< its coefficient in r and in t
  };
  // The guarded rows, stored flat (one pass over contiguous memory per evaluation): row i's
  // entries are entries_[rowStart_[i], rowStart_[i + 1]).
  std::vector<int> rowStart_{0};
  std::vector<Entry> entries_;
  std::vector<double> inverseSquared_;  ///< per row: 1/m_k²
};

}  // namespace devsurf::terms
