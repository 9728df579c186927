#include "devsurf/models/composite/CompositeTopology.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>

#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

namespace devsurf::models::composite {

namespace {
struct MeshTraits : public OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
  typedef OpenMesh::Vec3d Normal;
};
}  // namespace

struct CompositeTopology::Mesh {
  OpenMesh::PolyMesh_ArrayKernelT<MeshTraits> mesh;
  OpenMesh::EPropHandleT<int> sceneEdge;  ///< index into CompositeDesign::edges
  OpenMesh::FPropHandleT<int> sceneFace;  ///< index into CompositeDesign::faces
};

namespace {

[[noreturn]] void failTopology(const std::string& message) { throw std::invalid_argument(message); }

/// OpenMesh writes a face it cannot add to its global error stream; the topology reports that
/// face itself, by path. The stream is switched off once per process (a thread-safe static):
/// saving, disabling and restoring its switch around every build raced between sessions that
/// build composites on different worker threads (ThreadSanitizer, hostile client).
void silenceOpenMeshErrors() {
  static const bool silenced = [] {
    omerr().disable();
    return true;
  }();
  (void)silenced;
}

std::string edgePath(int e) { return "edges[" + std::to_string(e) + "]"; }
std::string facePath(int f) { return "faces[" + std::to_string(f) + "]"; }

std::string pointText(const Eigen::Vector3d& p) {
  std::ostringstream s;
  s << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return s.str();
}

std::vector<double> reversedEdgeKnots(const spline::KnotVector& k) {
  const std::vector<double>& t = k.knots();
  const double sum = k.domainBegin() + k.domainEnd();
  std::vector<double> r(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) r[i] = sum - t[t.size() - 1 - i];
  return r;
}

bool topologySameKnots(const spline::KnotVector& x, const spline::KnotVector& y) {
  if (x.degree() != y.degree() || x.knots().size() != y.knots().size()) return false;
  const double tol = 1e-12 * std::max(1.0, x.domainEnd() - x.domainBegin());
  for (std::size_t i = 0; i < x.knots().size(); ++i)
    if (std::abs(x.knots()[i] - y.knots()[i]) > tol) return false;
  return true;
}

std::string labelsText(const std::vector<EdgeType>& labels) {
  std::string s;
  for (EdgeType t : labels) s += (s.empty() ? "" : " ") + std::string(edgeTypeName(t));
  return s;
}

}  // namespace

const char* edgeTypeName(EdgeType t) { return t == EdgeType::Ruling ? "R" : "S"; }

const char* creaseKindName(CreaseKind k) {
  switch (k) {
    case CreaseKind::Fold: return "fold";
    case CreaseKind::Geodesic: return "geodesic";
    case CreaseKind::Smooth: return "smooth";
    case CreaseKind::Straight: return "straight";
    case CreaseKind::None: break;
  }
  return "none";
}

const char* faceTypeName(FaceType t) {
  switch (t) {
    case FaceType::Strip: return "strip (S R S R)";
    case FaceType::DegenerateStrip: return "strip with a degenerate ruling (S R S)";
    case FaceType::Cone: return "cone (S R R)";
    case FaceType::Planar: return "planar polygon (R…R)";
  }
  return "?";
}

CompositeTopology::~CompositeTopology() = default;
CompositeTopology::CompositeTopology(CompositeTopology&&) noexcept = default;
CompositeTopology& CompositeTopology::operator=(CompositeTopology&&) noexcept = default;

