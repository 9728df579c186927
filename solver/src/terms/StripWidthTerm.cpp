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
    Row row;
    row.inverseSquared = 1.0 / (minWidth[k] * minWidth[k]);
    auto accumulate = [&row](const std::vector<SignedPoints>& sets, bool isRuling, int k) {
      for (const auto& [points, sign] : sets)
        for (spline::EvaluationMatrix::InnerIterator it(points.weights, k); it; ++it) {
          const int offset = points.offset + 3 * static_cast<int>(it.col());
          auto e = std::find_if(row.entries.begin(), row.entries.end(),
                                [offset](const Entry& entry) { return entry.offset == offset; });
          if (e == row.entries.end()) {
            row.entries.push_back({offset, 0.0, 0.0});
            e = row.entries.end() - 1;
          }
          (isRuling ? e->r : e->t) += sign * it.value();
        }
    };
    accumulate(ruling, true, k);
    accumulate(tangent, false, k);
    rows_.push_back(std::move(row));
  }
}

void StripWidthTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int i = 0; i < numResiduals(); ++i)
    for (const Entry& e : rows_[i].entries)
      for (int c = 0; c < 3; ++c) entries.push_back({i, e.offset + c});
}

void StripWidthTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  double* out = jacobian;
  for (int i = 0; i < numResiduals(); ++i) {
    const Row& row = rows_[i];
    Eigen::Vector3d r = Eigen::Vector3d::Zero(), t = Eigen::Vector3d::Zero();
    for (const Entry& e : row.entries) {
      r += e.r * x.segment<3>(e.offset);
      t += e.t * x.segment<3>(e.offset);
    }
    const Eigen::Vector3d N = r.cross(t);
    const double g = 1.0 - N.squaredNorm() * row.inverseSquared;
    residuals[i] = hingeResidual(g);
    if (!out) continue;
    const double slope = hingeSlope(g);
    if (slope == 0.0) {  // at rest (wide enough): a zero row, which the assembler skips
      const std::size_t n = 3 * row.entries.size();
      std::fill(out, out + n, 0.0);
      out += n;
      continue;
    }
    // d|N|² = 2 (t × N)·dr + 2 (N × r)·dt; the row is −slope/m² times that.
    const double s = -2.0 * slope * row.inverseSquared;
    const Eigen::Vector3d gr = s * t.cross(N), gt = s * N.cross(r);
    for (const Entry& e : row.entries) {
      const Eigen::Vector3d v = e.r * gr + e.t * gt;
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
  for (const Row& row : rows_) {
    Eigen::Vector3d r = Eigen::Vector3d::Zero(), t = Eigen::Vector3d::Zero();
    for (const Entry& e : row.entries) {
      r += e.r * x.segment<3>(e.offset);
      t += e.t * x.segment<3>(e.offset);
    }
    best = std::min(best, r.cross(t).norm() * std::sqrt(row.inverseSquared));
  }
  return best * ratio;
}

}  // namespace devsurf::terms
