// Bézier curves: evaluation, degree elevation and polynomial composition.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::spline {

namespace {

/// Binomial coefficients C(m, 0..m) as doubles: C(m, i) = C(m, i−1)·(m − i + 1)/i, rounded to the
/// nearest integer (exact for m ≤ 1029 in doubles up to 2^53; the rows used here are short).
std::vector<double> binomialRow(int m) {
  std::vector<double> row(static_cast<size_t>(m + 1), 1.0);
  for (int i = 1; i <= m; ++i) row[i] = std::nearbyint(row[i - 1] * (m - i + 1) / i);
  return row;
}

/// Product of two scalar polynomials in Bernstein form (degrees f.size()−1 and g.size()−1):
/// B^m_i B^n_j = C(m,i) C(n,j) / C(m+n,i+j) B^{m+n}_{i+j}.
Eigen::VectorXd bernsteinProduct(const Eigen::VectorXd& f, const Eigen::VectorXd& g) {
  const int m = static_cast<int>(f.size()) - 1;
  const int n = static_cast<int>(g.size()) - 1;
  const std::vector<double> cm = binomialRow(m);
  const std::vector<double> cn = binomialRow(n);
  const std::vector<double> cmn = binomialRow(m + n);
  Eigen::VectorXd h = Eigen::VectorXd::Zero(m + n + 1);
  for (int i = 0; i <= m; ++i) {
    for (int j = 0; j <= n; ++j) {
      h(i + j) += cm[i] * cn[j] / cmn[i + j] * f(i) * g(j);
    }
  }
  return h;
}

}  // namespace

Eigen::VectorXd evaluateBezier(const Eigen::MatrixXd& points, double t) {
  if (points.rows() < 1) throw std::invalid_argument("evaluateBezier: need at least one point");
  Eigen::MatrixXd work = points;
  const int p = static_cast<int>(points.rows()) - 1;
  for (int k = 1; k <= p; ++k) {
    for (int i = 0; i <= p - k; ++i) {
      work.row(i) = (1.0 - t) * work.row(i) + t * work.row(i + 1);
    }
  }
  return work.row(0).transpose();
}

Eigen::MatrixXd elevateBezierDegree(const Eigen::MatrixXd& points, int t) {
  if (points.rows() < 1) {
    throw std::invalid_argument("elevateBezierDegree: need at least one point");
  }
  if (t < 0) {
    throw std::invalid_argument("elevateBezierDegree: t must be >= 0, got " + std::to_string(t));
  }
  const int p = static_cast<int>(points.rows()) - 1;
  const std::vector<double> cp = binomialRow(p);
  const std::vector<double> ct = binomialRow(t);
  const std::vector<double> cpt = binomialRow(p + t);
  Eigen::MatrixXd result = Eigen::MatrixXd::Zero(p + t + 1, points.cols());
  for (int i = 0; i <= p + t; ++i) {
    for (int j = std::max(0, i - t); j <= std::min(p, i); ++j) {
      result.row(i) += cp[j] * ct[i - j] / cpt[i] * points.row(j);
    }
  }
  return result;
}

Eigen::MatrixXd composeBezier(const Eigen::MatrixXd& points, const Eigen::VectorXd& phi) {
  if (points.rows() < 1) throw std::invalid_argument("composeBezier: need at least one point");
  if (phi.size() < 1) {
    throw std::invalid_argument("composeBezier: phi needs at least one Bézier coefficient");
  }
  const int p = static_cast<int>(points.rows()) - 1;
  const int q = static_cast<int>(phi.size()) - 1;
  // Powers φ^k and (1−φ)^k in Bernstein form of degree k·q (1 − φ has coefficients 1 − φ_i).
  const Eigen::VectorXd oneMinus = Eigen::VectorXd::Ones(q + 1) - phi;
  std::vector<Eigen::VectorXd> phiPow(static_cast<size_t>(p + 1));
  std::vector<Eigen::VectorXd> onePow(static_cast<size_t>(p + 1));
  phiPow[0] = Eigen::VectorXd::Ones(1);
  onePow[0] = Eigen::VectorXd::Ones(1);
  for (int k = 1; k <= p; ++k) {
    phiPow[k] = bernsteinProduct(phiPow[k - 1], phi);
    onePow[k] = bernsteinProduct(onePow[k - 1], oneMinus);
  }
  // c(φ) = Σ_k P_k C(p,k) φ^k (1−φ)^{p−k}.
  const std::vector<double> cp = binomialRow(p);
  Eigen::MatrixXd result = Eigen::MatrixXd::Zero(p * q + 1, points.cols());
  for (int k = 0; k <= p; ++k) {
    const Eigen::VectorXd basis = cp[k] * bernsteinProduct(phiPow[k], onePow[p - k]);
    result += basis * points.row(k);
  }
  return result;
}

}  // namespace devsurf::spline
