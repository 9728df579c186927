#include "devsurf/models/composite/CompositeHinges.h"

#include <optional>

#include <Eigen/Geometry>

namespace devsurf::models::composite {

namespace {

PointSlot vertexSlot(int v) { return {v, -1, 0}; }

/// The point next to vertex v in face f along f's other boundary edge at v (not `skip`): the
/// other vertex of an R edge, the control point after v of an S edge. `rulingOnly`: only an R
/// edge will do (the hinge of a curved crease needs the face's ruling there).
std::optional<PointSlot> facePointNextTo(const CompositeTopology& topology, int f, int v, int skip, bool rulingOnly) {
  for (const OrientedEdge& oe : topology.face(f).loop) {
    if (oe.edge == skip) continue;
    const auto ends = topology.edgeVertices(oe.edge);
    if (ends[0] != v && ends[1] != v) continue;
    if (topology.edgeType(oe.edge) == EdgeType::Ruling) return vertexSlot(ends[0] == v ? ends[1] : ends[0]);
    if (rulingOnly) return std::nullopt;
    const std::vector<PointSlot> slots = topology.controlSlots(oe.edge, ends[0] != v);
    return slots[1];
  }
  return std::nullopt;
}

bool spansPlane(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& p) {
  const Eigen::Vector3d e = b - a, q = p - a;
  return e.cross(q).norm() > 1e-9 * e.norm() * q.norm() && q.norm() > 0.0;
}

}  // namespace

bool hasFoldHinge(const CompositeTopology& topology, int edge, int end) {
  if (edge < 0 || edge >= topology.numEdges() || !topology.edge(edge).interior()) return false;
  const EdgeInfo& info = topology.edge(edge);
  const auto ends = topology.edgeVertices(edge);
  if (topology.edgeType(edge) == EdgeType::Ruling) return end == 0;
  if (end != 0 && end != 1) return false;
  const int v = ends[end];
  return facePointNextTo(topology, info.faces[0], v, edge, true) && facePointNextTo(topology, info.faces[1], v, edge, true);
}

std::vector<FoldHinge> foldHinges(const CompositeTopology& topology,
                                  const std::function<Eigen::Vector3d(const PointSlot&)>& pointAt) {
  std::vector<FoldHinge> hinges;
  for (int e = 0; e < topology.numEdges(); ++e) {
    if (!topology.edge(e).interior()) continue;
    const EdgeInfo& info = topology.edge(e);
    const auto ends = topology.edgeVertices(e);
    if (topology.edgeType(e) == EdgeType::Ruling) {
      FoldHinge h{e, 0, vertexSlot(ends[0]), vertexSlot(ends[1]), {}, {}};
      bool found = false;
      for (int v : {ends[0], ends[1]}) {
        const auto c = facePointNextTo(topology, info.faces[0], v, e, false);
        const auto d = facePointNextTo(topology, info.faces[1], v, e, false);
        if (!c || !d) continue;
        h.c = *c;
        h.d = *d;
        found = true;
        const Eigen::Vector3d a = pointAt(h.a), b = pointAt(h.b);
        if (spansPlane(a, b, pointAt(h.c)) && spansPlane(a, b, pointAt(h.d))) break;
      }
      if (found && !(h.c == h.d) && !(h.c == h.a) && !(h.c == h.b) && !(h.d == h.a) && !(h.d == h.b)) hinges.push_back(h);
      continue;
    }
    // A curved crease: a hinge at each end whose faces both have a ruling there. At v1 the axis
    // runs against the edge, so the faces' sides swap.
    const std::vector<PointSlot> slots = topology.controlSlots(e);
    for (int end = 0; end < 2; ++end) {
      const int v = ends[end];
      const int left = info.faces[end == 0 ? 0 : 1], right = info.faces[end == 0 ? 1 : 0];
      const auto c = facePointNextTo(topology, left, v, e, true);
      const auto d = facePointNextTo(topology, right, v, e, true);
      if (!c || !d) continue;
      const PointSlot a = slots[end == 0 ? 0 : slots.size() - 1];
      const PointSlot b = slots[end == 0 ? 1 : slots.size() - 2];
      if (a == *c || a == *d || b == *c || b == *d || *c == *d) continue;  // a degenerate corner
      hinges.push_back({e, end, a, b, *c, *d});
    }
  }
  return hinges;
}

}  // namespace devsurf::models::composite
