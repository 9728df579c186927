#pragma once

#include <array>
#include <string>
#include <vector>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Vertex normals of a quad mesh M as a Gauss image (004_… §2.2.1 eq. 3): the 'black'
/// parallelogram of every face of the normal mesh touches the unit sphere in the point n_f, i.e.
/// for a quad v0 v1 v2 v3 with vertex normals n0 … n3 four rows
///   c_norm,j = ⟨n_j + n_{j+1}, n_f⟩ − 2      (j = 0 … 3, indices mod 4),
/// where n_f = (v2 − v0) × (v3 − v1) / ‖…‖ is the unit normal of the parallelogram inscribed in
/// the face (front side: the face is counter-clockwise seen from there). A triangle v0 v1 v2
/// (`[3] = -1`) has three rows (j mod 3) with n_f = (v1 − v0) × (v2 − v0) / ‖…‖.
///
/// Dimensionless. n_f depends on the vertices: the Jacobian is full with respect to the face's
/// vertices and the two normals of each row. With the vertices fixed the rows are linear in the
/// normals. The normals are not unit vectors (they touch the sphere in edge midpoints).
/// \note A face whose diagonals are parallel (zero area) has no normal: its rows read −2 and have
///       zero derivatives (no NaN).
class GaussImageNormalTerm final : public engine::Term {
 public:
  /// @param[in] faces          vertex indices, counter-clockwise from the front; `[3] = -1` for a
  ///                           triangle
  /// @param[in] meshOffsets    index in x of vertex i's x coordinate in M (y at +1, z at +2)
  /// @param[in] normalOffsets  index in x of vertex i's normal (3 scalars), one per vertex
  /// @throws std::invalid_argument on a count mismatch, an index out of range, a repeated vertex
  ///         in a face, or a face whose vertex and normal variables overlap
  GaussImageNormalTerm(std::string name, std::vector<std::array<int, 4>> faces,
                       std::vector<int> meshOffsets, std::vector<int> normalOffsets);

  int numResiduals() const override { return numResiduals_; }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  std::vector<std::array<int, 4>> faces_;
  std::vector<int> meshOffsets_;
  std::vector<int> normalOffsets_;
  int numResiduals_ = 0;
};

}  // namespace devsurf::terms
