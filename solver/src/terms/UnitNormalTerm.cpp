#include "devsurf/terms/UnitNormalTerm.h"

namespace devsurf::terms {

UnitNormalTerm::UnitNormalTerm(std::string name, std::vector<int> offsets)
    : Term(std::move(name)), offsets_(std::move(offsets)) {}

void UnitNormalTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int i = 0; i < numResiduals(); ++i)
    for (int c = 0; c < 3; ++c) entries.push_back({i, offsets_[i] + c});
}

void UnitNormalTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                              double* jacobian) const {
  for (int i = 0; i < numResiduals(); ++i) {
    const Eigen::Vector3d n = x.segment<3>(offsets_[i]);
    residuals[i] = n.squaredNorm() - 1.0;
    if (jacobian)
      for (int c = 0; c < 3; ++c) jacobian[3 * i + c] = 2.0 * n[c];
  }
}

}  // namespace devsurf::terms
