#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Rows that compare an inner product of vertex differences on a mesh M with the same inner
/// product on a combinatorially equivalent mesh M′ (the checkerboard isometry and conformality
/// conditions of 004_… eq. 1–2 and the mapping regularizer E_map of §2.3.3):
///   r = λ · ⟨Σ_k α_k v_k, Σ_k β_k v_k⟩ − ⟨Σ_k α_k v′_k, Σ_k β_k v′_k⟩,
/// with λ = 1 or a variable x[factor]. v_k and v′_k are 3D points at x[meshOffset .. +2] and
/// x[unfoldingOffset .. +2]. A row involves at most four distinct vertices; the Jacobian lists, in
/// order, the 3 coordinates of each v_k, then of each v′_k, then λ (if variable).
/// Shared machinery of CheckerboardIsometryTerm, CheckerboardConformalityTerm and
/// MappingRegularityTerm; evaluation allocates nothing.
class VertexProductRows {
 public:
  /// Appends a row. `vertices` are vertex indices (into the offset lists); a vertex listed twice
  /// has its coefficients merged. `factorOffset` < 0 means λ = 1.
  /// @throws std::invalid_argument (message prefixed by `who`) on a vertex index out of range or
  ///         more than four distinct vertices
  void add(const std::string& who, const int* vertices, const double* alpha, const double* beta,
           int count, const std::vector<int>& meshOffsets,
           const std::vector<int>& unfoldingOffsets, int factorOffset = -1);

  int size() const { return static_cast<int>(rows_.size()); }
  /// Structural nonzeros of all rows, rows numbered from 0.
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const;
  /// Writes size() residuals and (unless null) the Jacobian values in jacobianStructure() order.
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const;

 private:
  struct Row {
    int count = 0;
    std::array<int, 4> mesh{}, unfolding{};
    std::array<double, 4> alpha{}, beta{};
    int factor = -1;
  };
  std::vector<Row> rows_;
};

/// Appends the three rows of one face of M ↔ M′ (004_… eq. 1, or eq. 2 with λ = x[factorOffset]):
/// a quad [v0, v1, v2, v3] with diagonals d0 = v0 − v2, d1 = v1 − v3 gives ‖d0‖², ‖d1‖², ⟨d0, d1⟩
/// compared; a triangle [v0, v1, v2, −1] gives ‖v0 − v1‖², ‖v1 − v2‖², ‖v2 − v0‖² compared (its
/// midpoint triangle is congruent resp. similar). The face must have passed requireValidFaces.
void addCheckerboardFaceRows(VertexProductRows& rows, const std::string& who,
                             const std::array<int, 4>& face, const std::vector<int>& meshOffsets,
                             const std::vector<int>& unfoldingOffsets, int factorOffset = -1);

/// Checks faces of 3 or 4 vertex indices ([3] = −1 for a triangle): indices in [0, vertexCount),
/// no vertex twice in a face.
/// @throws std::invalid_argument (message prefixed by `who`, naming the face) otherwise
void requireValidFaces(const std::string& who, const std::vector<std::array<int, 4>>& faces,
                       int vertexCount);

/// Checks that blocks of variables [offset, offset + length) are non-negative and pairwise
/// disjoint, so that no row can list a variable twice.
/// @param[in] blocks  (offset, length) pairs; empty blocks are ignored
/// @throws std::invalid_argument (message prefixed by `who`) on a negative offset or an overlap
void requireDisjointBlocks(const std::string& who, std::vector<std::pair<int, int>> blocks);

/// Appends (offset, 3) for every point offset to `blocks`.
void appendPointBlocks(const std::vector<int>& pointOffsets,
                       std::vector<std::pair<int, int>>& blocks);

}  // namespace devsurf::terms
