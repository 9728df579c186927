#pragma once

#include <vector>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Second differences p_{i−1} − 2p_i + p_{i+1} of a control polygon whose 3D points live anywhere
/// in x (000_… §3.2, 003_… §5.2.6): an S edge's polygon starts and ends at vertex blocks and has its
/// interior points in the edge's own block, so terms::ControlPolygonFairnessTerm (one contiguous
/// range) does not fit. One row per interior point and coordinate; linear.
class PolygonFairnessTerm final : public engine::Term {
 public:
  /// @param[in] pointOffsets  index in x of each point's x coordinate, in polygon order (distinct)
  /// @throws std::invalid_argument if two consecutive stencil points coincide
  PolygonFairnessTerm(std::string name, std::vector<int> pointOffsets);

  int numResiduals() const override;
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  std::vector<int> points_;
};

}  // namespace devsurf::terms
