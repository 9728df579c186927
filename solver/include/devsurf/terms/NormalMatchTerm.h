#pragma once

#include <utility>
#include <vector>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/LinearPoints.h"

namespace devsurf::terms {

/// Smooth (tangent-plane continuous) transition across a shared ruling (000_… §3.1): the unit
/// normals of the two adjacent surfaces agree, n1_k − σ n2_k = 0, three rows (x, y, z) per pair.
/// Linear; σ = +1 for consistently oriented normals, −1 where one surface's orientation is
/// reversed. With normal splines, n1 and n2 are the splines evaluated at the shared ruling's
/// parameters; the normals must be unit (UnitNormalTerm) for equality to mean "same plane".
/// \note Rows couple n1 and n2, so their blocks cannot be Schur-eliminated as separate groups.
class NormalMatchTerm final : public engine::Term {
 public:
  enum class Orientation { Same, Opposite };

  /// @param[in] n1, n2  K normals each (free vectors or normal-spline evaluations); n1 and n2
  ///                    may share variables (coefficients of a shared variable are merged)
  /// @throws std::invalid_argument on mismatched row counts
  NormalMatchTerm(std::string name, LinearPoints n1, LinearPoints n2,
                  Orientation orientation = Orientation::Same);

  int numResiduals() const override { return 3 * count_; }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  int count_ = 0;
  /// Per row: (variable, coefficient), the merged constant Jacobian of that row.
  std::vector<std::vector<std::pair<int, double>>> rows_;
};

}  // namespace devsurf::terms
