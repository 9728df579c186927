#include "devsurf/terms/CheckerboardIsometryTerm.h"

#include <stdexcept>

namespace devsurf::terms {

CheckerboardIsometryTerm::CheckerboardIsometryTerm(std::string name,
                                                   const std::vector<std::array<int, 4>>& faces,
                                                   const std::vector<int>& meshOffsets,
                                                   const std::vector<int>& unfoldingOffsets)
    : Term(std::move(name)) {
  const std::string who = "CheckerboardIsometryTerm";
  if (meshOffsets.size() != unfoldingOffsets.size())
    throw std::invalid_argument(who + ": need one unfolding offset per mesh offset");
  requireValidFaces(who, faces, static_cast<int>(meshOffsets.size()));
  std::vector<std::pair<int, int>> blocks;
  appendPointBlocks(meshOffsets, blocks);
  appendPointBlocks(unfoldingOffsets, blocks);
  requireDisjointBlocks(who, std::move(blocks));
  for (const auto& face : faces)
    addCheckerboardFaceRows(rows_, who, face, meshOffsets, unfoldingOffsets);
}

}  // namespace devsurf::terms
