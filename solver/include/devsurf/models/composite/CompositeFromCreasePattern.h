#pragma once

#include <vector>

#include "devsurf/io/CreasePattern.h"
#include "devsurf/io/FoldImport.h"
#include "devsurf/models/composite/CompositeDesign.h"

namespace devsurf::models::composite {

/// A composite made from a straight-crease pattern, and what the conversion changed.
struct CreasePatternComposite {
  CompositeDesign design;
  /// Notes by element of the crease pattern ("edges[3]", "faces[2]").
  std::vector<io::ImportNote> notes;
  /// Per vertex of the pattern: its vertex in the design, −1 when no face uses it.
  std::vector<int> designVertexOf;
  /// Per edge of the pattern: its edge in the design, −1 when it was merged away (a flat edge
  /// inside a planar face) or is used by no face.
  std::vector<int> designEdgeOf;
};

/// Turns a crease pattern with faces (io::CreasePattern, e.g. from io::importFoldDocument) into a
/// composite of planar faces (000_… §3.1, faces R … R) joined along R edges, which fold freely:
///  * vertices: the folded state when the pattern has one, else the development at z = 0;
///  * faces: the pattern's faces, with neighbours across flat (F) edges merged into one planar
///    face when the union is a simple polygon (and, with a folded state, the edge is flat there:
///    |measured fold angle| < 1°); where a union would have a hole or pinch, the faces stay apart
///    and the flat edge is noted;
///  * cut (C) edges: noted — the composite has no slits, so they join their faces like a fold;
///  * fixed: the vertices of the face of largest area in the development, so the sheet keeps its
///    place while the rest is moved;
///  * development management on (developmentSamples), so the crease pattern and its exports follow,
///    with every vertex of the development pinned where the pattern has it (domain corners): the
///    sheet bends, it never stretches;
///  * fold-angle targets (design.foldAngles) from the edges' fold angles; on a flat sheet, mountain
///    and valley edges without one aim at ∓180° (noted) and foldAmount starts at 0 (flat), with a
///    folded state at 1.
/// @throws std::invalid_argument when the pattern has no faces or does not validate
CreasePatternComposite compositeFromCreasePattern(const io::CreasePattern& pattern, int developmentSamples = 2);

}  // namespace devsurf::models::composite
