#include "devsurf/terms/VertexCoincidenceTerm.h"

#include <stdexcept>

#include "devsurf/terms/VertexProductRows.h"

namespace devsurf::terms {

VertexCoincidenceTerm::VertexCoincidenceTerm(std::string name,
                                             std::vector<std::pair<int, int>> pairs,
                                             std::vector<int> pointOffsets)
    : Term(std::move(name)), pairs_(std::move(pairs)) {
  const std::string who = "VertexCoincidenceTerm";
  std::vector<std::pair<int, int>> blocks;
  appendPointBlocks(pointOffsets, blocks);
  requireDisjointBlocks(who, std::move(blocks));
  const int count = static_cast<int>(pointOffsets.size());
  for (std::size_t p = 0; p < pairs_.size(); ++p) {
    auto& [i, j] = pairs_[p];
    for (int index : {i, j})
      if (index < 0 || index >= count)
        throw std::invalid_argument(who + ": pair " + std::to_string(p) + " has point index " +
                                    std::to_string(index) + " out of range [0, " +
                                    std::to_string(count) + ")");
    if (i == j)
      throw std::invalid_argument(who + ": pair " + std::to_string(p) + " glues point " +
                                  std::to_string(i) + " to itself");
    i = pointOffsets[i];
    j = pointOffsets[j];
  }
}

void VertexCoincidenceTerm::jacobianStructure(
    std::vector<engine::JacobianEntry>& entries) const {
  int row = 0;
  for (const auto& [i, j] : pairs_)
    for (int c = 0; c < 3; ++c, ++row) {
      entries.push_back({row, i + c});
      entries.push_back({row, j + c});
    }
}

void VertexCoincidenceTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                     double* jacobian) const {
  int row = 0;
  double* J = jacobian;
  for (const auto& [i, j] : pairs_)
    for (int c = 0; c < 3; ++c, ++row) {
      residuals[row] = x[i + c] - x[j + c];
      if (!J) continue;
      *J++ = 1.0;
      *J++ = -1.0;
    }
}

}  // namespace devsurf::terms
