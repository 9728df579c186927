#include "devsurf/terms/StripWidthTerm.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

namespace devsurf::terms {
namespace {

Eigen::Vector3d sumAt(const std::vector<StripWidthTerm::SignedPoints>& sets, const Eigen::VectorXd& x, int k) {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  for (const auto& [points, sign] : sets) v += sign * points.point(x, k);
  return v;
}

}  // namespace

StripWidthTerm::StripWidthTerm(std::string name, std::vector<SignedPoints> ruling, std::vector<SignedPoints> tangent,
                               std::vector<double> minWidth)
    : Term(std::move(name)) {
  const int K = static_cast<int>(minWidth.size());
  for (const auto* sets : {&ruling, &tangent})
    for (const auto& s : *sets)
      if (s.first.rows() != K) throw std::invalid_argument("StripWidthTerm: every point set needs one row per parameter");
  for (int k = 0; k < K; ++k) {
    if (!(minWidth[k] > 0.0) || !std::isfinite(minWidth[k])) continue;
    const std::size_t first = entries_.size();
    auto accumulate = [this, first](const std::vector<SignedPoints>& sets, bool isRuling, int k) {
      for (const auto& [points, sign] : sets)
        for (spline::EvaluationMatrix::InnerIterator it(points.weights, k); it; ++it) {
          const int offset = points.offset + 3 * static_cast<int>(it.col());
          auto e = std::find_if(entries_.begin() + static_cast<std::ptrdiff_t>(first), entries_.end(),
                                [offset](const Entry& entry) { return entry.offset == offset; });
          if (e == entries_.end()) {
            entries_.push_back({offset, 0.0, 0.0});
            e = entries_.end() - 1;
          }
          (isRuling ? e->r : e->t) += sign * it.value();
        }
    };
    accumulate(ruling, true, k);
    accumulate(tangent, false, k);
    rowStart_.push_back(static_cast<int>(entries_.size()));
    inverseSquared_.push_back(1.0 / (minWidth[k] * minWidth[k]));
  }
}

void StripWidthTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int i = 0; i < numResiduals(); ++i)
    for (int k = rowStart_[i]; k < rowStart_[i + 1]; ++k)
      for (int c = 0; c < 3; ++c) entries.push_back({i, entries_[k].offset + c});
}

void StripWidthTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  double* out = jacobian;
  const Entry* entries = entries_.data();
  for (int i = 0; i < numResiduals(); ++i) {
    const Entry* begin = entries + rowStart_[i];
    const Entry* end = entries + rowStart_[i + 1];
    Eigen::Vector3d r = Eigen::Vector3d::Zero(), t = Eigen::Vector3d::Zero();
    for (const Entry* e = begin; e != end; ++e) {
      r += e->r * x.segment<3>(e->offset);
      t += e->t * x.segment<3>(e->offset);
    }
    const Eigen::Vector3d N = r.cross(t);
    const double inverseSquared = inverseSquared_[i];
    const double g = 1.0 - N.squaredNorm() * inverseSquared;
    residuals[i] = hingeResidual(g);
    if (!out) continue;
    const double slope = hingeSlope(g);
    const std::size_t n = 3 * static_cast<std::size_t>(end - begin);
    if (slope == 0.0) {  // at rest (wide enough): a zero row, which the assembler skips
      std::fill(out, out + n, 0.0);
      out += n;
      continue;
    }
    // d|N|² = 2 (t × N)·dr + 2 (N × r)·dt; the row is −slope/m² times that.
    const double s = -2.0 * slope * inverseSquared;
    const Eigen::Vector3d gr = s * t.cross(N), gt = s * N.cross(r);
    for (const Entry* e = begin; e != end; ++e) {
      const Eigen::Vector3d v = e->r * gr + e->t * gt;
      for (int c = 0; c < 3; ++c) *out++ = v[c];
    }
  }
}

std::vector<double> StripWidthTerm::widths(const std::vector<SignedPoints>& ruling, const std::vector<SignedPoints>& tangent,
                                           const Eigen::VectorXd& x) {
  const int K = ruling.empty() ? 0 : ruling.front().first.rows();
  std::vector<double> w(static_cast<std::size_t>(K));
  for (int k = 0; k < K; ++k) w[k] = sumAt(ruling, x, k).cross(sumAt(tangent, x, k)).norm();
  return w;
}

double StripWidthTerm::widthRatioMin(const Eigen::VectorXd& x, double ratio) const {
  double best = 1.0 / ratio;
  for (int i = 0; i < numResiduals(); ++i) {
    Eigen::Vector3d r = Eigen::Vector3d::Zero(), t = Eigen::Vector3d::Zero();
    for (int k = rowStart_[i]; k < rowStart_[i + 1]; ++k) {
      const Entry& e = entries_[k];
      r += e.r * x.segment<3>(e.offset);
      t += e.t * x.segment<3>(e.offset);
    }
    best = std::min(best, r.cross(t).norm() * std::sqrt(inverseSquared_[i]));
  }
  return best * ratio;
}

}  // namespace devsurf::terms
