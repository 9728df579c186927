#include "devsurf/terms/LinearPoints.h"

#include <algorithm>
#include <utility>
#include <vector>

namespace devsurf::terms {

LinearPoints LinearPoints::identity(int count, int offset) {
  LinearPoints p;
  p.weights.resize(count, count);
  p.weights.setIdentity();
  p.weights.makeCompressed();
  p.offset = offset;
  return p;
}

Eigen::Vector3d LinearPoints::point(const Eigen::VectorXd& x, int k) const {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (spline::EvaluationMatrix::InnerIterator it(weights, k); it; ++it)
    p += it.value() * x.segment<3>(offset + 3 * static_cast<int>(it.col()));
  return p;
}

void LinearPoints::appendStructure(int k, int row, std::vector<engine::JacobianEntry>& out) const {
  for (spline::EvaluationMatrix::InnerIterator it(weights, k); it; ++it)
    for (int c = 0; c < 3; ++c) out.push_back({row, offset + 3 * static_cast<int>(it.col()) + c});
}

double* LinearPoints::writeJacobian(int k, const Eigen::Vector3d& v, double scale,
                                    double* out) const {
  for (spline::EvaluationMatrix::InnerIterator it(weights, k); it; ++it) {
    const double w = scale * it.value();
    *out++ = w * v[0];
    *out++ = w * v[1];
    *out++ = w * v[2];
  }
  return out;
}

bool hasDuplicateEntries(const engine::Term& term) {
  std::vector<engine::JacobianEntry> entries;
  term.jacobianStructure(entries);
  std::vector<std::pair<int, int>> keys;
  keys.reserve(entries.size());
  for (const auto& e : entries) keys.emplace_back(e.row, e.variable);
  std::sort(keys.begin(), keys.end());
  return std::adjacent_find(keys.begin(), keys.end()) != keys.end();
}

}  // namespace devsurf::terms
