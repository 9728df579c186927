#pragma once

#include <vector>

#include "devsurf/io/CreasePattern.h"
#include "devsurf/io/CreaseStrokes.h"
#include "devsurf/io/FoldImport.h"

namespace devsurf::io {

/// The curved creases of a crease pattern read from a FOLD file, as strokes to lay out again.
struct FoldCurvedCreases {
  /// Every mountain, valley, boundary and cut line of the file as a stroke (development
  /// coordinates, the file's units) when some mountain or valley line is curved; empty otherwise
  /// (a pattern of straight creases is imported as it is).
  std::vector<CreaseStroke> strokes;
  std::vector<ImportNote> notes;
};

/// Finds the curved creases of a FOLD crease pattern. A FOLD file holds only straight edges: a
/// curved crease is a polyline of them (Origami Simulator's, devsurf's own FOLD export), with flat
/// edges (F, U) between the creases as the facets or rulings of the folded surface. Lines are
/// the chains of M, V, B and C edges joined at vertices where exactly two of those edges meet,
/// with the same assignment, turning by at most `maxTurnDeg` (a straight creases' vertex, where
/// more lines meet or one turns sharply, ends them). When a mountain or valley chain bends off its
/// chord by more than kStraightStrokeFraction × the pattern's diagonal and twice the file's last
/// decimal (a straight crease written to three decimals is not bent by its rounding) — and, in a
/// file devsurf wrote, lies on a curve it marked — every chain becomes a
/// stroke (closed chains closed), with the fold angle the length-weighted mean of its edges'
/// `edges_foldAngle` (the edges without one left out of the mean; none: no angle), and the flat
/// edges are left out: the curved-crease composite proposes its own rulings. Notes say what was
/// left out (flat edges, the folded form) and where a crease's angles vary along it.
/// @param[in] pattern     as importFoldDocument made it (faces, edges, assignments, angles)
/// @param[in] edgeCurves  per edge, the curve devsurf's export marked it with (FoldImport::edgeCurves;
///                        −1 unmarked; empty: none): a chain also ends where the mark changes, so
///                        each exported curve comes back as one crease with its own angle
/// @param[in] maxTurnDeg  largest turn between two edges of one chain, degrees
FoldCurvedCreases foldCurvedCreases(const CreasePattern& pattern, const std::vector<int>& edgeCurves = {},
                                    double maxTurnDeg = 35.0);

}  // namespace devsurf::io
