#include "devsurf/terms/PolygonFairnessTerm.h"

#include <stdexcept>

namespace devsurf::terms {

PolygonFairnessTerm::PolygonFairnessTerm(std::string name, std::vector<int> pointOffsets)
    : Term(std::move(name)), points_(std::move(pointOffsets)) {
  for (std::size_t i = 1; i + 1 < points_.size(); ++i)
    if (points_[i - 1] == points_[i] || points_[i] == points_[i + 1] || points_[i - 1] == points_[i + 1])
      throw std::invalid_argument("PolygonFairnessTerm: a stencil uses one point twice");
}

int PolygonFairnessTerm::numResiduals() const {
  return points_.size() < 3 ? 0 : 3 * static_cast<int>(points_.size() - 2);
}

void PolygonFairnessTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (std::size_t i = 1; i + 1 < points_.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const int row = 3 * static_cast<int>(i - 1) + c;
      entries.push_back({row, points_[i - 1] + c});
      entries.push_back({row, points_[i] + c});
      entries.push_back({row, points_[i + 1] + c});
    }
}

void PolygonFairnessTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  for (std::size_t i = 1; i + 1 < points_.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const std::size_t row = 3 * (i - 1) + static_cast<std::size_t>(c);
      residuals[row] = x[points_[i - 1] + c] - 2.0 * x[points_[i] + c] + x[points_[i + 1] + c];
      if (jacobian) {
        jacobian[3 * row] = 1.0;
        jacobian[3 * row + 1] = -2.0;
        jacobian[3 * row + 2] = 1.0;
      }
    }
}

}  // namespace devsurf::terms
