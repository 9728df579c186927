#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/StripFootPoints.h"

namespace devsurf::terms {

/// Tangency of a ruled strip to the reference, 000_… eq. (10): per reference point q_j with
/// normal m_j two rows
///   ⟨m_j, a(u_j) − b(u_j)⟩ / |a − b|,   ⟨m_j, a′(u_j)⟩ / |a′|,
/// the ruling and the tangent of a at the foot parameter u_j lie in the reference's tangent plane.
/// u_j is renewed in linearizeAt() and held within an iteration. The rows are the cosines of the
/// angles with m_j, differentiated with their normalization: with the 1/|·| scales held constant
/// instead (as for the developability rows, 003_… §5.2.1) a row shrinks with its vector, and the
/// solver narrowed the strip's rulings to satisfy eq. (10) on doubly curved targets. Dimensionless.
class StripReferenceTangencyTerm final : public engine::Term {
 public:
  /// @param[in] normals  m_j, one unit vector per reference point of `feet` (N×3)
  /// @throws std::invalid_argument on a null projection, a count mismatch or a zero normal
  StripReferenceTangencyTerm(std::string name, std::shared_ptr<StripFootPoints> feet, Eigen::MatrixX3d normals);

  int numResiduals() const override { return 2 * feet_->count(); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  void linearizeAt(const Eigen::VectorXd& x) override;
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  std::shared_ptr<StripFootPoints> feet_;
  Eigen::MatrixX3d normals_;
};

}  // namespace devsurf::terms
