#include "devsurf/terms/ReferencePlaneDistanceTerm.h"

#include <stdexcept>

#include "devsurf/terms/VertexProductRows.h"

namespace devsurf::terms {

ReferencePlaneDistanceTerm::ReferencePlaneDistanceTerm(
    std::string name, std::vector<int> pointOffsets,
    std::shared_ptr<const spatial::TriangleMeshProximity> reference)
    : ReferencePlaneDistanceTerm(std::move(name),
            reference ? std::make_shared<ReferenceFootPoints>(std::move(reference), std::move(pointOffsets))
                      : nullptr) {}

ReferencePlaneDistanceTerm::ReferencePlaneDistanceTerm(std::string name, std::shared_ptr<ReferenceFootPoints> feet)
    : Term(std::move(name)), footPoints_(std::move(feet)) {
  const std::string who = "ReferencePlaneDistanceTerm";
  if (!footPoints_) throw std::invalid_argument(who + ": no reference mesh");
  offsets_ = footPoints_->pointOffsets();
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
  const std::vector<spatial::ClosestPoint>& closest = footPoints_->at(x);
  for (std::size_t i = 0; i < offsets_.size(); ++i) {
    feet_[i] = closest[i].point;
    normals_[i] = closest[i].normal;
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
