#include "devsurf/terms/CurvedFoldRulingTerm.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

namespace devsurf::terms {

CurvedFoldRulingTerm::CurvedFoldRulingTerm(std::string name, const LinearPoints& da, const LinearPoints& dda,
                                           const LinearPoints& across1, const LinearPoints& across2,
                                           std::vector<double> orientation1, std::vector<double> orientation2,
                                           Mode mode, std::vector<double> rowMultipliers)
    : Term(std::move(name)),
      count_(da.rows()),
      orientation1_(std::move(orientation1)),
      orientation2_(std::move(orientation2)),
      mode_(mode),
      multipliers_(std::move(rowMultipliers)),
      scales_(static_cast<std::size_t>(count_), 1.0),
      curvatureScratch_(static_cast<std::size_t>(count_), 0.0),
      sortedScratch_(static_cast<std::size_t>(count_), 0.0) {
  if (dda.rows() != count_ || across1.rows() != count_ || across2.rows() != count_)
    throw std::invalid_argument("CurvedFoldRulingTerm: all point sets need the same rows");
  if (static_cast<int>(orientation1_.size()) != count_ || static_cast<int>(orientation2_.size()) != count_)
    throw std::invalid_argument("CurvedFoldRulingTerm: need one orientation per parameter and side");
  for (int k = 0; k < count_; ++k)
    if (std::abs(orientation1_[k]) != 1.0 || std::abs(orientation2_[k]) != 1.0)
      throw std::invalid_argument("CurvedFoldRulingTerm: orientations must be +1 or -1");
  if (multipliers_.empty()) multipliers_.assign(static_cast<std::size_t>(count_), 1.0);
  if (static_cast<int>(multipliers_.size()) != count_)
    throw std::invalid_argument("CurvedFoldRulingTerm: need one row multiplier per parameter");

  const LinearPoints* sets[4] = {&da, &dda, &across1, &across2};
  rowStart_.reserve(static_cast<std::size_t>(count_) + 1);
  rowStart_.push_back(0);
  std::vector<RowPoint> row;
  for (int k = 0; k < count_; ++k) {
    row.clear();
    for (int s = 0; s < 4; ++s) {
      for (spline::EvaluationMatrix::InnerIterator it(sets[s]->weights, k); it; ++it) {
        const int variable = sets[s]->offset + 3 * static_cast<int>(it.col());
        auto found = std::find_if(row.begin(), row.end(), [variable](const RowPoint& p) { return p.variable == variable; });
        if (found == row.end()) {
          row.push_back({variable, {}});
          found = row.end() - 1;
        }
        found->weight[static_cast<std::size_t>(s)] += it.value();
      }
    }
    std::sort(row.begin(), row.end(), [](const RowPoint& p, const RowPoint& q) { return p.variable < q.variable; });
    points_.insert(points_.end(), row.begin(), row.end());
    rowStart_.push_back(static_cast<int>(points_.size()));
    for (std::size_t s = 0; s < 4; ++s) {
      setStart_.push_back(static_cast<int>(setEntries_.size()));
      for (const RowPoint& p : row)
        if (p.weight[s] != 0.0) setEntries_.push_back({p.variable, p.weight[s]});
    }
  }
  setStart_.push_back(static_cast<int>(setEntries_.size()));
}

Eigen::Vector3d CurvedFoldRulingTerm::vectorAt(const Eigen::VectorXd& x, int k, int s) const {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  for (int e = setStart_[4 * k + s]; e < setStart_[4 * k + s + 1]; ++e) {
    const SetEntry& entry = setEntries_[static_cast<std::size_t>(e)];
    v += entry.weight * x.segment<3>(entry.variable);
  }
  return v;
}

void CurvedFoldRulingTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int k = 0; k < count_; ++k)
    for (int p = rowStart_[k]; p < rowStart_[k + 1]; ++p)
      for (int c = 0; c < 3; ++c) entries.push_back({k, points_[static_cast<std::size_t>(p)].variable + c});
}

std::array<Eigen::Vector3d, 4> CurvedFoldRulingTerm::vectorsAt(const Eigen::VectorXd& x, int k) const {
  return {vectorAt(x, k, 0), vectorAt(x, k, 1), vectorAt(x, k, 2), vectorAt(x, k, 3)};
}

