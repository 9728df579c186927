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
///  * cut (C) edges: the sheet is cut along them first (io::cutAlongSlits: points along a slit
///    doubled, one per side; each side a boundary edge), so a slit opens when the sheet folds;
///    designVertexOf and designEdgeOf name a doubled point's and a cut edge's first copy;
///  * fixed: the vertices of the face of largest area in the development, so the sheet keeps its
///    place while the rest is moved;
///  * development management on (developmentSamples), so the crease pattern and its exports follow,
///    with every vertex of the development pinned where the pattern has it (domain corners): the
///    sheet bends, it never stretches;
///  * fold-angle targets (design.foldAngles) from the edges' fold angles; on a flat sheet, mountain
///    and valley edges without one aim at ∓180° (noted) and foldAmount starts at 0 (flat), with a
///    folded state at 1.
/// A pattern with curved creases (hasCurvedCreases) goes to compositeFromCurvedCreasePattern.
/// @throws std::invalid_argument when the pattern has no faces or does not validate
CreasePatternComposite compositeFromCreasePattern(const io::CreasePattern& pattern, int developmentSamples = 2);

/// Whether some chain of edges sharing a CreaseEdge::curve id ≥ 0 is not straight (principal
/// deviation above 1e-6 × the pattern's diagonal).
bool hasCurvedCreases(const io::CreasePattern& pattern);

/// The fold-angle target (degrees) of a curved crease asked for a full fold (±180°): only a straight
/// crease lays its two sides onto each other.
inline constexpr double kCurvedFullFoldDeg = 90.0;

/// Turns a flat crease pattern whose creases may be curved (chains of edges sharing a curve id, as
/// io::importSvgText makes them) into a composite whose faces are valid (000_… §3.1):
///  * sides: a face's boundary is cut at its corners (vertices where strokes meet, turn or end)
///    into curved sides (S edges, a cubic B-spline fitted by least squares to the polyline), straight
///    interior creases (R edges) and straight pieces of the outline (R or S, as the face needs);
///  * rulings proposed: a face with curved sides needs two straight ends (S R S R; one may shrink
///    to a point, S R S; or meet the other at an apex, S R R). Of all choices the one with the fewest
///    joints inside its two chains is taken; every joint gets a straight ruling to the other chain
///    (near its point at the same fraction of arc length, to a joint of the other chain when one is
///    near), inside the face, one at a time until no face has a joint left. A proposed ruling is an
///    R edge with crease "smooth" (the paper does not fold there); a crease cut by one keeps
///    tangent continuity;
///  * creases: curved mountain and valley creases are curved folds (crease "fold", 000_… eq. 7),
///    curved flat lines "smooth", straight creases R edges that fold freely;
///  * fixed: the corners of the face of largest area;
///  * S edges share one spline space: cubic, clamped uniform, at least 6 control points;
///  * development management on (at least 4 samples per span), every corner pinned where the drawing has it and every curved
///    side's samples kept on its drawn curve (domain curves), so the sheet is the drawing;
///  * fold-angle targets at every hinge of a crease with an angle (CompositeHinges), flat mountain
///    and valley creases without one aiming at ∓180°, curved ones at a full fold (±180°: no angle,
///    or one of 180°) at ±kCurvedFullFoldDeg, with a note; foldAmount 0 (flat).
/// @throws std::invalid_argument naming the face ("faces[3]: …") when no layout exists: a face
///         bounded by one closed curve, two curves meeting at both ends, a crease inside a chain,
///         or no ruling fitting inside the face
CreasePatternComposite compositeFromCurvedCreasePattern(const io::CreasePattern& pattern, int developmentSamples = 2);

}  // namespace devsurf::models::composite
