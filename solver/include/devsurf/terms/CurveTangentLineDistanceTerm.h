#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/LinearPoints.h"

namespace devsurf::terms {

/// Proximity of one curve to another, 000_… §4.2 ("Approximation with composite developables"):
/// samples v_k of a spline curve (linear in its control points, relation (5)) are kept on the
/// tangent lines T_k of a second curve at their closest points, "v_k ∈ T_k", linearized. The second
/// curve is given as a dense polyline (a neighbouring strip's boundary, held within the iteration);
/// the foot point f_k and its unit tangent t_k are renewed in linearizeAt().
///
/// Rows: per sample two, ⟨v_k − f_k, e₁⟩ and ⟨v_k − f_k, e₂⟩ with (t_k, e₁, e₂) orthonormal —
/// the distance from T_k. With `pinEnds` six more: v_0 − (first polyline point) and
/// v_{K−1} − (last polyline point), so the paired boundaries also end together (the composite they
/// initialize shares the whole edge, corners included). Units of length; linear within an iteration.
///
/// Tangents: a foot inside a segment takes the segment's direction; a foot on an interior polyline
/// point the normalized sum of the two adjacent directions; an end of the polyline its end segment
/// (the curve extended by its end tangent).
class CurveTangentLineDistanceTerm final : public engine::Term {
 public:
  /// @param[in] samples   points v_k on the constrained curve (rows of an evaluation matrix over its
  ///                      control-point block in x)
  /// @param[in] polyline  the other curve, ≥ 2 points in order, consecutive points distinct
  /// @param[in] pinEnds   add the rows holding the first and last sample at the polyline's ends
  /// @throws std::invalid_argument on no samples, too few polyline points, non-finite points or a
  ///         zero-length segment
  CurveTangentLineDistanceTerm(std::string name, LinearPoints samples, std::vector<Eigen::Vector3d> polyline,
                               bool pinEnds);

  int numResiduals() const override { return 2 * samples_.rows() + (pinEnds_ ? 6 : 0); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  /// Foot points and tangents of the samples at x.
  void linearizeAt(const Eigen::VectorXd& x) override;
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

  /// Closest point of the polyline to p and the unit tangent there (the rule above).
  void project(const Eigen::Vector3d& p, Eigen::Vector3d& foot, Eigen::Vector3d& tangent) const;
  /// Foot point of sample k from the last linearization.
  const Eigen::Vector3d& footPoint(int k) const { return feet_[static_cast<std::size_t>(k)]; }

 private:
  LinearPoints samples_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<Eigen::Vector3d> directions_;  ///< unit direction of each segment
  bool pinEnds_;
  std::vector<Eigen::Vector3d> feet_;
  std::vector<std::array<Eigen::Vector3d, 2>> across_;  ///< e₁, e₂ per sample
};

}  // namespace devsurf::terms
