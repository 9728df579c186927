#pragma once

#include <array>
#include <vector>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/Hinge.h"

namespace devsurf::terms {

/// Degeneracy guard "development faces keep their orientation" (ARCHITECTURE §8): triangles of a
/// planar mesh whose 2D vertices live in x keep a minimum signed area. One row per triangle, a
/// hinge
///   ρ_t = hinge(1 − A_t / m_t),   A_t = ½ (p1 − p0) × (p2 − p0),
/// (hinge: terms::hingeResidual, zero for g ≤ 0 and a C¹ ramp above),
/// zero while a triangle is counterclockwise with at least m_t. The isometry rows (eq. 12) see
/// only distances and cannot tell a face from its mirror image; this row can.
/// Hard; triangles with m_t ≤ 0 get no row.
class TriangleOrientationTerm final : public engine::Term {
 public:
  /// @param[in] offset     index in x of vertex 0's x coordinate (vertex k at offset + stride·k)
  /// @param[in] triangles  vertex indices, counterclockwise
  /// @param[in] minArea    one minimum signed area m_t per triangle (≤ 0: not guarded)
  /// @param[in] stride     scalars per vertex in x (2: a development's (x, y); 3: a quad mesh's
  ///                       unfolding stored as (x, y, z) with z held 0); ≥ 2
  TriangleOrientationTerm(std::string name, int offset, std::vector<std::array<int, 3>> triangles,
                          std::vector<double> minArea, int stride = 2);

  int numResiduals() const override { return static_cast<int>(triangles_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  int offset_;
  int stride_;
  std::vector<std::array<int, 3>> triangles_;  ///< guarded ones only
  std::vector<double> inverseMin_;             ///< 1/m_t
};

}  // namespace devsurf::terms
