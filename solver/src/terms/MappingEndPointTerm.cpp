#include "devsurf/terms/MappingEndPointTerm.h"

#include <stdexcept>

namespace devsurf::terms {

MappingEndPointTerm::MappingEndPointTerm(std::string name, int shapeOffset,
                                         std::vector<std::pair<int, double>> weights,
                                         std::shared_ptr<const ExtendedCurve> c2,
                                         Eigen::Vector3d target)
    : Term(std::move(name)),
      shapeOffset_(shapeOffset),
      weights_(std::move(weights)),
      c2_(std::move(c2)),
      target_(std::move(target)) {
  if (!c2_) throw std::invalid_argument("MappingEndPointTerm: c2 is null");
}

void MappingEndPointTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int c = 0; c < 3; ++c)
    for (const auto& [k, w] : weights_) entries.push_back({c, shapeOffset_ + k});
}

void MappingEndPointTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                   double* jacobian) const {
  double sigma = 0.0;
  for (const auto& [k, w] : weights_) sigma += w * x[shapeOffset_ + k] * x[shapeOffset_ + k];
  const CurveJet c2 = c2_->evaluate(sigma);
  for (int c = 0; c < 3; ++c) residuals[c] = c2.point[c] - target_[c];
  if (!jacobian) return;
  double* out = jacobian;
  for (int c = 0; c < 3; ++c)
    for (const auto& [k, w] : weights_) *out++ = c2.d1[c] * 2.0 * w * x[shapeOffset_ + k];
}

}  // namespace devsurf::terms
