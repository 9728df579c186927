#include "devsurf/terms/ConformalFactorTerm.h"

#include <stdexcept>

namespace devsurf::terms {

ConformalFactorTerm::ConformalFactorTerm(std::string name, int factorOffset, int faceCount)
    : Term(std::move(name)), factorOffset_(factorOffset), faceCount_(faceCount) {
  if (factorOffset < 0) throw std::invalid_argument("ConformalFactorTerm: negative factor offset");
  if (faceCount < 0) throw std::invalid_argument("ConformalFactorTerm: negative face count");
}

void ConformalFactorTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int f = 0; f < faceCount_; ++f) entries.push_back({f, factorOffset_ + f});
}

void ConformalFactorTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                   double* jacobian) const {
  for (int f = 0; f < faceCount_; ++f) {
    residuals[f] = x[factorOffset_ + f] - 1.0;
    if (jacobian) jacobian[f] = 1.0;
  }
}

}  // namespace devsurf::terms
