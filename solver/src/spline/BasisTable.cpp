#include "devsurf/spline/BasisTable.h"

#include <cassert>
#include <stdexcept>
#include <string>
#include <utility>

#include "devsurf/spline/Basis.h"

namespace devsurf::spline {

BasisTable::BasisTable(const KnotVector& knots, std::vector<double> params, int derivatives)
    : knots_(knots), params_(std::move(params)), degree_(knots.degree()), derivatives_(derivatives) {
  if (derivatives < 0)
    throw std::invalid_argument("BasisTable: derivatives must be >= 0, got " + std::to_string(derivatives));
  const int p = degree_, rows = derivatives + 1;
  control_.resize(params_.size() * static_cast<std::size_t>(p + 1));
  values_.resize(params_.size() * static_cast<std::size_t>(rows * (p + 1)));
  Eigen::MatrixXd basis(rows, p + 1);
  for (std::size_t k = 0; k < params_.size(); ++k) {
    const int s = basisFunctionsInto(knots, params_[k], derivatives, basis);
    for (int j = 0; j <= p; ++j) {
      control_[k * static_cast<std::size_t>(p + 1) + static_cast<std::size_t>(j)] = knots.controlIndex(s - p + j);
      for (int l = 0; l < rows; ++l)
        values_[(k * static_cast<std::size_t>(rows) + static_cast<std::size_t>(l)) * static_cast<std::size_t>(p + 1) +
                static_cast<std::size_t>(j)] = basis(l, j);
    }
  }
}

bool BasisTable::fits(const BSplineCurve& curve) const {
  return !curve.isRational() && curve.points.rows() == knots_.numControlPoints() &&
         curve.knots.kind() == knots_.kind() && curve.knots.degree() == degree_ && curve.knots.knots() == knots_.knots();
}

void BasisTable::evaluate(int k, const Eigen::MatrixXd& points, int upTo, Eigen::Ref<Eigen::MatrixXd> out) const {
  assert(k >= 0 && k < size() && "a tabled parameter");
  assert(upTo >= 0 && upTo <= derivatives_ && "a tabled derivative");
  assert(points.rows() == knots_.numControlPoints() && out.rows() == points.cols() && out.cols() == upTo + 1 &&
         "shapes the caller promised");
  const int p = degree_, rows = derivatives_ + 1;
  const int* control = control_.data() + static_cast<std::size_t>(k) * static_cast<std::size_t>(p + 1);
  const double* values = values_.data() + static_cast<std::size_t>(k) * static_cast<std::size_t>(rows * (p + 1));
  // Plain loops over the column-major points: Eigen's dynamic-size row and column expressions
  // cost more than the products here (a quarter of a composite iterate's metrics).
  const Eigen::Index n = points.rows(), dim = points.cols();
  const double* data = points.data();
  for (int l = 0; l <= upTo; ++l) {
    const double* basis = values + l * (p + 1);
    for (Eigen::Index d = 0; d < dim; ++d) {
      const double* coordinate = data + d * n;
      double sum = 0.0;
      for (int j = 0; j <= p; ++j) sum += basis[j] * coordinate[control[j]];
      out(d, l) = sum;
    }
  }
}

}  // namespace devsurf::spline
