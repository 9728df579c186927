#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "devsurf/models/composite/CompositeDesign.h"
#include "devsurf/spline/KnotVector.h"

namespace devsurf::models::composite {

/// The four face types of 000_… §3.1, classified by the labels of the boundary.
enum class FaceType {
  Strip,            ///< S R S R: ruled spline developable between curves a and b
  DegenerateStrip,  ///< S R S: the same with the ruling at u = begin degenerated to a vertex
  Cone,             ///< S R R: base curve a and an apex vertex
  Planar,           ///< R … R: planar polygon
};
const char* faceTypeName(FaceType t);

/// An edge as a face traverses it: `reversed` means from v1 to v0.
struct OrientedEdge {
  int edge = -1;
  bool reversed = false;
};

/// Where a control point of a curve lives among the variables: a vertex, or interior control
/// point `index` (0-based, i.e. curve control point index+1) of an S edge.
struct PointSlot {
  int vertex = -1;  ///< ≥ 0: the vertex's block
  int edge = -1;    ///< ≥ 0: the edge's interior block
  int index = 0;
  bool operator==(const PointSlot& o) const {
    return vertex == o.vertex && edge == o.edge && (vertex >= 0 || index == o.index);
  }
};

/// Per face: its type and, for strip-like faces, which curves and rulings form it.
///
/// Strip-like faces are parametrized s(u, v) = (1−v) a(u) + v b(u) with u in the face's knot
/// domain. The boundary loop is rotated so that loop[0] is an S edge followed by an R edge; a is
/// loop[0] as traversed, b is the other S edge traversed against the loop (so a and b both run
/// with u), a cone has b ≡ apex. With the face counterclockwise seen from its normal, the normal
/// is a′ × (b − a) (000_… §3.1; this orientation makes eq. (7) the curved fold condition).
struct FaceInfo {
  FaceType type = FaceType::Planar;
  std::vector<OrientedEdge> loop;  ///< boundary as given (Planar) or rotated (strip-like)
  std::vector<int> corners;        ///< vertex at the start of each loop edge
  OrientedEdge a, b;               ///< curves a, b in the direction of u (b.edge = −1 for cones)
  int apex = -1;                   ///< cone apex vertex
  int ruling0 = -1;                ///< R edge at u = begin (−1: degenerated to vertex point0)
  int ruling1 = -1;                ///< R edge at u = end
  int point0 = -1;                 ///< S R S: the vertex where the ruling at u = begin degenerates
  spline::KnotVector knots;        ///< a's knots in the direction of u (strip-like faces)
};

/// Per edge: the faces on either side. faces[0] traverses the edge from v0 to v1 (the face to
/// its left, seen from the normals' side), faces[1] from v1 to v0; −1 where there is none.
struct EdgeInfo {
  std::array<int, 2> faces{{-1, -1}};
  bool interior() const { return faces[0] >= 0 && faces[1] >= 0; }
};

/// Combinatorics of a composite developable (000_… §3.1, 003_… §5.3): the labelled polygon mesh
/// (kept as an OpenMesh PolyMesh) and the identification of variables it implies.
///
/// Consistency checks (each error names the offending face/edge/vertex with the scene's path,
/// e.g. "faces[2]: …", "edges[5].points: …"):
/// - edge: valid distinct vertex indices; an R edge has no spline; an S edge has a clamped
///   polynomial spline whose first/last control points are its vertices (vertex–edge
///   consistency); no two edges join the same pair of vertices.
/// - face: at least 3 edges, consecutive edges share a vertex and close the loop, no vertex twice;
///   labels are S R S R, S R S, S R R or R…R (at most 2 S edges, S edges never adjacent except in
///   S R S).
/// - edge–face / face–face: both S edges of a strip have the same degree, control-point count and
///   knots (in the direction of u); shared S edges make neighbouring faces consistent.
/// - manifold: an edge lies in at most 2 faces and is traversed once in each direction (faces
///   consistently oriented); every edge and vertex belongs to a face; OpenMesh accepts the faces.
class CompositeTopology {
 public:
  /// @throws std::invalid_argument naming the path of the first problem ("faces[1]: …")
  explicit CompositeTopology(const CompositeDesign& design);
  ~CompositeTopology();
  CompositeTopology(CompositeTopology&&) noexcept;
  CompositeTopology& operator=(CompositeTopology&&) noexcept;

  int numVertices() const { return numVertices_; }
  int numEdges() const { return static_cast<int>(edges_.size()); }
  int numFaces() const { return static_cast<int>(faces_.size()); }
  const FaceInfo& face(int f) const { return faces_.at(f); }
  const EdgeInfo& edge(int e) const { return edges_.at(e); }
  EdgeType edgeType(int e) const { return types_.at(e); }
  /// Interior control points of an S edge (0 for R edges and degree-1 S edges with 2 points).
  int interiorPoints(int e) const { return interior_.at(e); }
  std::array<int, 2> edgeVertices(int e) const { return ends_.at(e); }

  /// The control points of S edge e as slots, from v0 to v1 (or from v1 to v0 when reversed):
  /// the reversed curve is a view (an index map), never a copy.
  std::vector<PointSlot> controlSlots(int e, bool reversed = false) const;
  /// Knot vector of S edge e in the given direction (reversal t ↦ t_begin + t_end − t).
  spline::KnotVector knots(int e, bool reversed = false) const;

  /// Whether the face's u runs along the edge's v0→v1 direction (strip-like faces, S edges a/b).
  /// @throws std::logic_error if e is not a or b of f
  bool edgeRunsWithU(int f, int e) const;
  /// Which end of a strip-like face an R edge is (0: u = begin, 1: u = end), −1 if not a ruling
  /// of f.
  int rulingEnd(int f, int e) const;

  /// Vertex count, edges and faces of the underlying OpenMesh mesh (for checks and tests).
  int meshVertices() const;
  int meshEdges() const;
  int meshFaces() const;
  /// Boundary vertices of the mesh (true per vertex).
  const std::vector<bool>& boundaryVertex() const { return boundaryVertex_; }

 private:
  struct Mesh;
  std::unique_ptr<Mesh> mesh_;
  int numVertices_ = 0;
  std::vector<EdgeType> types_;
  std::vector<std::array<int, 2>> ends_;
  std::vector<int> interior_;
  std::vector<spline::KnotVector> edgeKnots_;
  std::vector<EdgeInfo> edges_;
  std::vector<FaceInfo> faces_;
  std::vector<bool> boundaryVertex_;
};

}  // namespace devsurf::models::composite
