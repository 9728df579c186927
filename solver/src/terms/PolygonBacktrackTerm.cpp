#include "devsurf/terms/PolygonBacktrackTerm.h"

#include "devsurf/terms/Hinge.h"

#include <algorithm>
#include <stdexcept>

namespace devsurf::terms {

PolygonBacktrackTerm::PolygonBacktrackTerm(std::string name, std::vector<int> pointOffsets,
                                           const Eigen::VectorXd& reference, int window)
    : Term(std::move(name)), points_(std::move(pointOffsets)) {
  if (points_.size() < 3) throw std::invalid_argument("PolygonBacktrackTerm: a polygon needs 3 points");
  if (window < 2) throw std::invalid_argument("PolygonBacktrackTerm: the window pairs at least consecutive legs");
  for (std::size_t i = 1; i < points_.size(); ++i)
    for (std::size_t j = i + 1; j < points_.size() && j <= i + 1; ++j)
      if (points_[i - 1] == points_[i] || points_[i] == points_[j] || points_[i - 1] == points_[j])
        throw std::invalid_argument("PolygonBacktrackTerm: a stencil uses one point twice");
  auto leg = [this, &reference](int i) -> Eigen::Vector3d {
    return reference.segment<3>(points_[i + 1]) - reference.segment<3>(points_[i]);
  };
  const int legs = static_cast<int>(points_.size()) - 1;
  for (int i = 0; i < legs; ++i)
    for (int j = i + 1; j < legs && j - i < window; ++j) {
      if (points_[i] == points_[j + 1] || points_[i + 1] == points_[j + 1]) continue;  // a closed loop's seam
      const Eigen::Vector3d di = leg(i), dj = leg(j);
      if (di.dot(dj) < 0.0) continue;  // the reference has them apart already: by design
      rows_.push_back({i, j});
      inverseLegs_.push_back(1.0 / (std::max(di.norm(), 1e-9) * std::max(dj.norm(), 1e-9)));
    }
}

int PolygonBacktrackTerm::numResiduals() const { return static_cast<int>(rows_.size()); }

void PolygonBacktrackTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int r = 0; r < numResiduals(); ++r) {
    const auto [i, j] = rows_[r];
    // Points i, i+1, j, j+1 with i+1 == j for consecutive legs (listed once).
    for (int p : {i, i + 1})
      for (int c = 0; c < 3; ++c) entries.push_back({r, points_[p] + c});
    if (j != i + 1)
      for (int c = 0; c < 3; ++c) entries.push_back({r, points_[j] + c});
    for (int c = 0; c < 3; ++c) entries.push_back({r, points_[j + 1] + c});
  }
}

void PolygonBacktrackTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  double* out = jacobian;
  for (int r = 0; r < numResiduals(); ++r) {
    const auto [i, j] = rows_[r];
    const Eigen::Vector3d di = x.segment<3>(points_[i + 1]) - x.segment<3>(points_[i]);
    const Eigen::Vector3d dj = x.segment<3>(points_[j + 1]) - x.segment<3>(points_[j]);
    const double g = -di.dot(dj) * inverseLegs_[r];
    residuals[r] = hingeResidual(g);
    if (!out) continue;
    // ⟨d_i, d_j⟩: ∂/∂p_i = −d_j, ∂/∂p_{i+1} = d_j, ∂/∂p_j = −d_i, ∂/∂p_{j+1} = d_i; the row is its
    // negative, scaled (consecutive legs share p_{i+1} = p_j: d_j − d_i there).
    const double s = -hingeSlope(g) * inverseLegs_[r];
    auto put = [&out](const Eigen::Vector3d& v) {
      for (int c = 0; c < 3; ++c) *out++ = v[c];
    };
    put(-s * dj);
    if (j == i + 1) {
      put(s * (dj - di));
    } else {
      put(s * dj);
      put(-s * di);
    }
    put(s * di);
  }
}

double PolygonBacktrackTerm::backtrackMax(const Eigen::VectorXd& x) const {
  double worst = 0.0;
  for (int i = 0; i + 2 < static_cast<int>(points_.size()); ++i) {
    const Eigen::Vector3d d0 = x.segment<3>(points_[i + 1]) - x.segment<3>(points_[i]);
    const Eigen::Vector3d d1 = x.segment<3>(points_[i + 2]) - x.segment<3>(points_[i + 1]);
    const double n = d0.norm() * d1.norm();
    if (n <= 1e-300) continue;
    worst = std::max(worst, -d0.dot(d1) / n);
  }
  return worst;
}

}  // namespace devsurf::terms
