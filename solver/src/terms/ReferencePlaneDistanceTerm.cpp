#include "devsurf/terms/ReferencePlaneDistanceTerm.h"

#include <stdexcept>

#include "devsurf/terms/VertexProductRows.h"

namespace devsurf::terms {

ReferencePlaneDistanceTerm::ReferencePlaneDistanceTerm(
    std::string name, std::vector<int> pointOffsets,
    std::shared_ptr<const spatial::TriangleMeshProximity> reference)
    : Term(std::move(name)), offsets_(std::move(pointOffsets)), reference_(std::move(reference)) {
  const std::string who = "ReferencePlaneDistanceTerm";
  if (!reference_) throw std::invalid_argument(who + ": no reference mesh");
  std::vector<std::pair<int, int>> blocks;
  appendPointBlocks(offsets_, blocks);
  requireDisjointBlocks(who, std::move(blocks));
  feet_.assign(offsets_.size(), Eigen::Vector3d::Zero());
  normals_.assign(offsets_.size(), Eigen::Vector3d::UnitZ());
}

void ReferencePlaneDistanceTerm::jacobianStructure(
    std::vector<engine::JacobianEntry>& entries) const {
  for (int i = 0; i < numResiduals(); ++i)
    for (int c = 0; c < 3; ++c) entries.push_back({i, offsets_[i] + c});
}

void ReferencePlaneDistanceTerm::linearizeAt(const Eigen::VectorXd& x) {
  for (int i = 0; i < numResiduals(); ++i) {
    const spatial::ClosestPoint foot = reference_->closest(x.segment<3>(offsets_[i]));
    feet_[i] = foot.point;
    normals_[i] = foot.normal;
  }
}

void ReferencePlaneDistanceTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                          double* jacobian) const {
  for (int i = 0; i < numResiduals(); ++i) {
    residuals[i] = normals_[i].dot(x.segment<3>(offsets_[i]) - feet_[i]);
    if (jacobian)
      for (int c = 0; c < 3; ++c) jacobian[3 * i + c] = normals_[i][c];
  }
}

}  // namespace devsurf::terms
