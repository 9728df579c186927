#include "devsurf/terms/RulingLengthTerm.h"

#include "devsurf/terms/Hinge.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace devsurf::terms {

RulingLengthTerm::RulingLengthTerm(std::string name, LinearPoints a, LinearPoints b, std::vector<double> minLength)
    : Term(std::move(name)), a_(std::move(a)), b_(std::move(b)) {
  if (a_.rows() != b_.rows() || static_cast<int>(minLength.size()) != b_.rows())
    throw std::invalid_argument("RulingLengthTerm: a, b and minLength need one entry per ruling");
  for (int k = 0; k < b_.rows(); ++k)
    if (minLength[k] > 0.0 && std::isfinite(minLength[k])) {
      rows_.push_back(k);
      inverseSquared_.push_back(1.0 / (minLength[k] * minLength[k]));
    }
}

void RulingLengthTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int i = 0; i < numResiduals(); ++i) {
    a_.appendStructure(rows_[i], i, entries);
    b_.appendStructure(rows_[i], i, entries);
  }
}

void RulingLengthTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  double* out = jacobian;
  for (int i = 0; i < numResiduals(); ++i) {
    const int k = rows_[i];
    const Eigen::Vector3d r = b_.point(x, k) - a_.point(x, k);
    const double g = 1.0 - r.squaredNorm() * inverseSquared_[i];
    residuals[i] = hingeResidual(g);
    if (out) {
      // ∂g/∂b = −2 r/m², ∂g/∂a = +2 r/m² (zero while inactive: the structure stays fixed).
      const double s = hingeSlope(g) * 2.0 * inverseSquared_[i];
      out = a_.writeJacobian(k, r, s, out);
      out = b_.writeJacobian(k, r, -s, out);
    }
  }
}

double RulingLengthTerm::lengthRatioMin(const Eigen::VectorXd& x, double ratio) const {
  double best = 1.0 / ratio;
  for (int i = 0; i < numResiduals(); ++i) {
    const Eigen::Vector3d r = b_.point(x, rows_[i]) - a_.point(x, rows_[i]);
    best = std::min(best, r.norm() * std::sqrt(inverseSquared_[i]));
  }
  return best * ratio;
}

}  // namespace devsurf::terms
