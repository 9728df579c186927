#include "devsurf/terms/CheckerboardConformalityTerm.h"

#include <stdexcept>

namespace devsurf::terms {

CheckerboardConformalityTerm::CheckerboardConformalityTerm(
    std::string name, const std::vector<std::array<int, 4>>& faces,
    const std::vector<int>& meshOffsets, const std::vector<int>& unfoldingOffsets,
    int factorOffset)
    : Term(std::move(name)) {
  const std::string who = "CheckerboardConformalityTerm";
  if (meshOffsets.size() != unfoldingOffsets.size())
    throw std::invalid_argument(who + ": need one unfolding offset per mesh offset");
  requireValidFaces(who, faces, static_cast<int>(meshOffsets.size()));
  std::vector<std::pair<int, int>> blocks;
  appendPointBlocks(meshOffsets, blocks);
  appendPointBlocks(unfoldingOffsets, blocks);
  blocks.emplace_back(factorOffset, static_cast<int>(faces.size()));
  if (factorOffset < 0) throw std::invalid_argument(who + ": negative factor offset");
  requireDisjointBlocks(who, std::move(blocks));
  for (std::size_t f = 0; f < faces.size(); ++f)
    addCheckerboardFaceRows(rows_, who, faces[f], meshOffsets, unfoldingOffsets,
                            factorOffset + static_cast<int>(f));
}

}  // namespace devsurf::terms
