#include "devsurf/terms/HandleTargetTerm.h"

namespace devsurf::terms {

HandleTargetTerm::HandleTargetTerm(std::string name, int offset, const Eigen::Vector3d& target)
    : Term(std::move(name)), offset_(offset), target_(target) {}

void HandleTargetTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int c = 0; c < 3; ++c) entries.push_back({c, offset_ + c});
}

void HandleTargetTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                double* jacobian) const {
  for (int c = 0; c < 3; ++c) {
    residuals[c] = x[offset_ + c] - target_[c];
    if (jacobian) jacobian[c] = 1.0;
  }
}

}  // namespace devsurf::terms