CompositeTopology::CompositeTopology(const CompositeDesign& design) : mesh_(std::make_unique<Mesh>()) {
  numVertices_ = static_cast<int>(design.vertices.rows());
  if (numVertices_ < 3) failTopology("vertices: a composite needs at least 3 vertices, got " + std::to_string(numVertices_));
  const int numEdges = static_cast<int>(design.edges.size());
  const int numFaces = static_cast<int>(design.faces.size());
  if (numFaces < 1) failTopology("faces: a composite needs at least one face");
  double scale = 1.0;
  {
    const Eigen::RowVector3d lo = design.vertices.colwise().minCoeff();
    const Eigen::RowVector3d hi = design.vertices.colwise().maxCoeff();
    scale = std::max(1.0, (hi - lo).norm());
  }

  // ---- edges ----
  types_.resize(numEdges);
  ends_.resize(numEdges);
  interior_.assign(numEdges, 0);
  edgeKnots_.resize(numEdges);
  edges_.assign(numEdges, EdgeInfo{});
  std::map<std::pair<int, int>, int> byVertices;
  for (int e = 0; e < numEdges; ++e) {
    const CompositeEdge& edge = design.edges[e];
    const std::string path = edgePath(e);
    for (int v : {edge.v0, edge.v1})
      if (v < 0 || v >= numVertices_)
        failTopology(path + ".v: vertex " + std::to_string(v) + " does not exist (" + std::to_string(numVertices_) +
             " vertices)");
    if (edge.v0 == edge.v1) failTopology(path + ".v: an edge joins two different vertices, got " + std::to_string(edge.v0) + " twice");
    const auto key = std::minmax(edge.v0, edge.v1);
    const auto [it, inserted] = byVertices.emplace(std::make_pair(key.first, key.second), e);
    if (!inserted)
      failTopology(path + ".v: joins the same vertices as edges[" + std::to_string(it->second) +
           "] (parallel edges are not supported)");
    types_[e] = edge.type;
    ends_[e] = {edge.v0, edge.v1};
    if (edge.type == EdgeType::Ruling) {
      if (edge.curve.points.rows() > 0)
        failTopology(path + ".points: an R edge (ruling) is straight and has no control points");
      if (edge.crease == CreaseKind::Fold || edge.crease == CreaseKind::Geodesic || edge.crease == CreaseKind::Straight)
        failTopology(path + ".crease: \"" + creaseKindName(edge.crease) +
             "\" applies to S edges; an R edge is a straight crease and folds freely");
      continue;
    }
    const spline::BSplineCurve& c = edge.curve;
    if (c.knots.knots().empty()) failTopology(path + ".degree: an S edge needs a spline (degree and knots)");
    if (c.knots.kind() != spline::KnotKind::Clamped)
      failTopology(path + ".knots: an S edge is an open curve between its vertices (clamped knots)");
    if (c.isRational()) failTopology(path + ".weights: S edges of a composite are polynomial (no weights)");
    if (c.points.cols() != 3) failTopology(path + ".points: expected 3 coordinates per control point");
    const int n = static_cast<int>(c.points.rows());
    if (n != c.knots.numControlPoints())
      failTopology(path + ".points: a degree-" + std::to_string(c.degree()) + " edge with these knots has " +
           std::to_string(c.knots.numControlPoints() - 2) + " interior control points, got " +
           std::to_string(std::max(0, n - 2)));
    if (!c.points.allFinite()) failTopology(path + ".points: coordinates must be finite");
    const Eigen::Vector3d first = c.points.row(0).transpose(), last = c.points.row(n - 1).transpose();
    const Eigen::Vector3d p0 = design.vertices.row(edge.v0).transpose();
    const Eigen::Vector3d p1 = design.vertices.row(edge.v1).transpose();
    const double tol = 1e-9 * scale;
    if ((first - p0).norm() > tol)
      failTopology(path + ".points: the first control point " + pointText(first) + " is not vertex " +
           std::to_string(edge.v0) + " " + pointText(p0) + " (vertex–edge consistency)");
    if ((last - p1).norm() > tol)
      failTopology(path + ".points: the last control point " + pointText(last) + " is not vertex " +
           std::to_string(edge.v1) + " " + pointText(p1) + " (vertex–edge consistency)");
    interior_[e] = n - 2;
    edgeKnots_[e] = c.knots;
  }

  // ---- faces ----
  faces_.resize(numFaces);
  // (from, to) → face that traverses it, per edge
  std::vector<std::vector<int>> forwardFaces(numEdges), backwardFaces(numEdges);
  for (int f = 0; f < numFaces; ++f) {
    const std::vector<int>& ids = design.faces[f];
    const std::string path = facePath(f);
    const int N = static_cast<int>(ids.size());
    if (N < 3) failTopology(path + ": a face needs at least 3 edges, got " + std::to_string(N));
    for (int i = 0; i < N; ++i) {
      if (ids[i] < 0 || ids[i] >= numEdges)
        failTopology(path + "[" + std::to_string(i) + "]: edge " + std::to_string(ids[i]) + " does not exist (" +
             std::to_string(numEdges) + " edges)");
      for (int j = 0; j < i; ++j)
        if (ids[j] == ids[i]) failTopology(path + ": uses edge " + std::to_string(ids[i]) + " twice");
    }
    // Orientation of the first edge: its end is the vertex it shares with the second edge.
    std::vector<OrientedEdge> loop(N);
    std::vector<int> corners(N);
    {
      const auto e0 = ends_[ids[0]], e1 = ends_[ids[1]];
      const bool forward = e0[1] == e1[0] || e0[1] == e1[1];
      const bool backward = e0[0] == e1[0] || e0[0] == e1[1];
      if (!forward && !backward)
        failTopology(path + "[1]: edge " + std::to_string(ids[1]) + " shares no vertex with edge " + std::to_string(ids[0]) +
             " before it (list a face's edges in boundary order)");
      loop[0] = {ids[0], !forward};
    }
    int cur = loop[0].reversed ? ends_[ids[0]][0] : ends_[ids[0]][1];
    corners[0] = loop[0].reversed ? ends_[ids[0]][1] : ends_[ids[0]][0];
    for (int i = 1; i < N; ++i) {
      const auto en = ends_[ids[i]];
      corners[i] = cur;
      if (en[0] == cur) {
        loop[i] = {ids[i], false};
        cur = en[1];
      } else if (en[1] == cur) {
        loop[i] = {ids[i], true};
        cur = en[0];
      } else {
        failTopology(path + "[" + std::to_string(i) + "]: edge " + std::to_string(ids[i]) + " (vertices " +
             std::to_string(en[0]) + "–" + std::to_string(en[1]) + ") does not continue the boundary at vertex " +
             std::to_string(cur) + " (list a face's edges in boundary order)");
      }
    }
    if (cur != corners[0])
      failTopology(path + ": the boundary does not close (it ends at vertex " + std::to_string(cur) + " but starts at vertex " +
           std::to_string(corners[0]) + ")");
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < i; ++j)
        if (corners[i] == corners[j]) failTopology(path + ": passes vertex " + std::to_string(corners[i]) + " twice");

    std::vector<EdgeType> labels(N);
    int sCount = 0;
    for (int i = 0; i < N; ++i) {
      labels[i] = types_[loop[i].edge];
      sCount += labels[i] == EdgeType::Spline;
    }
    const std::string kinds = " (face types: S R S R, S R S, S R R, R…R)";
    FaceInfo info;
    if (sCount == 0) {
      info.type = FaceType::Planar;
    } else if (sCount > 2) {
      failTopology(path + ": has " + std::to_string(sCount) + " S edges (" + labelsText(labels) + "); a face has at most 2" + kinds);
    } else if (sCount == 1) {
      if (N != 3)
        failTopology(path + ": labels " + labelsText(labels) + " are not a face type; a face with one S edge is a cone, S R R" +
             kinds);
      info.type = FaceType::Cone;
    } else if (N == 4) {
      info.type = FaceType::Strip;
    } else if (N == 3) {
      info.type = FaceType::DegenerateStrip;
    } else {
      failTopology(path + ": labels " + labelsText(labels) + " are not a face type; two S edges need R edges between them" + kinds);
    }
    if (info.type == FaceType::Strip && (labels[0] == labels[1] || labels[1] == labels[2]))
      failTopology(path + ": labels " + labelsText(labels) + " are not a face type; the S edges of a strip are opposite" + kinds);
    if (info.type != FaceType::Planar) {
      // Rotate so that loop[0] is an S edge followed by an R edge.
      int start = 0;
      while (!(labels[start] == EdgeType::Spline && labels[(start + 1) % N] == EdgeType::Ruling)) ++start;
      std::rotate(loop.begin(), loop.begin() + start, loop.end());
      std::rotate(corners.begin(), corners.begin() + start, corners.end());
      info.a = loop[0];
      info.ruling1 = loop[1].edge;
      if (info.type == FaceType::Strip) {
        info.b = {loop[2].edge, !loop[2].reversed};
        info.ruling0 = loop[3].edge;
      } else if (info.type == FaceType::DegenerateStrip) {
        info.b = {loop[2].edge, !loop[2].reversed};
        info.point0 = corners[0];
      } else {
        info.apex = corners[2];
        info.ruling0 = loop[2].edge;
      }
      info.knots = knots(info.a.edge, info.a.reversed);
      if (info.b.edge >= 0) {
        const spline::BSplineCurve& ca = design.edges[info.a.edge].curve;
        const spline::BSplineCurve& cb = design.edges[info.b.edge].curve;
        const std::string both = "S edges " + std::to_string(info.a.edge) + " and " + std::to_string(info.b.edge);
        if (ca.degree() != cb.degree())
          failTopology(path + ": " + both + " differ in degree (" + std::to_string(ca.degree()) + " and " +
               std::to_string(cb.degree()) + "); a strip's curves share one spline space (edge–face consistency)");
        if (ca.points.rows() != cb.points.rows())
          failTopology(path + ": " + both + " differ in control points (" + std::to_string(ca.points.rows()) + " and " +
               std::to_string(cb.points.rows()) + "); a strip's curves share one spline space (edge–face consistency)");
        if (!topologySameKnots(info.knots, knots(info.b.edge, info.b.reversed)))
          failTopology(path + ": " + both + " differ in knots (compared in the direction of the strip's rulings); a strip's "
               "curves share one spline space (edge–face consistency)");
      }
    }
    info.loop = loop;
    info.corners = corners;
    for (const OrientedEdge& oe : loop) (oe.reversed ? backwardFaces : forwardFaces)[oe.edge].push_back(f);
    faces_[f] = std::move(info);
  }

  // ---- manifold, use ----
  for (int e = 0; e < numEdges; ++e) {
    const std::string path = edgePath(e);
    const std::size_t total = forwardFaces[e].size() + backwardFaces[e].size();
    if (total == 0) failTopology(path + ": belongs to no face");
    if (total > 2) {
      std::string list;
      for (int f : forwardFaces[e]) list += (list.empty() ? "" : ", ") + std::to_string(f);
      for (int f : backwardFaces[e]) list += (list.empty() ? "" : ", ") + std::to_string(f);
      failTopology(path + ": is shared by " + std::to_string(total) + " faces (" + list +
           "); the composite must be a manifold (at most 2 faces per edge)");
    }
    for (const auto* side : {&forwardFaces[e], &backwardFaces[e]})
      if (side->size() == 2) {
        const bool fw = side == &forwardFaces[e];
        failTopology(path + ": faces " + std::to_string((*side)[0]) + " and " + std::to_string((*side)[1]) +
             " both traverse it from vertex " + std::to_string(ends_[e][fw ? 0 : 1]) + " to vertex " +
             std::to_string(ends_[e][fw ? 1 : 0]) +
             "; orient all faces consistently (a shared edge runs in opposite directions)");
      }
    if (!forwardFaces[e].empty()) edges_[e].faces[0] = forwardFaces[e][0];
    if (!backwardFaces[e].empty()) edges_[e].faces[1] = backwardFaces[e][0];
    const CreaseKind ck = design.edges[e].crease;
    if (ck != CreaseKind::None && ck != CreaseKind::Straight && !edges_[e].interior())
      failTopology(path + ".crease: \"" + std::string(creaseKindName(ck)) + "\" needs faces on both sides; edge " +
           std::to_string(e) + " is on the boundary");
  }
  std::vector<bool> used(numVertices_, false);
  for (const auto& en : ends_) used[en[0]] = used[en[1]] = true;
  for (int v = 0; v < numVertices_; ++v)
    if (!used[v]) failTopology("vertices[" + std::to_string(v) + "]: belongs to no edge");

  // ---- the OpenMesh mesh ----
  auto& m = mesh_->mesh;
  m.add_property(mesh_->sceneEdge);
  m.add_property(mesh_->sceneFace);
  std::vector<OpenMesh::VertexHandle> vh(numVertices_);
  for (int v = 0; v < numVertices_; ++v)
    vh[v] = m.add_vertex({design.vertices(v, 0), design.vertices(v, 1), design.vertices(v, 2)});
  silenceOpenMeshErrors();
  for (int f = 0; f < numFaces; ++f) {
    std::vector<OpenMesh::VertexHandle> loop;
    for (int c : faces_[f].corners) loop.push_back(vh[c]);
    const auto fh = m.add_face(loop);
    if (!fh.is_valid())
      failTopology(facePath(f) + ": makes the mesh non-manifold at one of its vertices (the faces around a vertex must "
           "form one fan)");
    m.property(mesh_->sceneFace, fh) = f;
  }
  for (const auto eh : m.edges()) {
    const int a = eh.v0().idx(), b = eh.v1().idx();
    m.property(mesh_->sceneEdge, eh) = byVertices.at({std::min(a, b), std::max(a, b)});
  }
  boundaryVertex_.assign(numVertices_, false);
  for (int v = 0; v < numVertices_; ++v) boundaryVertex_[v] = m.is_boundary(vh[v]);
}

