#pragma once

#include <vector>

#include "devsurf/io/CreasePattern.h"
#include "devsurf/io/FoldImport.h"

namespace devsurf::io {

/// A crease pattern cut open along its slits, and what the cutting did.
struct SlitCut {
  CreasePattern pattern;          ///< vertices doubled along the cuts, cut edges now boundary edges
  std::vector<int> sourceVertex;  ///< per vertex of `pattern`: the input vertex it copies
  std::vector<ImportNote> notes;  ///< by element of the input ("edges[4]: …")
};

/// Cuts the sheet along its C (cut) edges (FOLD's slits): around every vertex on a cut, the faces
/// are grouped into sectors — neighbours across an edge that is not a cut — and each sector after
/// the first gets its own copy of the vertex (same position in the development and the folded
/// state). A slit's tip inside the sheet has one sector and stays one vertex; a point along a slit
/// or where it meets the sheet's edge has two. Each side of a cut edge becomes a boundary (B)
/// edge of its face: the first keeps the edge's index, a second side is appended. A cut with no
/// face on either side, or one whose two sides would join the same two vertices (a single-edge
/// slit with both ends inside the sheet), stays as it is (joining its faces, folding freely), with a
/// note; so do all cuts when together they would part the sheet into pieces (a cut from edge to
/// edge: a design is one piece).
/// @param[in] pattern  a crease pattern with faces (validated)
/// @returns the cut pattern (validated), equal to the input when it has no cut edges
SlitCut cutAlongSlits(const CreasePattern& pattern);

}  // namespace devsurf::io
