#include "devsurf/terms/StripDevelopabilityTerm.h"

#include <cassert>
#include <cmath>
#include <stdexcept>

namespace devsurf::terms {
StripDevelopabilityTerm::StripDevelopabilityTerm(std::string name, LinearPoints a, LinearPoints da,
                                                 LinearPoints b, LinearPoints db,
                                                 LinearPoints normals)
    : Term(std::move(name)),
      count_(a.rows()),
      a_(std::move(a)),
      da_(std::move(da)),
      b_(std::move(b)),
      db_(std::move(db)),
      n_(std::move(normals)),
      scales_(3 * static_cast<std::size_t>(count_), 1.0) {
  if (da_.rows() != count_ || b_.rows() != count_ || db_.rows() != count_ || n_.rows() != count_)
    throw std::invalid_argument("StripDevelopabilityTerm: all point sets need the same rows");
}

void StripDevelopabilityTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int k = 0; k < count_; ++k) {
    const int r = 3 * k;
    a_.appendStructure(k, r, entries);       // ⟨b − a, n⟩
    b_.appendStructure(k, r, entries);
    n_.appendStructure(k, r, entries);
    da_.appendStructure(k, r + 1, entries);  // ⟨a′, n⟩
    n_.appendStructure(k, r + 1, entries);
    db_.appendStructure(k, r + 2, entries);  // ⟨b′, n⟩
    n_.appendStructure(k, r + 2, entries);
  }
}

void StripDevelopabilityTerm::linearizeAt(const Eigen::VectorXd& x) {
  for (int k = 0; k < count_; ++k) {
    scales_[3 * k] = inverseLengthOrOne(b_.point(x, k) - a_.point(x, k));
    scales_[3 * k + 1] = inverseLengthOrOne(da_.point(x, k));
    scales_[3 * k + 2] = inverseLengthOrOne(db_.point(x, k));
  }
}

void StripDevelopabilityTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                       double* jacobian) const {
  double* J = jacobian;
  for (int k = 0; k < count_; ++k) {
    const Eigen::Vector3d d = b_.point(x, k) - a_.point(x, k);
    const Eigen::Vector3d ta = da_.point(x, k);
    const Eigen::Vector3d tb = db_.point(x, k);
    const Eigen::Vector3d n = n_.point(x, k);
    const double s1 = scales_[3 * k], s2 = scales_[3 * k + 1], s3 = scales_[3 * k + 2];
    residuals[3 * k] = s1 * d.dot(n);
    residuals[3 * k + 1] = s2 * ta.dot(n);
    residuals[3 * k + 2] = s3 * tb.dot(n);
    if (!J) continue;
    J = a_.writeJacobian(k, n, -s1, J);
    J = b_.writeJacobian(k, n, s1, J);
    J = n_.writeJacobian(k, d, s1, J);
    J = da_.writeJacobian(k, n, s2, J);
    J = n_.writeJacobian(k, ta, s2, J);
    J = db_.writeJacobian(k, n, s3, J);
    J = n_.writeJacobian(k, tb, s3, J);
  }
}

}  // namespace devsurf::terms
