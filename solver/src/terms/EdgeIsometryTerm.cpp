#include "devsurf/terms/EdgeIsometryTerm.h"

#include <algorithm>
#include <stdexcept>

namespace devsurf::terms {
namespace {

/// Adds coefficient·(entry) to a merged list of (base, coefficient).
void accumulate(std::vector<std::pair<int, double>>& list, int base, double coefficient) {
  for (auto& entry : list)
    if (entry.first == base) {
      entry.second += coefficient;
      return;
    }
  list.emplace_back(base, coefficient);
}

}  // namespace

EdgeIsometryTerm::EdgeIsometryTerm(std::string name, std::vector<LinearPoints> spatial,
                                   std::vector<int> developedOffsets,
                                   std::vector<std::pair<int, int>> pairs)
    : Term(std::move(name)) {
  // Vertex index → (point set, row).
  std::vector<std::pair<int, int>> vertex;
  for (int s = 0; s < static_cast<int>(spatial.size()); ++s)
    for (int k = 0; k < spatial[s].rows(); ++k) vertex.emplace_back(s, k);
  const int numVertices = static_cast<int>(vertex.size());
  if (static_cast<int>(developedOffsets.size()) != numVertices)
    throw std::invalid_argument("EdgeIsometryTerm: need one developed vertex per 3D vertex");

  rows_.reserve(pairs.size());
  for (const auto& [i, j] : pairs) {
    if (i < 0 || j < 0 || i >= numVertices || j >= numVertices || i == j)
      throw std::invalid_argument("EdgeIsometryTerm: invalid vertex pair");
    Row row;
    for (const auto& [v, sign] :
         {std::pair<int, double>{i, 1.0}, std::pair<int, double>{j, -1.0}}) {
      const LinearPoints& p = spatial[vertex[v].first];
      for (spline::EvaluationMatrix::InnerIterator it(p.weights, vertex[v].second); it; ++it)
        accumulate(row.spatial, p.offset + 3 * static_cast<int>(it.col()), sign * it.value());
      accumulate(row.developed, developedOffsets[v], sign);
    }
    std::vector<int> variables;
    for (const auto& e : row.spatial)
      for (int c = 0; c < 3; ++c) variables.push_back(e.first + c);
    for (const auto& e : row.developed)
      for (int c = 0; c < 2; ++c) variables.push_back(e.first + c);
    std::sort(variables.begin(), variables.end());
    if (std::adjacent_find(variables.begin(), variables.end()) != variables.end())
      throw std::invalid_argument(
          "EdgeIsometryTerm: a row lists a variable twice (3D and 2D variables overlap)");
    rows_.push_back(std::move(row));
  }
}

EdgeIsometryTerm::EdgeIsometryTerm(std::string name, LinearPoints spatial,
                                   std::vector<int> developedOffsets,
                                   std::vector<std::pair<int, int>> pairs)
    : EdgeIsometryTerm(std::move(name), std::vector<LinearPoints>{std::move(spatial)},
                       std::move(developedOffsets), std::move(pairs)) {}

void EdgeIsometryTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int r = 0; r < numResiduals(); ++r) {
    for (const auto& e : rows_[r].spatial)
      for (int c = 0; c < 3; ++c) entries.push_back({r, e.first + c});
    for (const auto& e : rows_[r].developed)
      for (int c = 0; c < 2; ++c) entries.push_back({r, e.first + c});
  }
}

void EdgeIsometryTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                double* jacobian) const {
  double* J = jacobian;
  for (int r = 0; r < numResiduals(); ++r) {
    const Row& row = rows_[r];
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    for (const auto& [base, coefficient] : row.spatial) d += coefficient * x.segment<3>(base);
    Eigen::Vector2d e = Eigen::Vector2d::Zero();
    for (const auto& [base, coefficient] : row.developed) e += coefficient * x.segment<2>(base);
    residuals[r] = d.squaredNorm() - e.squaredNorm();
    if (!J) continue;
    for (const auto& entry : row.spatial)
      for (int c = 0; c < 3; ++c) *J++ = 2.0 * entry.second * d[c];
    for (const auto& entry : row.developed)
      for (int c = 0; c < 2; ++c) *J++ = -2.0 * entry.second * e[c];
  }
}

std::vector<std::pair<int, int>> gridEdgeAndDiagonalPairs(int U, int V) {
  if (U < 1 || V < 1) throw std::invalid_argument("gridEdgeAndDiagonalPairs: empty grid");
  const auto id = [U](int i, int j) { return j * U + i; };
  std::vector<std::pair<int, int>> pairs;
  for (int j = 0; j < V; ++j)
    for (int i = 0; i + 1 < U; ++i) pairs.emplace_back(id(i, j), id(i + 1, j));
  for (int j = 0; j + 1 < V; ++j)
    for (int i = 0; i < U; ++i) pairs.emplace_back(id(i, j), id(i, j + 1));
  for (int j = 0; j + 1 < V; ++j)
    for (int i = 0; i + 1 < U; ++i) {
      pairs.emplace_back(id(i, j), id(i + 1, j + 1));
      pairs.emplace_back(id(i + 1, j), id(i, j + 1));
    }
  return pairs;
}

}  // namespace devsurf::terms
