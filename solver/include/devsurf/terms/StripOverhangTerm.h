#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Term.h"
#include "devsurf/spline/KnotVector.h"

namespace devsurf::spatial {
struct MatrixRows;
}  // namespace devsurf::spatial

namespace devsurf::terms {

/// The part of a ruled strip s(u, v) = (1 − v) a(u) + v b(u) that overhangs its reference points,
/// pulled back towards them. 000_… eq. (9)–(11) measure from the reference to the strip only
/// ("the strip grows so as to cover as much of the reference shape as possible", Fig. 11), so a
/// strip over a doubly curved or bounded region spreads beyond it where no point holds it (a flap).
/// This term measures the other way: at fixed samples (u_k, v_k) of the strip, the nearest reference
/// point q_k (renewed in linearizeAt, a k-d tree over the points) and d_k = s(u_k, v_k) − q_k; three
/// rows d_k·(1 − ρ/|d_k|) where |d_k| > ρ and zero rows within the reach ρ — the gradient of
/// ½ max(0, |d_k| − ρ)², continuous in d. Over the reference (within ρ of a point) the rows rest;
/// beyond it they pull the sample back to ρ from the nearest point. Units of length.
class StripOverhangTerm final : public engine::Term {
 public:
  /// @param[in] knots     the common knot vector of a and b (n control points)
  /// @param[in] weights   NURBS weights (n) or empty; held constant
  /// @param[in] offsetA   index in x of a's control point 0, coordinate x (b at offsetB)
  /// @param[in] points    reference points, N×3 (the coordinates of x)
  /// @param[in] reach     ρ > 0: a sample this close to a point rests (about the points' spacing)
  /// @param[in] samplesU  samples along the strip (≥ 2), at equal steps of u over the domain
  /// @param[in] samplesV  samples across it (≥ 2), v = 0 … 1
  /// @throws std::invalid_argument on no or non-finite points, ρ ≤ 0, too few samples or wrong weights
  StripOverhangTerm(std::string name, const spline::KnotVector& knots, Eigen::VectorXd weights, int offsetA,
                    int offsetB, Eigen::MatrixX3d points, double reach, int samplesU, int samplesV);
  ~StripOverhangTerm() override;

  int numResiduals() const override { return 3 * static_cast<int>(v_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  /// Finds the nearest reference point of every sample at x.
  void linearizeAt(const Eigen::VectorXd& x) override;
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

  /// The sample's point s(u_k, v_k) at x.
  Eigen::Vector3d samplePoint(const Eigen::VectorXd& x, int k) const;
  /// The nearest reference point found for sample k by the last linearizeAt.
  Eigen::Vector3d nearest(int k) const { return nearest_.row(k).transpose(); }
  int samples() const { return static_cast<int>(v_.size()); }

 private:
  struct Index;
  int n_ = 0, offsetA_ = 0, offsetB_ = 0;
  double reach_ = 0.0;
  Eigen::MatrixX3d points_;
  std::unique_ptr<Index> index_;
  int support_ = 0;             ///< control points a sample depends on (degree + 1)
  std::vector<double> v_;       ///< v_k
  std::vector<int> supportIndex_;   ///< samples × support: the control points of sample k
  std::vector<double> basis_;   ///< samples × support: R_i(u_k) of those control points
  Eigen::MatrixX3d nearest_;    ///< q_k
};

}  // namespace devsurf::terms
