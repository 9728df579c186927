#pragma once

#include <utility>
#include <vector>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/LinearPoints.h"

namespace devsurf::terms {

/// Isometric development of a sampled mesh (000_… §5 eq. 12, 003_… §5.2.5): for every pair
/// (i, j) of mesh vertices one row
///   ‖v_i − v_j‖² − ‖v̄_i − v̄_j‖²,
/// where v_i is a 3D point linear in control points (a spline evaluation) and v̄_i the vertex's
/// 2D image in the development (two variables). Quadratic, unscaled (units of length²). The
/// pairs are the edges and diagonals of the mesh faces (gridEdgeAndDiagonalPairs for U×V grids).
///
/// Vertex numbering: the 3D vertices are the rows of `spatial[0]`, then the rows of `spatial[1]`,
/// … (e.g. {a(u_0..u_{U−1}), b(u_0..u_{U−1})} for a strip sampled along both boundaries).
/// Two vertices may depend on the same control points (neighbouring samples of one curve): their
/// coefficients are merged, so every row lists each variable once.
/// \note Fixed development vertices (the corners in 003_… §5.2.5) are fixed in the layout.
class EdgeIsometryTerm final : public engine::Term {
 public:
  /// @param[in] spatial           3D vertices as linear point sets, concatenated in order
  /// @param[in] developedOffsets  index in x of each vertex's 2D image (x̄ at o, ȳ at o+1); one
  ///                              per 3D vertex
  /// @param[in] pairs             vertex index pairs (i ≠ j), one row each
  /// @throws std::invalid_argument on a count mismatch, an index out of range, i = j, or a row
  ///         whose 3D and 2D variables overlap
  EdgeIsometryTerm(std::string name, std::vector<LinearPoints> spatial,
                   std::vector<int> developedOffsets, std::vector<std::pair<int, int>> pairs);
  /// One point set holding all 3D vertices.
  EdgeIsometryTerm(std::string name, LinearPoints spatial, std::vector<int> developedOffsets,
                   std::vector<std::pair<int, int>> pairs);

  int numResiduals() const override { return static_cast<int>(rows_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  /// v_i − v_j = Σ coefficient · x[base .. base+2];  v̄_i − v̄_j = Σ coefficient · x[base, base+1].
  struct Row {
    std::vector<std::pair<int, double>> spatial;
    std::vector<std::pair<int, double>> developed;
  };
  std::vector<Row> rows_;
};

/// Vertex pairs of the faces of a U×V grid of samples (vertex (i, j) ↦ index j·U + i, i < U,
/// j < V): every edge along u and along v, and both diagonals of every quad, each pair once.
/// For a strip sampled at U parameters along a and b use V = 2 (indices of a first, then b).
/// @throws std::invalid_argument if U < 1 or V < 1
std::vector<std::pair<int, int>> gridEdgeAndDiagonalPairs(int U, int V);

}  // namespace devsurf::terms
