#include "devsurf/models/CurvePairWidth.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <vector>

#include <Eigen/SVD>

namespace devsurf::models {
namespace {

/// Points of c sampled uniformly in its parameter, rows.
Eigen::MatrixXd uniformCurveSamples(const spline::BSplineCurve& c, int count) {
  const double u0 = c.knots.domainBegin(), u1 = c.knots.domainEnd();
  std::vector<double> params(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) params[static_cast<std::size_t>(k)] = u0 + (u1 - u0) * k / (count - 1);
  return c.evaluate(params);
}

}  // namespace

void requireCurvePairWidth(const spline::BSplineCurve& first, const spline::BSplineCurve& second,
                           const std::string& firstName, const std::string& secondName) {
  const Eigen::MatrixXd a = uniformCurveSamples(first, 257), b = uniformCurveSamples(second, 65);
  const Eigen::RowVectorXd lo = a.colwise().minCoeff().cwiseMin(b.colwise().minCoeff());
  const Eigen::RowVectorXd hi = a.colwise().maxCoeff().cwiseMax(b.colwise().maxCoeff());
  const double extent = (hi - lo).norm();
  auto span = [](const Eigen::MatrixXd& p) { return (p.colwise().maxCoeff() - p.colwise().minCoeff()).norm(); };
  if (span(first.points) <= 1e-12 * std::max(extent, 1e-300))
    throw std::invalid_argument(firstName + ".points: every control point is the same point; " + firstName +
                                " has no length");
  if (span(second.points) <= 1e-12 * std::max(extent, 1e-300))
    throw std::invalid_argument(secondName + ".points: every control point is the same point; " + secondName +
                                " has no length");
  // The second on the first: every sample of it on the first's polyline.
  const double tolerance = 1e-9 * extent;
  bool onFirst = true;
  for (Eigen::Index k = 0; k < b.rows() && onFirst; ++k) {
    double nearest = std::numeric_limits<double>::infinity();
    for (Eigen::Index i = 0; i + 1 < a.rows() && nearest > tolerance; ++i) {
      const Eigen::RowVectorXd d = a.row(i + 1) - a.row(i);
      const double length2 = d.squaredNorm();
      const double t = length2 > 0.0 ? std::clamp((b.row(k) - a.row(i)).dot(d) / length2, 0.0, 1.0) : 0.0;
      nearest = std::min(nearest, (b.row(k) - a.row(i) - t * d).norm());
    }
    onFirst = nearest <= tolerance;
  }
  if (onFirst)
    throw std::invalid_argument(secondName + ".points: " + secondName + " lies on " + firstName +
                                "; the strip between them has no width");
  // Both on one straight line: every ruling runs along it.
  Eigen::MatrixXd samples(a.rows() + b.rows(), 3);
  samples << a, b;
  const Eigen::MatrixXd centred = samples.rowwise() - samples.colwise().mean();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred);
  const Eigen::VectorXd sigma = svd.singularValues();
  if (sigma(1) <= 1e-9 * sigma(0))
    throw std::invalid_argument(secondName + ".points: " + firstName + " and " + secondName +
                                " lie on one straight line; the strip between them has no width");
}

}  // namespace devsurf::models
