#pragma once

#include <map>

#include "devsurf/models/composite/CompositeDesign.h"
#include "devsurf/models/composite/CompositeTopology.h"

namespace devsurf::models::composite {

/// The S edges sharing `edge`'s spline space through strip-like faces (a strip's two curves share
/// one space, 000_… §3.1; S R S faces too), `edge` included, each with whether its own direction
/// runs against `edge`'s (a parameter u of `edge` is begin + end − u there).
std::map<int, bool> linkedSplineEdges(const CompositeTopology& topology, int edge);

/// Edges cut in two: every face loop through an old edge e of `secondHalf` (e → the index of its
/// appended second half; e itself now runs from its v0 to the cut point) takes both halves in e's
/// place, in the loop's direction. `before`: the design's edges as they were before the cut.
void insertSecondHalves(CompositeDesign& design, const std::vector<CompositeEdge>& before, const std::map<int, int>& secondHalf);

/// Face `face` of the design split by a new R edge between its corner loop positions i and j (the
/// vertices where loop edges i − 1 and i, and j − 1 and j, meet; not neighbours): the face keeps
/// the loop from corner i to corner j plus the new edge, the other part (j to i plus the new edge)
/// is appended as the last face. Returns the new edge's index (the last edge).
int splitFaceLoop(CompositeDesign& design, int face, int i, int j);

/// A composite split along a new ruling (000_… §4.1, editing the labelled mesh): S edge `edge` is
/// cut at the fraction `at` ∈ (0, 1) of its parameter domain (in its own direction), and so is
/// every S edge linked to it (linkedSplineEdges) at the same parameter, by knot insertion — no
/// curve moves. Every strip-like face along the chain gets a new R edge between the cut points of
/// its two curves (S R S R and S R S faces) or from the cut point to its apex (cones), and
/// becomes two faces. The cut of edge e keeps index e for its first half (from v0); the second
/// halves are appended as new edges, the cut points as new vertices, the new rulings after them.
/// Fold targets at an S edge's v1 end, tangent-continuity pairs at v1 and control points of
/// fixed points and handles follow the half they are on; a seam edge's halves are both seam edges;
/// the two halves of every cut edge are a new tangent-continuity pair (one smooth curve, one crease
/// in the exports).
///
/// @param[in] design    the composite, consistent with `topology`
/// @param[in] topology  CompositeTopology(design)
/// @param[in] edge      an S edge of the design
/// @param[in] at        fraction of the edge's parameter domain, 0 < at < 1
/// @returns the split design (its development vertices cleared: its sampling changed)
/// @throws std::invalid_argument naming the field ("edge", "at") when the edge is not S, `at` is
///         outside (0, 1) or a half would have fewer than degree + 1 control points, and
///         quoting CompositeTopology when the result is not a composite
CompositeDesign splitAlongRuling(const CompositeDesign& design, const CompositeTopology& topology, int edge, double at);

}  // namespace devsurf::models::composite
