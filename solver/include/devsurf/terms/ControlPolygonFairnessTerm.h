#pragma once

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Fairness of a control polygon (000_… §3.2, 003_… §5.2.6): second differences
/// p_{i−1} − 2p_i + p_{i+1} for every interior point (every point of a closed polygon), one row
/// per coordinate. Linear; the solver's schedule gives it the decaying weight ε_fair·decay^k.
class ControlPolygonFairnessTerm final : public engine::Term {
 public:
  /// @param[in] offset     index in x of point 0, coordinate 0
  /// @param[in] numPoints  points in the polygon
  /// @param[in] dimension  coordinates per point (3 for curves, 2 for developed polylines)
  /// @param[in] closed     wrap around (periodic curve)
  ControlPolygonFairnessTerm(std::string name, int offset, int numPoints, int dimension = 3,
                             bool closed = false);

  int numResiduals() const override { return rowsPerCoordinate() * dimension_; }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  int rowsPerCoordinate() const;
  /// Point indices (i−1, i, i+1) of second difference number s.
  void stencil(int s, int& prev, int& mid, int& next) const;
  int offset_, numPoints_, dimension_;
  bool closed_;
};

}  // namespace devsurf::terms
