#include "devsurf/terms/ExtendedCurve.h"

#include <algorithm>
#include <stdexcept>

namespace devsurf::terms {

namespace {

/// de Casteljau for a 3D Bézier polygon at local s (s outside [0,1] extrapolates).
Eigen::Vector3d deCasteljau(const std::vector<Eigen::Vector3d>& p, double s) {
  const int n = static_cast<int>(p.size());
  if (n == 0) return Eigen::Vector3d::Zero();
  // Small fixed buffer: curves used here have modest degree; fall back to a vector otherwise.
  Eigen::Vector3d buffer[32];
  std::vector<Eigen::Vector3d> heap;
  Eigen::Vector3d* w = buffer;
  if (n > 32) {
    heap = p;
    w = heap.data();
  } else {
    std::copy(p.begin(), p.end(), buffer);
  }
  for (int k = 1; k < n; ++k)
    for (int i = 0; i < n - k; ++i) w[i] = (1.0 - s) * w[i] + s * w[i + 1];
  return w[0];
}

std::vector<Eigen::Vector3d> hodograph(const std::vector<Eigen::Vector3d>& p, double length) {
  std::vector<Eigen::Vector3d> d;
  const int deg = static_cast<int>(p.size()) - 1;
  for (int i = 0; i < deg; ++i) d.push_back(deg * (p[i + 1] - p[i]) / length);
  return d;
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
    points_.push_back(p);
    firsts_.push_back(hodograph(p, length));
    seconds_.push_back(hodograph(firsts_.back(), length));
  }
}

CurveJet ExtendedCurve::evaluate(double u) const {
  // Piece: the last one whose begin ≤ u (the first for u before the domain).
  const auto it = std::upper_bound(breaks_.begin() + 1, breaks_.end() - 1, u);
  const int j = static_cast<int>(it - breaks_.begin()) - 1;
  const double s = (u - breaks_[j]) / (breaks_[j + 1] - breaks_[j]);
  CurveJet jet;
  jet.point = deCasteljau(points_[j], s);
  jet.d1 = deCasteljau(firsts_[j], s);
  jet.d2 = deCasteljau(seconds_[j], s);
  return jet;
}

}  // namespace devsurf::terms
