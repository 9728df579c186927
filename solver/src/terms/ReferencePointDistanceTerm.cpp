#include "devsurf/terms/ReferencePointDistanceTerm.h"

#include <stdexcept>

#include "devsurf/terms/VertexProductRows.h"

namespace devsurf::terms {

ReferencePointDistanceTerm::ReferencePointDistanceTerm(
    std::string name, std::vector<int> pointOffsets,
    std::shared_ptr<const spatial::TriangleMeshProximity> reference)
    : ReferencePointDistanceTerm(std::move(name),
            reference ? std::make_shared<ReferenceFootPoints>(std::move(reference), std::move(pointOffsets))
                      : nullptr) {}

ReferencePointDistanceTerm::ReferencePointDistanceTerm(std::string name, std::shared_ptr<ReferenceFootPoints> feet)
    : Term(std::move(name)), footPoints_(std::move(feet)) {
  const std::string who = "ReferencePointDistanceTerm";
  if (!footPoints_) throw std::invalid_argument(who + ": no reference mesh");
  offsets_ = footPoints_->pointOffsets();
  std::vector<std::pair<int, int>> blocks;
  appendPointBlocks(offsets_, blocks);
  requireDisjointBlocks(who, std::move(blocks));
  feet_.assign(offsets_.size(), Eigen::Vector3d::Zero());
}

void ReferencePointDistanceTerm::jacobianStructure(
    std::vector<engine::JacobianEntry>& entries) const {
  for (int i = 0; i < static_cast<int>(offsets_.size()); ++i)
    for (int c = 0; c < 3; ++c) entries.push_back({3 * i + c, offsets_[i] + c});
}

void ReferencePointDistanceTerm::linearizeAt(const Eigen::VectorXd& x) {
  const std::vector<spatial::ClosestPoint>& closest = footPoints_->at(x);
  for (std::size_t i = 0; i < offsets_.size(); ++i) feet_[i] = closest[i].point;
}

void ReferencePointDistanceTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                          double* jacobian) const {
  for (int i = 0; i < static_cast<int>(offsets_.size()); ++i)
    for (int c = 0; c < 3; ++c) {
      residuals[3 * i + c] = x[offsets_[i] + c] - feet_[i][c];
      if (jacobian) jacobian[3 * i + c] = 1.0;
    }
}

}  // namespace devsurf::terms
