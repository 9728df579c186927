#pragma once

#include <array>
#include <string>
#include <vector>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Symmetry of the discrete shape operator of a quad (004_… §2.2.1 eq. 5): orthogonal principal
/// directions. For a quad v0 v1 v2 v3 with vertex normals n0 … n3 one row
///   c_sym = ⟨n3 − n1, v2 − v0⟩ − ⟨v3 − v1, n2 − n0⟩.
/// Triangles (`[3] = -1`) have no row. Units of length (normals are dimensionless); bilinear in
/// vertices and normals, linear in the normals when the vertices are fixed.
class ShapeOperatorSymmetryTerm final : public engine::Term {
 public:
  /// @param[in] faces          vertex indices, counter-clockwise from the front; `[3] = -1` for a
  ///                           triangle (no row)
  /// @param[in] meshOffsets    index in x of vertex i's x coordinate in M (y at +1, z at +2)
  /// @param[in] normalOffsets  index in x of vertex i's normal (3 scalars), one per vertex
  /// @throws std::invalid_argument on a count mismatch, an index out of range, a repeated vertex
  ///         in a quad, or a quad whose vertex and normal variables overlap
  ShapeOperatorSymmetryTerm(std::string name, std::vector<std::array<int, 4>> faces,
                            std::vector<int> meshOffsets, std::vector<int> normalOffsets);

  int numResiduals() const override { return static_cast<int>(quads_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  std::vector<std::array<int, 4>> quads_;  ///< the quads among the faces, in order
  std::vector<int> meshOffsets_;
  std::vector<int> normalOffsets_;
};

}  // namespace devsurf::terms
