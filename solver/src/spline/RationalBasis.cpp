#include "devsurf/spline/RationalBasis.h"

#include <stdexcept>
#include <string>

namespace devsurf::spline {

EvaluationMatrix curveEvaluationMatrix(const KnotVector& knots, const Eigen::VectorXd& weights,
                                       const std::vector<double>& params, int derivative) {
  if (weights.size() == 0) return evaluationMatrix(knots, params, derivative);
  if (weights.size() != knots.numControlPoints())
    throw std::invalid_argument("weights: expected " + std::to_string(knots.numControlPoints()) +
                                " values (one per control point), got " +
                                std::to_string(weights.size()));
  if (derivative < 0 || derivative > 2)
    throw std::invalid_argument("rational evaluation: derivative must be 0, 1 or 2");
  const int p = knots.degree();
  std::vector<Eigen::Triplet<double, int>> triplets;
  triplets.reserve(params.size() * static_cast<std::size_t>(p + 1));
  Eigen::VectorXd R(p + 1), dR(p + 1), ddR(p + 1);
  for (std::size_t k = 0; k < params.size(); ++k) {
    const BasisValues basis = basisFunctions(knots, params[k], 2);
    double W[3] = {0.0, 0.0, 0.0};
    for (int j = 0; j <= p; ++j)
      for (int l = 0; l < 3; ++l) W[l] += weights[basis.controlIndex[j]] * basis.values(l, j);
    for (int j = 0; j <= p; ++j) {
      const double w = weights[basis.controlIndex[j]];
      R[j] = w * basis.values(0, j) / W[0];
      dR[j] = (w * basis.values(1, j) - R[j] * W[1]) / W[0];
      ddR[j] = (w * basis.values(2, j) - 2.0 * dR[j] * W[1] - R[j] * W[2]) / W[0];
    }
    const Eigen::VectorXd& values = derivative == 0 ? R : (derivative == 1 ? dR : ddR);
    for (int j = 0; j <= p; ++j)
      triplets.emplace_back(static_cast<int>(k), basis.controlIndex[j], values[j]);
  }
  EvaluationMatrix m(static_cast<Eigen::Index>(params.size()), knots.numControlPoints());
  m.setFromTriplets(triplets.begin(), triplets.end());  // sums wrapped periodic columns
  m.makeCompressed();
  return m;
}

}  // namespace devsurf::spline
