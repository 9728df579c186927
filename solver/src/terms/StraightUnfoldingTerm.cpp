#include "devsurf/terms/StraightUnfoldingTerm.h"

#include <algorithm>
#include <stdexcept>

namespace devsurf::terms {
StraightUnfoldingTerm::StraightUnfoldingTerm(std::string name, LinearPoints da, LinearPoints dda,
                                             LinearPoints nLeft, LinearPoints nOsc)
    : Term(std::move(name)),
      count_(da.rows()),
      da_(std::move(da)),
      dda_(std::move(dda)),
      left_(std::move(nLeft)),
      osc_(std::move(nOsc)),
      scales_(2 * static_cast<std::size_t>(count_), 1.0) {
  if (dda_.rows() != count_ || left_.rows() != count_ || osc_.rows() != count_)
    throw std::invalid_argument("StraightUnfoldingTerm: all point sets need the same rows");
  if (hasDuplicateEntries(*this))
    throw std::invalid_argument("StraightUnfoldingTerm: a row lists a variable twice");
}

void StraightUnfoldingTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int k = 0; k < count_; ++k) {
    const int r = 3 * k;
    da_.appendStructure(k, r, entries);  // ⟨a′, n_osc⟩
    osc_.appendStructure(k, r, entries);
    dda_.appendStructure(k, r + 1, entries);  // ⟨a″, n_osc⟩
    osc_.appendStructure(k, r + 1, entries);
    left_.appendStructure(k, r + 2, entries);  // ⟨n_left, n_osc⟩
    osc_.appendStructure(k, r + 2, entries);
  }
}

void StraightUnfoldingTerm::linearizeAt(const Eigen::VectorXd& x) {
  for (int k = 0; k < count_; ++k) {
    scales_[2 * k] = inverseLengthOrOne(da_.point(x, k));
    scales_[2 * k + 1] = inverseLengthOrOne(dda_.point(x, k));
  }
}

void StraightUnfoldingTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                     double* jacobian) const {
  double* J = jacobian;
  for (int k = 0; k < count_; ++k) {
    const Eigen::Vector3d t1 = da_.point(x, k);
    const Eigen::Vector3d t2 = dda_.point(x, k);
    const Eigen::Vector3d nl = left_.point(x, k);
    const Eigen::Vector3d no = osc_.point(x, k);
    const double s1 = scales_[2 * k], s2 = scales_[2 * k + 1];
    residuals[3 * k] = s1 * t1.dot(no);
    residuals[3 * k + 1] = s2 * t2.dot(no);
    residuals[3 * k + 2] = nl.dot(no);
    if (!J) continue;
    J = da_.writeJacobian(k, no, s1, J);
    J = osc_.writeJacobian(k, t1, s1, J);
    J = dda_.writeJacobian(k, no, s2, J);
    J = osc_.writeJacobian(k, t2, s2, J);
    J = left_.writeJacobian(k, no, 1.0, J);
    J = osc_.writeJacobian(k, nl, 1.0, J);
  }
}

}  // namespace devsurf::terms
