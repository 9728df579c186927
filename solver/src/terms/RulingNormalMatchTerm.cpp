#include "devsurf/terms/RulingNormalMatchTerm.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

namespace devsurf::terms {
namespace {

/// [v]×: the matrix of w ↦ v × w.
Eigen::Matrix3d crossMatrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

}  // namespace

RulingNormalMatchTerm::RulingNormalMatchTerm(std::string name, const LinearPoints& t1, const LinearPoints& d1,
                                             const LinearPoints& t2, const LinearPoints& d2,
                                             std::vector<double> orientation1, std::vector<double> orientation2)
    : Term(std::move(name)), count_(t1.rows()), orientation1_(std::move(orientation1)), orientation2_(std::move(orientation2)) {
  if (d1.rows() != count_ || t2.rows() != count_ || d2.rows() != count_)
    throw std::invalid_argument("RulingNormalMatchTerm: all point sets need the same rows");
  if (static_cast<int>(orientation1_.size()) != count_ || static_cast<int>(orientation2_.size()) != count_)
    throw std::invalid_argument("RulingNormalMatchTerm: need one orientation per pair and side");
  for (int k = 0; k < count_; ++k)
    if (std::abs(orientation1_[static_cast<std::size_t>(k)]) != 1.0 || std::abs(orientation2_[static_cast<std::size_t>(k)]) != 1.0)
      throw std::invalid_argument("RulingNormalMatchTerm: orientations must be +1 or -1");
  const LinearPoints* sets[4] = {&t1, &d1, &t2, &d2};
  pairStart_.push_back(0);
  std::vector<PairPoint> pair;
  for (int k = 0; k < count_; ++k) {
    pair.clear();
    for (std::size_t s = 0; s < 4; ++s)
      for (spline::EvaluationMatrix::InnerIterator it(sets[s]->weights, k); it; ++it) {
        const int variable = sets[s]->offset + 3 * static_cast<int>(it.col());
        auto found = std::find_if(pair.begin(), pair.end(), [variable](const PairPoint& p) { return p.variable == variable; });
        if (found == pair.end()) {
          pair.push_back({variable, {}});
          found = pair.end() - 1;
        }
        found->weight[s] += it.value();
      }
    std::sort(pair.begin(), pair.end(), [](const PairPoint& p, const PairPoint& q) { return p.variable < q.variable; });
    points_.insert(points_.end(), pair.begin(), pair.end());
    pairStart_.push_back(static_cast<int>(points_.size()));
  }
}

void RulingNormalMatchTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int k = 0; k < count_; ++k)
    for (int c = 0; c < 3; ++c)
      for (int p = pairStart_[k]; p < pairStart_[k + 1]; ++p)
        for (int d = 0; d < 3; ++d) entries.push_back({3 * k + c, points_[static_cast<std::size_t>(p)].variable + d});
}

void RulingNormalMatchTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  double* J = jacobian;
  for (int k = 0; k < count_; ++k) {
    std::array<Eigen::Vector3d, 4> v;  // t1, d1, t2, d2
    v.fill(Eigen::Vector3d::Zero());
    for (int p = pairStart_[k]; p < pairStart_[k + 1]; ++p) {
      const PairPoint& point = points_[static_cast<std::size_t>(p)];
      for (std::size_t s = 0; s < 4; ++s) v[s] += point.weight[s] * x.segment<3>(point.variable);
    }
    const Eigen::Vector3d g1 = v[0].cross(v[1]), g2 = v[2].cross(v[3]);
    const double length1 = g1.norm(), length2 = g2.norm();
    const int pointsOfPair = pairStart_[k + 1] - pairStart_[k];
    const bool degenerate = !(length1 > 1e-12 * v[0].norm() * v[1].norm()) || !(length2 > 1e-12 * v[2].norm() * v[3].norm());
    if (degenerate) {
      std::fill_n(residuals + 3 * k, 3, 0.0);
      if (J) J = std::fill_n(J, 9 * pointsOfPair, 0.0);
      continue;
    }
    const Eigen::Vector3d h1 = g1 / length1, h2 = g2 / length2;
    const double o1 = orientation1_[static_cast<std::size_t>(k)], o2 = orientation2_[static_cast<std::size_t>(k)];
    const Eigen::Vector3d r = o1 * h1 - o2 * h2;
    residuals[3 * k] = r.x();
    residuals[3 * k + 1] = r.y();
    residuals[3 * k + 2] = r.z();
    if (!J) continue;
    // ∂ĝ/∂g = (I − ĝĝᵀ)/|g|; g = t × d: δg = δt × d = −[d]× δt, and t × δd = [t]× δd.
    const Eigen::Matrix3d P1 = o1 * (Eigen::Matrix3d::Identity() - h1 * h1.transpose()) / length1;
    const Eigen::Matrix3d P2 = -o2 * (Eigen::Matrix3d::Identity() - h2 * h2.transpose()) / length2;
    const std::array<Eigen::Matrix3d, 4> partial = {-P1 * crossMatrix(v[1]), P1 * crossMatrix(v[0]),
                                                    -P2 * crossMatrix(v[3]), P2 * crossMatrix(v[2])};
    // Rows 3k + c, each over the pair's points in order, three columns per point (jacobianStructure).
    for (int c = 0; c < 3; ++c)
      for (int p = pairStart_[k]; p < pairStart_[k + 1]; ++p) {
        const PairPoint& point = points_[static_cast<std::size_t>(p)];
        const Eigen::RowVector3d row = point.weight[0] * partial[0].row(c) + point.weight[1] * partial[1].row(c) +
                                       point.weight[2] * partial[2].row(c) + point.weight[3] * partial[3].row(c);
        *J++ = row[0];
        *J++ = row[1];
        *J++ = row[2];
      }
  }
}

}  // namespace devsurf::terms
