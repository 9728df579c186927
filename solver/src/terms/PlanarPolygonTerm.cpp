#include "devsurf/terms/PlanarPolygonTerm.h"

#include <algorithm>
#include <stdexcept>

namespace devsurf::terms {

PlanarPolygonTerm::PlanarPolygonTerm(std::string name, int normalOffset,
                                     std::vector<int> vertexOffsets)
    : Term(std::move(name)), normal_(normalOffset), vertices_(std::move(vertexOffsets)) {
  if (vertices_.size() < 3)
    throw std::invalid_argument("PlanarPolygonTerm: a polygon needs at least 3 vertices");
  std::vector<int> starts = vertices_;
  starts.push_back(normal_);
  std::sort(starts.begin(), starts.end());
  for (std::size_t i = 1; i < starts.size(); ++i)
    if (starts[i] - starts[i - 1] < 3)
      throw std::invalid_argument("PlanarPolygonTerm: vertices and normal must not overlap");
}

void PlanarPolygonTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  const int n = numResiduals();
  for (int i = 0; i < n; ++i) {
    const int from = vertices_[i], to = vertices_[(i + 1) % n];
    for (int c = 0; c < 3; ++c) entries.push_back({i, normal_ + c});
    for (int c = 0; c < 3; ++c) entries.push_back({i, from + c});
    for (int c = 0; c < 3; ++c) entries.push_back({i, to + c});
  }
}

void PlanarPolygonTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                 double* jacobian) const {
  const int n = numResiduals();
  const Eigen::Vector3d normal = x.segment<3>(normal_);
  double* J = jacobian;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d edge =
        x.segment<3>(vertices_[(i + 1) % n]) - x.segment<3>(vertices_[i]);
    residuals[i] = normal.dot(edge);
    if (!J) continue;
    for (int c = 0; c < 3; ++c) *J++ = edge[c];
    for (int c = 0; c < 3; ++c) *J++ = -normal[c];
    for (int c = 0; c < 3; ++c) *J++ = normal[c];
  }
}

}  // namespace devsurf::terms
