#include "devsurf/terms/MappingRegularityTerm.h"

#include <stdexcept>

namespace devsurf::terms {

MappingRegularityTerm::MappingRegularityTerm(std::string name,
                                             const std::vector<std::array<int, 4>>& quadruples,
                                             const std::vector<int>& meshOffsets,
                                             const std::vector<int>& unfoldingOffsets)
    : Term(std::move(name)) {
  const std::string who = "MappingRegularityTerm";
  if (meshOffsets.size() != unfoldingOffsets.size())
    throw std::invalid_argument(who + ": need one unfolding offset per mesh offset");
  std::vector<std::pair<int, int>> blocks;
  appendPointBlocks(meshOffsets, blocks);
  appendPointBlocks(unfoldingOffsets, blocks);
  requireDisjointBlocks(who, std::move(blocks));
  const int count = static_cast<int>(meshOffsets.size());
  for (std::size_t q = 0; q < quadruples.size(); ++q) {
    const auto& [i, j, k, l] = quadruples[q];
    for (int index : quadruples[q])
      if (index < 0 || index >= count)
        throw std::invalid_argument(who + ": quadruple " + std::to_string(q) +
                                    " has vertex index " + std::to_string(index) +
                                    " out of range [0, " + std::to_string(count) + ")");
    if (i == j || j == k || i == k || l == j)
      throw std::invalid_argument(who + ": quadruple " + std::to_string(q) +
                                  " repeats a vertex (need i, j, k distinct and l != j)");
    // ⟨v_i − 2v_j + v_k, v_l − v_j⟩: α on (i, j, k, l) = (1, −2, 1, 0), β = (0, −1, 0, 1).
    const int vertices[4] = {i, j, k, l};
    const double alpha[4] = {1.0, -2.0, 1.0, 0.0}, beta[4] = {0.0, -1.0, 0.0, 1.0};
    rows_.add(who, vertices, alpha, beta, 4, meshOffsets, unfoldingOffsets);
  }
}

}  // namespace devsurf::terms