std::vector<PointSlot> CompositeTopology::controlSlots(int e, bool reversed) const {
  if (types_.at(e) != EdgeType::Spline) throw std::logic_error("controlSlots: edge " + std::to_string(e) + " is a ruling");
  const int inner = interior_[e];
  std::vector<PointSlot> slots(static_cast<std::size_t>(inner) + 2);
  slots.front() = {ends_[e][0], -1, 0};
  slots.back() = {ends_[e][1], -1, 0};
  for (int i = 0; i < inner; ++i) slots[static_cast<std::size_t>(i) + 1] = {-1, e, i};
  if (reversed) std::reverse(slots.begin(), slots.end());
  return slots;
}

spline::KnotVector CompositeTopology::knots(int e, bool reversed) const {
  const spline::KnotVector& k = edgeKnots_.at(e);
  if (!reversed) return k;
  return spline::KnotVector::clamped(k.degree(), reversedEdgeKnots(k), k.numControlPoints());
}

bool CompositeTopology::edgeRunsWithU(int f, int e) const {
  const FaceInfo& info = faces_.at(f);
  if (info.a.edge == e) return !info.a.reversed;
  if (info.b.edge == e) return !info.b.reversed;
  throw std::logic_error("edge " + std::to_string(e) + " is not a curve of face " + std::to_string(f));
}

int CompositeTopology::rulingEnd(int f, int e) const {
  const FaceInfo& info = faces_.at(f);
  if (info.type == FaceType::Planar) return -1;
  if (info.ruling0 == e) return 0;
  if (info.ruling1 == e) return 1;
  return -1;
}

int CompositeTopology::meshVertices() const { return static_cast<int>(mesh_->mesh.n_vertices()); }
int CompositeTopology::meshEdges() const { return static_cast<int>(mesh_->mesh.n_edges()); }
int CompositeTopology::meshFaces() const { return static_cast<int>(mesh_->mesh.n_faces()); }

}  // namespace devsurf::models::composite
