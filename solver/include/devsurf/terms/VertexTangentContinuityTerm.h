#pragma once

#include <string>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Tangent continuity of two curves through a shared vertex (000_… §3.1, "tangent continuity at
/// shared vertices when asked"): with v the vertex and a, b the control points next to it on the
/// two curves (their first control-polygon legs are the end tangents), three rows
///   (a − v) × (b − v),
/// zero when v, a, b are collinear. Bilinear, units of length². Which of the two collinear
/// configurations (a straight pass-through or a cusp) holds is decided by the start.
class VertexTangentContinuityTerm final : public engine::Term {
 public:
  /// @param[in] vertexOffset, aOffset, bOffset  index in x of v, a, b (3 scalars each)
  /// @throws std::invalid_argument if two of the points share variables
  VertexTangentContinuityTerm(std::string name, int vertexOffset, int aOffset, int bOffset);

  int numResiduals() const override { return 3; }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  int v_, a_, b_;
};

}  // namespace devsurf::terms
