#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Term.h"
#include "devsurf/spline/KnotVector.h"
#include "devsurf/terms/StripFootPoints.h"

namespace devsurf::terms {

/// Distance of reference points from the strip's tangent planes, 000_… eq. (11): per reference
/// point q_j one row  ⟨s(u_j, v_j) − q_j, n(u_j)⟩ / |n(u_j)|,  which pushes the strip so that q_j
/// lies in its tangent plane at the foot point (and lets it slide along the target).
///
/// With a normal spline n(u) = Σ_k N_k(t) c_k (t = (u − u₀)/(u₁ − u₀), its control points a block
/// of x) the row depends on the curves' and the normal spline's control points, as in the paper;
/// it is differentiated with its normalization (a scale held per iteration would let the row
/// shrink with the normal). Without one (free normal vectors
/// at the evaluation parameters, which do not define n at arbitrary u) n(u_j) is the strip's unit
/// normal s_u × s_v at the foot point, held constant within an iteration: the variant of the
/// paper's Fig. 16 ("n(u_j) in (11) considered fixed in each iteration").
///
/// A point whose foot lies on the strip's boundary (v_j ∈ {0, 1}, or u_j at an end of open
/// curves) lies beyond the strip, and its distance from the tangent plane there says little: a
/// strip sliding off the region kept such rows near zero (on a curved target it drifted away over
/// tens of iterations). Its row is half the distance itself, ½⟨s − q_j, ĝ_j⟩ with the gap's
/// direction ĝ_j held per iteration, which pulls the boundary outward: the strip grows to cover
/// the region (issue 15). Units of length.
class StripTangentPlaneDistanceTerm final : public engine::Term {
 public:
  /// A normal spline as a block of x: its knots on [0, 1] and the index of control point 0.
  struct NormalSpline {
    spline::KnotVector knots;
    int offset = 0;
  };

  /// @param[in] feet     the shared projection
  /// @param[in] normals  the strip's normal spline, or nullopt for normals held per iteration
  /// @param[in] domain   the curves' parameter domain [u₀, u₁] (maps u to the spline's t)
  /// @throws std::invalid_argument on a null projection or an empty domain
  StripTangentPlaneDistanceTerm(std::string name, std::shared_ptr<StripFootPoints> feet,
                                std::optional<NormalSpline> normals, double u0, double u1);

  int numResiduals() const override { return feet_->count(); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  void linearizeAt(const Eigen::VectorXd& x) override;
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  std::shared_ptr<StripFootPoints> feet_;
  std::optional<NormalSpline> spline_;
  double u0_ = 0.0, u1_ = 1.0;
  int normalCount_ = 0;
  std::vector<double> normalBasis_;         ///< N_k(t_j), dense (spline normals)
  std::vector<Eigen::Vector3d> heldNormal_; ///< unit normal at the foot (held normals)
  std::vector<Eigen::Vector3d> heldGap_;    ///< unit gap direction of points beyond the boundary
  std::vector<char> outside_;               ///< the foot is on the boundary, the gap not normal
};

}  // namespace devsurf::terms
