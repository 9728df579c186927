#pragma once

#include <vector>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Developability around a vertex where creases meet (000_… §5 "Local developability in
/// vertices"): the angles between successive edges of the vertex's star sum to 2π. One row
///   Σ_i ∠(v_i − v, v_{i+1} − v) − Θ,
/// with ∠(a, b) = atan2(|a × b|, a · b) ∈ [0, π]. For a closed star (interior vertex) i runs over
/// all n neighbours cyclically and Θ defaults to 2π (zero Gauss curvature); for an open star
/// (boundary vertex) i runs over the n − 1 consecutive pairs and Θ is the prescribed angle sum of
/// the development (e.g. the interior angle of the domain's corner). Nonlinear, in radians.
/// In the paper's setup v is a crease's end control point c₀ and v_i the control points c₁ of the
/// creases and boundary curves meeting there (their initial tangents).
/// \note The derivative of an angle is undefined where its two edges are parallel (∠ = 0 or π)
///       or one of them has zero length; there that angle contributes a zero gradient.
class VertexAngleSumTerm final : public engine::Term {
 public:
  enum class Star {
    Closed,  ///< interior vertex: angles v_n–v–v_1 included
    Open,    ///< boundary vertex: angles between consecutive neighbours only
  };

  /// @param[in] centerOffset       index in x of v
  /// @param[in] neighbourOffsets   index in x of v_1 … v_n, in circular order (n ≥ 2; ≥ 3 closed)
  /// @param[in] angleSum           Θ (2π for an intrinsically flat interior vertex)
  /// @throws std::invalid_argument for too few neighbours or overlapping variables
  VertexAngleSumTerm(std::string name, int centerOffset, std::vector<int> neighbourOffsets,
                     Star star = Star::Closed, double angleSum = 2.0 * 3.14159265358979323846);

  int numResiduals() const override { return 1; }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

  /// Current sum of the star's angles (without −Θ).
  double angleSum(const Eigen::VectorXd& x) const;

 private:
  int numAngles() const;
  int center_;
  std::vector<int> neighbours_;
  Star star_;
  double target_;
};

}  // namespace devsurf::terms
