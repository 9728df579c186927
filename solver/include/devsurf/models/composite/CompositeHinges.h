#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>

#include "devsurf/models/composite/CompositeTopology.h"

namespace devsurf::models::composite {

/// A hinge of a composite's crease, the four points whose dihedral angle is its fold angle
/// (terms::hingeFoldAngle: axis a → b, c in the face to its left, d in the face to its right).
///
/// An interior R edge is one hinge (end 0): axis v0 → v1; c, d the points next to an end vertex in
/// each face (the other vertex of an R edge, the first control point of an S edge — along a
/// ruling a developable's tangent plane does not turn, so any of them spans the face's plane).
/// An interior S edge is a hinge at each end where both faces have a ruling: axis from the end
/// vertex along the crease's first control-polygon leg, c, d the far ends of the two rulings.
struct FoldHinge {
  int edge = -1;
  int end = 0;  ///< 0: at v0 (R edges: the only hinge), 1: at v1 (S edges)
  PointSlot a, b, c, d;
};

/// Every hinge of the composite. `pointAt` gives a slot's current position: an R edge whose
/// face points at v0 are collinear with it (a degenerate plane) takes them at v1 instead.
std::vector<FoldHinge> foldHinges(const CompositeTopology& topology,
                                  const std::function<Eigen::Vector3d(const PointSlot&)>& pointAt);

/// Whether interior edge `edge` has a hinge at `end` (topology only: S edges need a ruling in
/// both faces at that end).
bool hasFoldHinge(const CompositeTopology& topology, int edge, int end);

}  // namespace devsurf::models::composite
