#include "devsurf/terms/ExtendedCurve.h"

#include <algorithm>
#include <stdexcept>

namespace devsurf::terms {

namespace {

/// Power-basis coefficients a_k of a Bézier polygon p_0 … p_n: P(s) = Σ_k a_k s^k with
/// a_k = C(n, k) Σ_{i ≤ k} (−1)^{k−i} C(k, i) p_i.
std::vector<Eigen::Vector3d> powerCoefficients(const std::vector<Eigen::Vector3d>& p) {
  const int n = static_cast<int>(p.size()) - 1;
  auto binomial = [](int m, int r) {
    double c = 1.0;
    for (int i = 1; i <= r; ++i) c = c * (m - r + i) / i;
    return c;
  };
  std::vector<Eigen::Vector3d> a(static_cast<std::size_t>(n) + 1, Eigen::Vector3d::Zero());
  for (int k = 0; k <= n; ++k) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int i = 0; i <= k; ++i) sum += (((k - i) % 2) ? -1.0 : 1.0) * binomial(k, i) * p[static_cast<std::size_t>(i)];
    a[static_cast<std::size_t>(k)] = binomial(n, k) * sum;
  }
  return a;
}

}  // namespace

ExtendedCurve::ExtendedCurve(const spline::BSplineCurve& curve) {
  curve.validate();
  if (curve.isRational()) throw std::invalid_argument("ExtendedCurve: curve must not be rational");
  if (curve.dimension() != 3) throw std::invalid_argument("ExtendedCurve: curve must be 3D");
  if (curve.knots.kind() != spline::KnotKind::Clamped) {
    throw std::invalid_argument("ExtendedCurve: knots must be clamped");
  }
  degree_ = curve.degree();
  const std::vector<spline::BezierPiece> pieces = spline::bezierPieces(curve);
  breaks_.push_back(pieces.front().begin);
  for (const auto& piece : pieces) {
    breaks_.push_back(piece.end);
    std::vector<Eigen::Vector3d> p;
    for (int i = 0; i < piece.points.rows(); ++i) p.push_back(piece.points.row(i).transpose());
    const double length = piece.end - piece.begin;
    coefficients_.push_back(powerCoefficients(p));
    inverseLengths_.push_back(1.0 / length);
  }
}

CurveJet ExtendedCurve::evaluate(double u) const {
  // Piece: the last one whose begin ≤ u (the first for u before the domain).
  const auto it = std::upper_bound(breaks_.begin() + 1, breaks_.end() - 1, u);
  const int j = static_cast<int>(it - breaks_.begin()) - 1;
  const double s = (u - breaks_[j]) / (breaks_[j + 1] - breaks_[j]);
  // Horner's scheme for P, P′ and P″/2 in the local parameter s, then the chain rule.
  const std::vector<Eigen::Vector3d>& a = coefficients_[static_cast<std::size_t>(j)];
  Eigen::Vector3d p = a.back(), d = Eigen::Vector3d::Zero(), h = Eigen::Vector3d::Zero();
  for (int k = static_cast<int>(a.size()) - 2; k >= 0; --k) {
    h = h * s + d;
    d = d * s + p;
    p = p * s + a[static_cast<std::size_t>(k)];
  }
  const double inv = inverseLengths_[static_cast<std::size_t>(j)];
  CurveJet jet;
  jet.point = p;
  jet.d1 = d * inv;
  jet.d2 = 2.0 * h * inv * inv;
  return jet;
}

}  // namespace devsurf::terms
