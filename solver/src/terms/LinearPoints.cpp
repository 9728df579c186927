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

void LinearPoints::appendStructure(int k, int row, std::vector<engine::JacobianEntry>& out) const {
  for (spline::EvaluationMatrix::InnerIterator it(weights, k); it; ++it)
    for (int c = 0; c < 3; ++c) out.push_back({row, offset + 3 * static_cast<int>(it.col()) + c});
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
