#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Term.h"
#include "devsurf/spatial/TriangleMeshProximity.h"
#include "devsurf/terms/ReferenceFootPoints.h"

namespace devsurf::terms {

/// Proximity to a reference triangle mesh Φ by tangent planes (004_… §2.3.2, E_prox,2): per point
/// one row ⟨n_i*, v_i − v_i*⟩, the signed distance of v_i from the plane of the triangle of Φ
/// holding its closest point v_i* (n_i* that triangle's unit normal, front side positive). Foot
/// points and planes are renewed in linearizeAt() and are constants within an iteration (the
/// Jacobian row is n_i*ᵀ); engine::checkJacobian calls linearizeAt() once first. Until the first
/// linearizeAt() every plane is z = 0. Units of length.
class ReferencePlaneDistanceTerm final : public engine::Term {
 public:
  /// @param[in] pointOffsets  index in x of each point's x coordinate (y at +1, z at +2)
  /// @param[in] reference     Φ (shared, immutable; may serve several terms)
  /// @throws std::invalid_argument on a null reference, a negative offset or overlapping blocks
  ReferencePlaneDistanceTerm(std::string name, std::vector<int> pointOffsets,
                             std::shared_ptr<const spatial::TriangleMeshProximity> reference);
  /// The same term on a foot-point set it may share with other terms at the same points (the
  /// closest points are then queried once per x for all of them).
  /// @param[in] feet  the points (their offsets in x) and Φ
  /// @throws std::invalid_argument on a null set or overlapping blocks
  ReferencePlaneDistanceTerm(std::string name, std::shared_ptr<ReferenceFootPoints> feet);

  int numResiduals() const override { return static_cast<int>(offsets_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  /// Foot points and planes of the points at x.
  void linearizeAt(const Eigen::VectorXd& x) override;
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

  /// Foot point and unit plane normal of point i from the last linearization.
  const Eigen::Vector3d& footPoint(int i) const { return feet_[i]; }
  const Eigen::Vector3d& normal(int i) const { return normals_[i]; }

 private:
  std::vector<int> offsets_;
  std::shared_ptr<ReferenceFootPoints> footPoints_;
  std::vector<Eigen::Vector3d> feet_, normals_;
};

}  // namespace devsurf::terms
