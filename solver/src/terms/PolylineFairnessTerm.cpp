#include "devsurf/terms/PolylineFairnessTerm.h"

#include <stdexcept>

#include "devsurf/terms/VertexProductRows.h"

namespace devsurf::terms {

PolylineFairnessTerm::PolylineFairnessTerm(std::string name,
                                           std::vector<std::array<int, 3>> triples,
                                           std::vector<int> pointOffsets)
    : Term(std::move(name)), triples_(std::move(triples)) {
  const std::string who = "PolylineFairnessTerm";
  std::vector<std::pair<int, int>> blocks;
  appendPointBlocks(pointOffsets, blocks);
  requireDisjointBlocks(who, std::move(blocks));
  const int count = static_cast<int>(pointOffsets.size());
  for (std::size_t t = 0; t < triples_.size(); ++t) {
    auto& triple = triples_[t];
    for (int& index : triple)
      if (index < 0 || index >= count)
        throw std::invalid_argument(who + ": triple " + std::to_string(t) +
                                    " has point index " + std::to_string(index) +
                                    " out of range [0, " + std::to_string(count) + ")");
    if (triple[0] == triple[1] || triple[1] == triple[2] || triple[0] == triple[2])
      throw std::invalid_argument(who + ": triple " + std::to_string(t) +
                                  " repeats a point");
    for (int& index : triple) index = pointOffsets[index];
  }
}

void PolylineFairnessTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  int row = 0;
  for (const auto& triple : triples_)
    for (int c = 0; c < 3; ++c, ++row)
      for (int offset : triple) entries.push_back({row, offset + c});
}

void PolylineFairnessTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                    double* jacobian) const {
  int row = 0;
  double* J = jacobian;
  for (const auto& [i, j, k] : triples_)
    for (int c = 0; c < 3; ++c, ++row) {
      residuals[row] = x[i + c] - 2.0 * x[j + c] + x[k + c];
      if (!J) continue;
      *J++ = 1.0;
      *J++ = -2.0;
      *J++ = 1.0;
    }
}

}  // namespace devsurf::terms
