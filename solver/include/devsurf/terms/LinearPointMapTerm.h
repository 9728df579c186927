#pragma once

#include <string>
#include <vector>

#include <Eigen/SparseCore>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Points that are a fixed linear map of other points: per mapped point i three rows
///   v_i − Σ_j W(i, j) c_j,
/// with v_i and c_j 3D points in x. Linear, units of length, a constant Jacobian (1 and −W(i, j)).
/// Ties the refined mesh S^k(M) of 004_… Algorithm 2 to its control mesh M (W = the subdivision
/// matrix of eq. 8), so that the quad-mesh terms act on S^k(M) while M stays the design.
class LinearPointMapTerm final : public engine::Term {
 public:
  /// @param[in] map             W: one row per mapped point, one column per source point; its
  ///                            structural nonzeros are the Jacobian's (explicit zeros are dropped)
  /// @param[in] mappedOffsets   index in x of mapped point i's x coordinate (y at +1, z at +2)
  /// @param[in] sourceOffsets   the same for source point j
  /// @throws std::invalid_argument on a size mismatch, a non-finite weight, a negative offset or
  ///         overlapping point blocks (mapped and source together)
  LinearPointMapTerm(std::string name, const Eigen::SparseMatrix<double, Eigen::RowMajor>& map,
                     std::vector<int> mappedOffsets, std::vector<int> sourceOffsets);

  int numResiduals() const override { return 3 * static_cast<int>(mapped_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  Eigen::SparseMatrix<double, Eigen::RowMajor> map_;
  std::vector<int> mapped_, source_;
};

}  // namespace devsurf::terms