void CurvedFoldRulingTerm::linearizeAt(const Eigen::VectorXd& x) {
  // s_k = 1 / (|a′_k|² max(κ_k, κ_ref)): κ_k the crease's curvature |a′ × a″| / |a′|³ at u_k,
  // κ_ref its 90th percentile over the parameters.
  std::vector<double>& curvature = curvatureScratch_;
  for (int k = 0; k < count_; ++k) {
    const Eigen::Vector3d tangent = vectorAt(x, k, 0), second = vectorAt(x, k, 1);
    const double speed = tangent.norm();
    scales_[static_cast<std::size_t>(k)] = speed * speed;  // |a′|², until κ_ref is known
    curvature[static_cast<std::size_t>(k)] = speed > 1e-12 ? tangent.cross(second).norm() / (speed * speed * speed) : 0.0;
  }
  std::vector<double>& sorted = sortedScratch_;
  sorted = curvature;
  const std::size_t at = static_cast<std::size_t>(kReferenceQuantile * (count_ - 1));
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(at), sorted.end());
  const double reference = count_ > 0 ? sorted[at] : 0.0;
  for (int k = 0; k < count_; ++k) {
    double& s = scales_[static_cast<std::size_t>(k)];
    const double normal = s * std::max(curvature[static_cast<std::size_t>(k)], reference);  // |a″'s normal part|, at least
    s = normal > 1e-12 ? 1.0 / normal : 1.0;
  }
}

void CurvedFoldRulingTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  const double sign = mode_ == Mode::CurvedFold ? 1.0 : -1.0;
  double* J = jacobian;
  for (int k = 0; k < count_; ++k) {
    const auto [tangent, curvature, across1, across2] = vectorsAt(x, k);
    const Eigen::Vector3d g1 = tangent.cross(across1), g2 = tangent.cross(across2);
    const double length1 = g1.norm(), length2 = g2.norm();
    const int numEntries = 3 * (rowStart_[k + 1] - rowStart_[k]);
    const bool degenerate = !(length1 > 1e-12 * tangent.norm() * across1.norm()) ||
                            !(length2 > 1e-12 * tangent.norm() * across2.norm());
    if (degenerate) {
      residuals[k] = 0.0;
      if (J) J = std::fill_n(J, numEntries, 0.0);
      continue;
    }
    const Eigen::Vector3d h1 = g1 / length1, h2 = g2 / length2;
    const double o1 = orientation1_[static_cast<std::size_t>(k)], o2 = sign * orientation2_[static_cast<std::size_t>(k)];
    const Eigen::Vector3d normalSum = o1 * h1 + o2 * h2;
    const double u = multipliers_[static_cast<std::size_t>(k)] * scales_[static_cast<std::size_t>(k)];
    residuals[k] = u * curvature.dot(normalSum);
    if (!J) continue;
    // ∂⟨a″, o ĝ⟩/∂g = q = o (I − ĝĝᵀ) a″ / |g|; with g = a′ × d: ⟨q, δa′ × d⟩ = ⟨d × q, δa′⟩ and
    // ⟨q, a′ × δd⟩ = ⟨q × a′, δd⟩.
    const Eigen::Vector3d q1 = o1 * (curvature - h1 * h1.dot(curvature)) / length1;
    const Eigen::Vector3d q2 = o2 * (curvature - h2 * h2.dot(curvature)) / length2;
    const std::array<Eigen::Vector3d, 4> gradient = {u * (across1.cross(q1) + across2.cross(q2)), u * normalSum,
                                                     u * q1.cross(tangent), u * q2.cross(tangent)};
    for (int p = rowStart_[k]; p < rowStart_[k + 1]; ++p) {
      const RowPoint& point = points_[static_cast<std::size_t>(p)];
      const Eigen::Vector3d g = point.weight[0] * gradient[0] + point.weight[1] * gradient[1] +
                                point.weight[2] * gradient[2] + point.weight[3] * gradient[3];
      *J++ = g[0];
      *J++ = g[1];
      *J++ = g[2];
    }
  }
}

}  // namespace devsurf::terms
