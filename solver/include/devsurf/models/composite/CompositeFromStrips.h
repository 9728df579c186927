#pragma once

#include <vector>

#include "devsurf/models/composite/CompositeDesign.h"
#include "devsurf/models/strip/StripCover.h"
#include "devsurf/models/strip/StripModel.h"

namespace devsurf::models::composite {

/// A composite made of strips whose boundaries were paired (000_… Fig. 10d: "such strips serve to
/// initialize a composite surface"): one face S R S R per strip; the two curves of a pairing become
/// one S edge (their control points averaged, the ends at the averaged corners), unpaired curves
/// S edges of the boundary, the end rulings R edges. Strips are turned (a and b exchanged) so that
/// all faces are oriented alike — a shared edge runs opposite ways in its two faces.
///
/// Paired curves must have the same degree and knots (read in their common direction); the strips'
/// approximation targets, handles and fixed points are not carried over.
/// @param[in] crease  the condition on every shared edge (CreaseKind::Fold: one sheet with curved
///                    folds, eq. 7; None: pieces joined along the edge, each developable)
/// @throws std::invalid_argument for closed or rational curves, differing knots, a curve in two
///         pairings, or pairings that cannot be oriented (a Möbius band)
CompositeDesign compositeFromStrips(std::vector<strip::StripDesign> strips,
                                    const std::vector<strip::BoundaryPairing>& pairings, CreaseKind crease);

/// Several composites as one design of as many separate parts (000_… Fig. 10e: "the bunny is
/// approximated by 6 composite surfaces"): vertices, edges and faces of part k follow those of
/// parts 0 … k−1, with their indices moved on, and so do fixed points, handles and tangent
/// continuity pairs.
/// @throws std::invalid_argument for no parts, or a part with a development (or its vertices),
///         fold-angle targets, a fold amount other than 1 or a drawing (they describe one sheet)
CompositeDesign disjointUnion(const std::vector<CompositeDesign>& parts);

}  // namespace devsurf::models::composite
