#include "devsurf/terms/NormalDirectionAnchorTerm.h"

#include <stdexcept>

namespace devsurf::terms {

NormalDirectionAnchorTerm::NormalDirectionAnchorTerm(std::string name, Eigen::MatrixX3d directions,
                                                     std::vector<int> pointOffsets)
    : Term(std::move(name)), directions_(std::move(directions)), offsets_(std::move(pointOffsets)) {
  if (directions_.rows() != static_cast<Eigen::Index>(offsets_.size()))
    throw std::invalid_argument("NormalDirectionAnchorTerm: one direction per vector expected");
  for (std::size_t i = 0; i < offsets_.size(); ++i)
    if (offsets_[i] < 0) throw std::invalid_argument("NormalDirectionAnchorTerm: offset " + std::to_string(i) + " is negative");
}

void NormalDirectionAnchorTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int i = 0; i < static_cast<int>(offsets_.size()); ++i)
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) entries.push_back({3 * i + r, offsets_[i] + c});
}

void NormalDirectionAnchorTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  for (int i = 0; i < static_cast<int>(offsets_.size()); ++i) {
    const Eigen::Vector3d u = directions_.row(i).transpose();
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - u * u.transpose();
    const Eigen::Vector3d r = P * x.segment<3>(offsets_[i]);
    for (int row = 0; row < 3; ++row) {
      residuals[3 * i + row] = r[row];
      if (jacobian)
        for (int c = 0; c < 3; ++c) jacobian[9 * i + 3 * row + c] = P(row, c);
    }
  }
}

}  // namespace devsurf::terms
