#include "devsurf/terms/GaussImageNormalTerm.h"

#include <algorithm>
#include <stdexcept>

#include <Eigen/Geometry>

namespace devsurf::terms {
namespace {

int cornerCount(const std::array<int, 4>& face) { return face[3] < 0 ? 3 : 4; }

}  // namespace

GaussImageNormalTerm::GaussImageNormalTerm(std::string name,
                                           std::vector<std::array<int, 4>> faces,
                                           std::vector<int> meshOffsets,
                                           std::vector<int> normalOffsets)
    : Term(std::move(name)),
      faces_(std::move(faces)),
      meshOffsets_(std::move(meshOffsets)),
      normalOffsets_(std::move(normalOffsets)) {
  const int numVertices = static_cast<int>(meshOffsets_.size());
  if (static_cast<int>(normalOffsets_.size()) != numVertices)
    throw std::invalid_argument("GaussImageNormalTerm: need one normal offset per mesh vertex");
  for (int v = 0; v < numVertices; ++v)
    if (meshOffsets_[v] < 0 || normalOffsets_[v] < 0)
      throw std::invalid_argument("GaussImageNormalTerm: negative offset of vertex " +
                                  std::to_string(v));
  for (int f = 0; f < static_cast<int>(faces_.size()); ++f) {
    const std::array<int, 4>& face = faces_[f];
    const int n = cornerCount(face);
    std::vector<int> variables;
    for (int c = 0; c < n; ++c) {
      if (face[c] < 0 || face[c] >= numVertices)
        throw std::invalid_argument("GaussImageNormalTerm: face " + std::to_string(f) +
                                    " has a vertex index out of range");
      for (int k = 0; k < 3; ++k) {
        variables.push_back(meshOffsets_[face[c]] + k);
        variables.push_back(normalOffsets_[face[c]] + k);
      }
    }
    std::sort(variables.begin(), variables.end());
    if (std::adjacent_find(variables.begin(), variables.end()) != variables.end())
      throw std::invalid_argument("GaussImageNormalTerm: face " + std::to_string(f) +
                                  " repeats a vertex or its vertex and normal variables overlap");
    numResiduals_ += n;
  }
}

void GaussImageNormalTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  int row = 0;
  for (const auto& face : faces_) {
    const int n = cornerCount(face);
    for (int j = 0; j < n; ++j, ++row) {
      for (int c = 0; c < n; ++c)
        for (int k = 0; k < 3; ++k) entries.push_back({row, meshOffsets_[face[c]] + k});
      for (const int corner : {j, (j + 1) % n})
        for (int k = 0; k < 3; ++k) entries.push_back({row, normalOffsets_[face[corner]] + k});
    }
  }
}

void GaussImageNormalTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                    double* jacobian) const {
  double* J = jacobian;
  int row = 0;
  for (const auto& face : faces_) {
    const int n = cornerCount(face);
    const auto vertex = [&x, this, &face](int c) -> Eigen::Vector3d {
      return x.segment<3>(meshOffsets_[face[c]]);
    };
    const auto normal = [&x, this, &face](int c) -> Eigen::Vector3d {
      return x.segment<3>(normalOffsets_[face[c]]);
    };
    // n_f = d0 × d1 / ‖d0 × d1‖: the diagonals of a quad, two edges of a triangle.
    const Eigen::Vector3d d0 = n == 4 ? Eigen::Vector3d(vertex(2) - vertex(0))
                                      : Eigen::Vector3d(vertex(1) - vertex(0));
    const Eigen::Vector3d d1 = n == 4 ? Eigen::Vector3d(vertex(3) - vertex(1))
                                      : Eigen::Vector3d(vertex(2) - vertex(0));
    const Eigen::Vector3d cross = d0.cross(d1);
    const double length = cross.norm();
    const bool degenerate = !(length > 0.0);
    const Eigen::Vector3d nf = degenerate ? Eigen::Vector3d::Zero() : Eigen::Vector3d(cross / length);
    for (int j = 0; j < n; ++j, ++row) {
      const Eigen::Vector3d sum = normal(j) + normal((j + 1) % n);
      residuals[row] = sum.dot(nf) - 2.0;
      if (!J) continue;
      // ∂r/∂cross = (I − n_f n_fᵀ) sum / ‖cross‖; ∂cross = ∂d0 × d1 + d0 × ∂d1.
      const Eigen::Vector3d g =
          degenerate ? Eigen::Vector3d::Zero() : Eigen::Vector3d((sum - sum.dot(nf) * nf) / length);
      const Eigen::Vector3d byD0 = d1.cross(g);  // ∂r/∂d0
      const Eigen::Vector3d byD1 = g.cross(d0);  // ∂r/∂d1
      std::array<Eigen::Vector3d, 4> byVertex;
      if (n == 4) {
        byVertex = {-byD0, -byD1, byD0, byD1};
      } else {
        byVertex = {-byD0 - byD1, byD0, byD1, Eigen::Vector3d::Zero()};
      }
      for (int c = 0; c < n; ++c)
        for (int k = 0; k < 3; ++k) *J++ = byVertex[c][k];
      for (int twice = 0; twice < 2; ++twice)
        for (int k = 0; k < 3; ++k) *J++ = nf[k];
    }
  }
}

}  // namespace devsurf::terms
