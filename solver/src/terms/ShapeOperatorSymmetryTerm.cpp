#include "devsurf/terms/ShapeOperatorSymmetryTerm.h"

#include <algorithm>
#include <stdexcept>

namespace devsurf::terms {

ShapeOperatorSymmetryTerm::ShapeOperatorSymmetryTerm(std::string name,
                                                     std::vector<std::array<int, 4>> faces,
                                                     std::vector<int> meshOffsets,
                                                     std::vector<int> normalOffsets)
    : Term(std::move(name)),
      meshOffsets_(std::move(meshOffsets)),
      normalOffsets_(std::move(normalOffsets)) {
  const int numVertices = static_cast<int>(meshOffsets_.size());
  if (static_cast<int>(normalOffsets_.size()) != numVertices)
    throw std::invalid_argument(
        "ShapeOperatorSymmetryTerm: need one normal offset per mesh vertex");
  for (int v = 0; v < numVertices; ++v)
    if (meshOffsets_[v] < 0 || normalOffsets_[v] < 0)
      throw std::invalid_argument("ShapeOperatorSymmetryTerm: negative offset of vertex " +
                                  std::to_string(v));
  for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
    const std::array<int, 4>& face = faces[f];
    const int n = face[3] < 0 ? 3 : 4;
    for (int c = 0; c < n; ++c)
      if (face[c] < 0 || face[c] >= numVertices)
        throw std::invalid_argument("ShapeOperatorSymmetryTerm: face " + std::to_string(f) +
                                    " has a vertex index out of range");
    if (n == 3) continue;
    std::vector<int> variables;
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 3; ++k) {
        variables.push_back(meshOffsets_[face[c]] + k);
        variables.push_back(normalOffsets_[face[c]] + k);
      }
    std::sort(variables.begin(), variables.end());
    if (std::adjacent_find(variables.begin(), variables.end()) != variables.end())
      throw std::invalid_argument("ShapeOperatorSymmetryTerm: face " + std::to_string(f) +
                                  " repeats a vertex or its vertex and normal variables overlap");
    quads_.push_back(face);
  }
}

void ShapeOperatorSymmetryTerm::jacobianStructure(
    std::vector<engine::JacobianEntry>& entries) const {
  for (int row = 0; row < numResiduals(); ++row) {
    const auto& quad = quads_[row];
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 3; ++k) entries.push_back({row, meshOffsets_[quad[c]] + k});
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 3; ++k) entries.push_back({row, normalOffsets_[quad[c]] + k});
  }
}

void ShapeOperatorSymmetryTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                         double* jacobian) const {
  double* J = jacobian;
  for (int row = 0; row < numResiduals(); ++row) {
    const auto& quad = quads_[row];
    const auto vertex = [&x, this, &quad](int c) -> Eigen::Vector3d {
      return x.segment<3>(meshOffsets_[quad[c]]);
    };
    const auto normal = [&x, this, &quad](int c) -> Eigen::Vector3d {
      return x.segment<3>(normalOffsets_[quad[c]]);
    };
    const Eigen::Vector3d d0 = vertex(2) - vertex(0), d1 = vertex(3) - vertex(1);
    const Eigen::Vector3d m0 = normal(2) - normal(0), m1 = normal(3) - normal(1);
    residuals[row] = m1.dot(d0) - d1.dot(m0);
    if (!J) continue;
    // ∂/∂v0 … v3, then ∂/∂n0 … n3.
    const Eigen::Vector3d gradients[8] = {-m1, m0, m1, -m0, d1, -d0, -d1, d0};
    for (const auto& gradient : gradients)
      for (int k = 0; k < 3; ++k) *J++ = gradient[k];
  }
}

}  // namespace devsurf::terms
