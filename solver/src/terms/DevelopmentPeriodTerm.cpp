#include "devsurf/terms/DevelopmentPeriodTerm.h"

#include <cstdlib>
#include <stdexcept>

namespace devsurf::terms {

DevelopmentPeriodTerm::DevelopmentPeriodTerm(std::string name, std::vector<std::array<int, 2>> pairs,
                                             int periodOffset)
    : Term(std::move(name)), pairs_(std::move(pairs)), period_(periodOffset) {
  for (const auto& p : pairs_) {
    if (std::abs(p[0] - p[1]) < 2 || std::abs(p[0] - period_) < 2 || std::abs(p[1] - period_) < 2)
      throw std::invalid_argument("DevelopmentPeriodTerm: a pair's variables overlap each other or the period");
  }
}

void DevelopmentPeriodTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (std::size_t i = 0; i < pairs_.size(); ++i)
    for (int c = 0; c < 2; ++c) {
      const int row = 2 * static_cast<int>(i) + c;
      entries.push_back({row, pairs_[i][1] + c});
      entries.push_back({row, pairs_[i][0] + c});
      entries.push_back({row, period_ + c});
    }
}

void DevelopmentPeriodTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  for (std::size_t i = 0; i < pairs_.size(); ++i)
    for (int c = 0; c < 2; ++c) {
      const std::size_t row = 2 * i + static_cast<std::size_t>(c);
      residuals[row] = x[pairs_[i][1] + c] - x[pairs_[i][0] + c] - x[period_ + c];
      if (jacobian) {
        jacobian[3 * row] = 1.0;
        jacobian[3 * row + 1] = -1.0;
        jacobian[3 * row + 2] = -1.0;
      }
    }
}

}  // namespace devsurf::terms
