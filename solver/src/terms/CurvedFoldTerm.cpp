#include "devsurf/terms/CurvedFoldTerm.h"

#include <algorithm>
#include <stdexcept>

namespace devsurf::terms {
CurvedFoldTerm::CurvedFoldTerm(std::string name, LinearPoints da, LinearPoints dda,
                               LinearPoints n1, LinearPoints n2, Mode mode,
                               std::vector<double> rowMultipliers)
    : Term(std::move(name)),
      count_(da.rows()),
      da_(std::move(da)),
      dda_(std::move(dda)),
      n1_(std::move(n1)),
      n2_(std::move(n2)),
      mode_(mode),
      multipliers_(std::move(rowMultipliers)),
      scales_(2 * static_cast<std::size_t>(count_), 1.0) {
  if (dda_.rows() != count_ || n1_.rows() != count_ || n2_.rows() != count_)
    throw std::invalid_argument("CurvedFoldTerm: all point sets need the same rows");
  if (multipliers_.empty()) multipliers_.assign(count_, 1.0);
  if (static_cast<int>(multipliers_.size()) != count_)
    throw std::invalid_argument("CurvedFoldTerm: need one row multiplier per parameter");
  if (hasDuplicateEntries(*this))
    throw std::invalid_argument("CurvedFoldTerm: crease and normals share variables");
}

void CurvedFoldTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int k = 0; k < count_; ++k) {
    da_.appendStructure(k, 2 * k, entries);  // ⟨a′, n1 ± n2⟩
    n1_.appendStructure(k, 2 * k, entries);
    n2_.appendStructure(k, 2 * k, entries);
    dda_.appendStructure(k, 2 * k + 1, entries);  // ⟨a″, n1 ± n2⟩
    n1_.appendStructure(k, 2 * k + 1, entries);
    n2_.appendStructure(k, 2 * k + 1, entries);
  }
}

void CurvedFoldTerm::linearizeAt(const Eigen::VectorXd& x) {
  for (int k = 0; k < count_; ++k) {
    scales_[2 * k] = inverseLengthOrOne(da_.point(x, k));
    scales_[2 * k + 1] = inverseLengthOrOne(dda_.point(x, k));
  }
}

void CurvedFoldTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                              double* jacobian) const {
  const double sign = mode_ == Mode::CurvedFold ? 1.0 : -1.0;
  double* J = jacobian;
  for (int k = 0; k < count_; ++k) {
    const Eigen::Vector3d t1 = da_.point(x, k);
    const Eigen::Vector3d t2 = dda_.point(x, k);
    const Eigen::Vector3d m = n1_.point(x, k) + sign * n2_.point(x, k);
    const double s1 = multipliers_[k] * scales_[2 * k];
    const double s2 = multipliers_[k] * scales_[2 * k + 1];
    residuals[2 * k] = s1 * t1.dot(m);
    residuals[2 * k + 1] = s2 * t2.dot(m);
    if (!J) continue;
    J = da_.writeJacobian(k, m, s1, J);
    J = n1_.writeJacobian(k, t1, s1, J);
    J = n2_.writeJacobian(k, t1, sign * s1, J);
    J = dda_.writeJacobian(k, m, s2, J);
    J = n1_.writeJacobian(k, t2, s2, J);
    J = n2_.writeJacobian(k, t2, sign * s2, J);
  }
}

}  // namespace devsurf::terms
