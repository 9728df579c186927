#pragma once

#include <string>
#include <vector>

#include "devsurf/models/composite/CompositeDesign.h"

namespace devsurf::models::composite {

/// A vertex where the design's fold-angle targets ask for a motion its planar faces cannot make:
/// the faces around it would have to stretch or tear for every crease there to fold.
struct FoldConflict {
  int vertex = -1;
  /// Why, for a person: "two straight creases cross here: …".
  std::string reason;
};

/// Vertices of the design whose creases cannot all fold as their targets ask, judged from the
/// rigid-origami conditions of a single vertex. Only interior vertices are judged where every face
/// around is planar (R … R: it cannot bend, so the vertex is a spherical linkage) and every edge
/// there has a non-zero fold-angle target (a crease without one folds freely and may give the
/// freedom needed). With n such creases (n − 3 degrees of freedom):
///  * n = 2: the two must continue one straight line with one sign (a crease cannot bend at a
///    point, nor turn from mountain to valley);
///  * two straight lines crossing (n = 4, opposite sector angles summing to π): a flat sheet folds
///    along one of them at a time, never both;
///  * n = 3: rigid — no fold at all without one crease staying flat;
///  * n = 4: three creases of one kind and one of the other (a rigidly folding degree-4 vertex);
///  * n ≥ 5: not all of one kind (the creases around a point cannot all fold one way).
/// Vertices with curved faces around them (strips, cones) bend and are not judged.
/// Sector angles are measured in the design's current positions (planar faces keep them).
/// @param[in] design  a design CompositeTopology accepts
/// @returns the conflicts in vertex order; empty when there is none
/// @throws std::invalid_argument when the topology is not valid
std::vector<FoldConflict> foldConflicts(const CompositeDesign& design);

class CompositeTopology;
/// The same with the design's topology already built (a model's, per iterate).
std::vector<FoldConflict> foldConflicts(const CompositeDesign& design, const CompositeTopology& topology);

}  // namespace devsurf::models::composite
