#include "devsurf/terms/NormalMatchTerm.h"

#include <stdexcept>

namespace devsurf::terms {
namespace {

/// Adds coefficient w · W(k, j) of variable offset + 3j + c for every nonzero of row k of p.
void addRow(const LinearPoints& p, int k, int c, double w,
            std::vector<std::pair<int, double>>& row) {
  for (spline::EvaluationMatrix::InnerIterator it(p.weights, k); it; ++it) {
    const int variable = p.offset + 3 * static_cast<int>(it.col()) + c;
    bool merged = false;
    for (auto& entry : row)
      if (entry.first == variable) {
        entry.second += w * it.value();
        merged = true;
      }
    if (!merged) row.emplace_back(variable, w * it.value());
  }
}

}  // namespace

NormalMatchTerm::NormalMatchTerm(std::string name, LinearPoints n1, LinearPoints n2,
                                 Orientation orientation)
    : Term(std::move(name)), count_(n1.rows()) {
  if (n2.rows() != count_)
    throw std::invalid_argument("NormalMatchTerm: n1 and n2 need the same rows");
  const double sign = orientation == Orientation::Same ? 1.0 : -1.0;
  rows_.resize(3 * static_cast<std::size_t>(count_));
  for (int k = 0; k < count_; ++k)
    for (int c = 0; c < 3; ++c) {
      addRow(n1, k, c, 1.0, rows_[3 * k + c]);
      addRow(n2, k, c, -sign, rows_[3 * k + c]);
    }
}

void NormalMatchTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int r = 0; r < numResiduals(); ++r)
    for (const auto& [variable, coefficient] : rows_[r]) entries.push_back({r, variable});
}

void NormalMatchTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                               double* jacobian) const {
  double* J = jacobian;
  for (int r = 0; r < numResiduals(); ++r) {
    double value = 0.0;
    for (const auto& [variable, coefficient] : rows_[r]) {
      value += coefficient * x[variable];
      if (J) *J++ = coefficient;
    }
    residuals[r] = value;
  }
}

}  // namespace devsurf::terms
