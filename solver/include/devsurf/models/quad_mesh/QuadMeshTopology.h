#pragma once

#include <array>
#include <vector>

namespace devsurf::models::quad_mesh {

/// A face of a quad-dominant mesh: four vertex indices counter-clockwise seen from the front, or
/// a triangle with `[3] = -1`.
using Face = std::array<int, 4>;

/// Number of vertices of a face (3 or 4).
inline int faceSize(const Face& f) { return f[3] < 0 ? 3 : 4; }

/// The combinatorics of the quad-dominant meshes M and M′ of Jiang et al. 2020 (004_… §2): one
/// mesh, checked once by OpenMesh (PolyMesh), with the index lists the terms need.
///
/// Conditions (std::invalid_argument naming "faces[f]" otherwise): every face has 3 or 4
/// distinct vertices in [0, vertexCount); faces are consistently oriented and the mesh is a
/// manifold with boundary (OpenMesh accepts every face); every vertex belongs to a face.
class QuadMeshTopology {
 public:
  /// @param[in] vertexCount  V
  /// @param[in] faces        F faces (ccw; triangles with [3] = −1)
  /// @throws std::invalid_argument naming the offending face ("faces[7]: …") or vertex
  QuadMeshTopology(int vertexCount, const std::vector<Face>& faces);

  int vertexCount() const { return vertexCount_; }
  const std::vector<Face>& faces() const { return faces_; }
  /// Every edge once, as (i, j) with i < j.
  const std::vector<std::array<int, 2>>& edges() const { return edges_; }
  /// Whether edges()[e] lies on the boundary (one face).
  const std::vector<char>& edgeOnBoundary() const { return edgeOnBoundary_; }
  /// Whether a vertex lies on the boundary.
  const std::vector<char>& vertexOnBoundary() const { return vertexOnBoundary_; }
  /// Successive vertex triples (i, j, k) on mesh polylines, j the middle one (004_… §2.3.3
  /// E_fair): at every interior vertex of valence 4 its two pairs of opposite edges, at every
  /// boundary vertex of valence 3 its two boundary edges. Each triple once.
  const std::vector<std::array<int, 3>>& polylineTriples() const { return triples_; }
  /// (i, j, k, l) for E_map (004_… §2.3.3): every polyline triple (i, j, k) with every other
  /// edge (j, l) at its middle vertex.
  const std::vector<std::array<int, 4>>& mappingQuadruples() const { return quadruples_; }
  /// Boundary loops as vertex cycles, in the direction that keeps the mesh on the left
  /// (counter-clockwise for a ccw disc); each loop once, starting at its smallest vertex.
  const std::vector<std::vector<int>>& boundaryLoops() const { return boundaryLoops_; }
  /// Faces around every vertex.
  const std::vector<std::vector<int>>& vertexFaces() const { return vertexFaces_; }
  /// Connected components: the component of every vertex, and their number.
  const std::vector<int>& vertexComponent() const { return component_; }
  int componentCount() const { return componentCount_; }

 private:
  int vertexCount_ = 0;
  std::vector<Face> faces_;
  std::vector<std::array<int, 2>> edges_;
  std::vector<char> edgeOnBoundary_;
  std::vector<char> vertexOnBoundary_;
  std::vector<std::array<int, 3>> triples_;
  std::vector<std::array<int, 4>> quadruples_;
  std::vector<std::vector<int>> boundaryLoops_;
  std::vector<std::vector<int>> vertexFaces_;
  std::vector<int> component_;
  int componentCount_ = 0;
};

}  // namespace devsurf::models::quad_mesh
