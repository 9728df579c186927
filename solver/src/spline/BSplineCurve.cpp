#include "devsurf/spline/BSplineCurve.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/QR>

#include "devsurf/spline/Basis.h"

namespace devsurf::spline {

namespace {

/// Basis values on the stack (basisFunctionsInto) up to kStackBasisDegree.
using StackBasis = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kStackBasisDegree + 1,
                                 kStackBasisDegree + 1>;

/// out.col(l) = Σ_j basis(l, j) · points.row(controlIndex(s − p + j)) for l ≤ upTo: a polynomial
/// curve's derivatives from basis values of span s.
void accumulateDerivatives(const KnotVector& knots, const Eigen::MatrixXd& points, const StackBasis& basis, int s,
                           int upTo, Eigen::Ref<Eigen::MatrixXd> out) {
  const int p = knots.degree();
  out.setZero();
  for (int j = 0; j <= p; ++j) {
    const auto point = points.row(knots.controlIndex(s - p + j)).transpose();
    for (int k = 0; k <= upTo; ++k) out.col(k) += basis(k, j) * point;
  }
}

[[noreturn]] void failCurve(const std::string& message) { throw std::invalid_argument(message); }

/// O(1) shape checks done on every evaluation (the O(n) ones live in validate()).
void requireShapes(const BSplineCurve& c) {
  if (c.knots.knots().empty()) failCurve("curve: knot vector is empty (default-constructed)");
  const int n = c.knots.numControlPoints();
  if (c.points.rows() != n) {
    failCurve("curve: expected " + std::to_string(n) + " control points (rows of points), got " +
         std::to_string(c.points.rows()));
  }
  if (c.points.cols() < 1) failCurve("curve: control points need at least one coordinate column");
  if (c.weights.size() != 0 && c.weights.size() != n) {
    failCurve("curve: weights must be empty or hold one value per control point (" + std::to_string(n) +
         "), got " + std::to_string(c.weights.size()));
  }
}

}  // namespace

void BSplineCurve::validate() const {
  requireShapes(*this);
  if (!points.allFinite()) failCurve("curve: control points must be finite");
  for (Eigen::Index i = 0; i < weights.size(); ++i) {
    if (!(std::isfinite(weights(i)) && weights(i) > 0.0)) {
      failCurve("curve: weights must be finite and positive (weights[" + std::to_string(i) + "] = " +
           std::to_string(weights(i)) + ")");
    }
  }
}

Eigen::VectorXd BSplineCurve::evaluate(double u, int derivative) const {
  requireShapes(*this);
  if (derivative < 0) failCurve("evaluate: derivative must be >= 0, got " + std::to_string(derivative));
  const int p = degree();
  const int dim = dimension();
  if (!isRational() && p <= kStackBasisDegree && derivative <= kStackBasisDegree) {
    Eigen::VectorXd result = Eigen::VectorXd::Zero(dim);
    if (derivative > p) return result;
    StackBasis basis(derivative + 1, p + 1);
    const int s = basisFunctionsInto(knots, u, derivative, basis);
    for (int j = 0; j <= p; ++j) result += basis(derivative, j) * points.row(knots.controlIndex(s - p + j)).transpose();
    return result;
  }
  const BasisValues b = basisFunctions(knots, u, derivative);

  if (!isRational()) {
    Eigen::VectorXd result = Eigen::VectorXd::Zero(dim);
    if (derivative > p) return result;
    for (int j = 0; j <= p; ++j) {
      result += b.values(derivative, j) * points.row(b.controlIndex[j]).transpose();
    }
    return result;
  }

  // Rational curve (The NURBS Book A4.2): derivatives of A(u) = Σ N_i w_i P_i and
  // w(u) = Σ N_i w_i, then C^{(k)} = (A^{(k)} − Σ_{i=1..k} C(k,i) w^{(i)} C^{(k−i)}) / w.
  Eigen::MatrixXd aders = Eigen::MatrixXd::Zero(dim, derivative + 1);
  Eigen::VectorXd wders = Eigen::VectorXd::Zero(derivative + 1);
  for (int j = 0; j <= p; ++j) {
    const int ci = b.controlIndex[j];
    const double w = weights(ci);
    if (!(w > 0.0)) {
      failCurve("curve: weights must be positive (weights[" + std::to_string(ci) + "] = " +
           std::to_string(w) + ")");
    }
    for (int k = 0; k <= derivative; ++k) {
      const double nw = b.values(k, j) * w;
      wders(k) += nw;
      aders.col(k) += nw * points.row(ci).transpose();
    }
  }
  Eigen::MatrixXd ck(dim, derivative + 1);
  std::vector<double> binom(static_cast<size_t>(derivative + 1), 0.0);  // row k of Pascal
  binom[0] = 1.0;
  for (int k = 0; k <= derivative; ++k) {
    if (k > 0) {
      for (int i = k; i >= 1; --i) binom[i] += binom[i - 1];
    }
    Eigen::VectorXd v = aders.col(k);
    for (int i = 1; i <= k; ++i) v -= binom[i] * wders(i) * ck.col(k - i);
    ck.col(k) = v / wders(0);
  }
  return ck.col(derivative);
}

void BSplineCurve::derivatives(double u, int upTo, Eigen::Ref<Eigen::MatrixXd> out) const {
  requireShapes(*this);
  if (upTo < 0) failCurve("derivatives: upTo must be >= 0, got " + std::to_string(upTo));
  if (out.rows() != dimension() || out.cols() != upTo + 1)
    failCurve("derivatives: out must be " + std::to_string(dimension()) + " x " + std::to_string(upTo + 1) +
              ", got " + std::to_string(out.rows()) + " x " + std::to_string(out.cols()));
  const int p = degree();
  if (isRational() || p > kStackBasisDegree || upTo > kStackBasisDegree) {
    for (int k = 0; k <= upTo; ++k) out.col(k) = evaluate(u, k);
    return;
  }
  StackBasis basis(upTo + 1, p + 1);
  const int s = basisFunctionsInto(knots, u, upTo, basis);
  accumulateDerivatives(knots, points, basis, s, upTo, out);
}

CurvePair::CurvePair(const BSplineCurve& a, const BSplineCurve& b) : a_(a), b_(b) {
  requireShapes(a);
  requireShapes(b);
  shared_ = !a.isRational() && !b.isRational() && a.degree() <= kStackBasisDegree && a.knots.kind() == b.knots.kind() &&
            a.knots.degree() == b.knots.degree() && a.knots.knots() == b.knots.knots();
}

void CurvePair::derivatives(double u, int upTo, Eigen::Ref<Eigen::MatrixXd> outA, Eigen::Ref<Eigen::MatrixXd> outB) const {
  if (!shared_ || upTo > kStackBasisDegree) {
    a_.derivatives(u, upTo, outA);
    b_.derivatives(u, upTo, outB);
    return;
  }
  if (upTo < 0 || outA.rows() != a_.dimension() || outA.cols() != upTo + 1 || outB.rows() != b_.dimension() ||
      outB.cols() != upTo + 1)
    failCurve("CurvePair::derivatives: out must be dim x " + std::to_string(upTo + 1));
  const int p = a_.degree();
  StackBasis basis(upTo + 1, p + 1);
  const int s = basisFunctionsInto(a_.knots, u, upTo, basis);
  accumulateDerivatives(a_.knots, a_.points, basis, s, upTo, outA);
  accumulateDerivatives(a_.knots, b_.points, basis, s, upTo, outB);
}

Eigen::MatrixXd BSplineCurve::evaluate(const std::vector<double>& params, int derivative) const {
  requireShapes(*this);
  const int p = degree(), dim = dimension();
  Eigen::MatrixXd result(static_cast<Eigen::Index>(params.size()), dim);
  if (!isRational() && derivative >= 0 && p <= kStackBasisDegree && derivative <= p) {
    // The common case (every sampled surface and metric) without a vector per parameter: one basis
    // evaluation straight into the row.
    StackBasis basis(derivative + 1, p + 1);
    const Eigen::Index n = points.rows();
    const double* data = points.data();
    for (size_t k = 0; k < params.size(); ++k) {
      const int s = basisFunctionsInto(knots, params[k], derivative, basis);
      for (int d = 0; d < dim; ++d) {
        double sum = 0.0;
        for (int j = 0; j <= p; ++j) sum += basis(derivative, j) * data[d * n + knots.controlIndex(s - p + j)];
        result(static_cast<Eigen::Index>(k), d) = sum;
      }
    }
    return result;
  }
  for (size_t k = 0; k < params.size(); ++k) {
    result.row(static_cast<Eigen::Index>(k)) = evaluate(params[k], derivative).transpose();
  }
  return result;
}

BSplineCurve approximateInSpace(const BSplineCurve& curve, const KnotVector& knots, int samplesPerSpan) {
  if (curve.isRational() || curve.knots.kind() != KnotKind::Clamped || knots.kind() != KnotKind::Clamped)
    throw std::invalid_argument("approximateInSpace: clamped, non-rational curves only");
  if (knots.degree() != curve.degree())
    throw std::invalid_argument("approximateInSpace: the space has degree " + std::to_string(knots.degree()) +
                                ", the curve " + std::to_string(curve.degree()));
  const double scale = std::max(std::abs(curve.knots.domainEnd() - curve.knots.domainBegin()), 1e-300);
  if (std::abs(knots.domainBegin() - curve.knots.domainBegin()) > 1e-12 * scale ||
      std::abs(knots.domainEnd() - curve.knots.domainEnd()) > 1e-12 * scale)
    throw std::invalid_argument("approximateInSpace: the space's domain differs from the curve's");
  const int n = knots.numControlPoints();
  if (n < knots.degree() + 1) throw std::invalid_argument("approximateInSpace: too few control points");
  std::vector<double> breaks = curve.knots.breakpoints();
  const std::vector<double> other = knots.breakpoints();
  breaks.insert(breaks.end(), other.begin(), other.end());
  std::sort(breaks.begin(), breaks.end());
  breaks.erase(std::unique(breaks.begin(), breaks.end(), [scale](double a, double b) { return std::abs(a - b) <= 1e-12 * scale; }),
               breaks.end());
  std::vector<double> params;
  for (std::size_t k = 0; k + 1 < breaks.size(); ++k)
    for (int j = 0; j < samplesPerSpan; ++j) params.push_back(breaks[k] + (breaks[k + 1] - breaks[k]) * (j + 0.5) / samplesPerSpan);
  const Eigen::MatrixXd target = curve.evaluate(params);
  const Eigen::MatrixXd basis = Eigen::MatrixXd(evaluationMatrix(knots, params, 0));
  BSplineCurve result;
  result.knots = knots;
  result.points.resize(n, curve.dimension());
  result.points.row(0) = curve.points.row(0);
  result.points.row(n - 1) = curve.points.row(curve.points.rows() - 1);
  if (n > 2) {
    const Eigen::MatrixXd rhs = target - basis.col(0) * result.points.row(0) - basis.col(n - 1) * result.points.row(n - 1);
    result.points.middleRows(1, n - 2) = basis.middleCols(1, n - 2).colPivHouseholderQr().solve(rhs);
  }
  return result;
}

std::vector<double> grevilleAbscissae(const KnotVector& knots) {
  const std::vector<double>& t = knots.knots();
  const int p = knots.degree();
  std::vector<double> g(static_cast<std::size_t>(knots.numControlPoints()), 0.0);
  for (int i = 0; i < knots.numControlPoints(); ++i) {
    double sum = 0.0;
    for (int j = 1; j <= p; ++j) sum += t[static_cast<std::size_t>(i + j)];
    g[static_cast<std::size_t>(i)] = p > 0 ? sum / p : t[static_cast<std::size_t>(i)];
  }
  return g;
}

}  // namespace devsurf::spline
