#include "devsurf/terms/StripPointDistanceTerm.h"

#include <stdexcept>

namespace devsurf::terms {

StripPointDistanceTerm::StripPointDistanceTerm(std::string name, std::shared_ptr<StripFootPoints> feet)
    : Term(std::move(name)), feet_(std::move(feet)) {
  if (!feet_) throw std::invalid_argument("StripPointDistanceTerm: no foot points");
}

void StripPointDistanceTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  const int n = feet_->controlPoints();
  for (int j = 0; j < feet_->count(); ++j)
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < n; ++i) {
        entries.push_back({3 * j + c, feet_->offsetA() + 3 * i + c});
        entries.push_back({3 * j + c, feet_->offsetB() + 3 * i + c});
      }
}

void StripPointDistanceTerm::linearizeAt(const Eigen::VectorXd& x) { feet_->update(x); }

void StripPointDistanceTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  const int n = feet_->controlPoints();
  for (int j = 0; j < feet_->count(); ++j) {
    const double v = feet_->v(j);
    const Eigen::Vector3d r = feet_->surfacePoint(x, j) - feet_->points().row(j).transpose();
    for (int c = 0; c < 3; ++c) residuals[3 * j + c] = r[c];
    if (!jacobian) continue;
    const double* R = feet_->basis(j);
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < n; ++i) {
        *jacobian++ = (1.0 - v) * R[i];
        *jacobian++ = v * R[i];
      }
  }
}

}  // namespace devsurf::terms
