#include "devsurf/models/quad_mesh/QuadMeshTopology.h"

#include <algorithm>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>

#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

namespace devsurf::models::quad_mesh {

namespace {

[[noreturn]] void failQuadTopology(const std::string& message) { throw std::invalid_argument(message); }

std::string quadFacePath(std::size_t f) { return "faces[" + std::to_string(f) + "]"; }

/// OpenMesh reports a face it cannot add on its global error stream; we report the face by path.
/// Switched off once per process (see CompositeTopology: toggling it raced between threads).
void silenceQuadMeshOpenMeshErrors() {
  static const bool silenced = [] {
    omerr().disable();
    return true;
  }();
  (void)silenced;
}

std::array<int, 2> edgeKey(int a, int b) { return a < b ? std::array<int, 2>{a, b} : std::array<int, 2>{b, a}; }

int findRoot(std::vector<int>& parent, int i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

}  // namespace

QuadMeshTopology::QuadMeshTopology(int vertexCount, const std::vector<Face>& faces)
    : vertexCount_(vertexCount), faces_(faces) {
  if (vertexCount < 3) failQuadTopology("mesh: at least 3 vertices are needed, got " + std::to_string(vertexCount));
  if (faces.empty()) failQuadTopology("faces: at least one face is needed");
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const Face& face = faces[f];
    const int n = faceSize(face);
    for (int k = 0; k < n; ++k) {
      if (face[k] < 0 || face[k] >= vertexCount)
        failQuadTopology(quadFacePath(f) + ": vertex " + std::to_string(face[k]) + " is not in [0, " + std::to_string(vertexCount) +
             ")");
      for (int l = 0; l < k; ++l)
        if (face[l] == face[k]) failQuadTopology(quadFacePath(f) + ": vertex " + std::to_string(face[k]) + " appears twice");
    }
  }

  // OpenMesh decides manifoldness and consistent orientation.
  silenceQuadMeshOpenMeshErrors();
  OpenMesh::PolyMesh_ArrayKernelT<> mesh;
  std::vector<OpenMesh::VertexHandle> vh(vertexCount);
  for (int i = 0; i < vertexCount; ++i) vh[i] = mesh.add_vertex(OpenMesh::Vec3f(0, 0, 0));
  for (std::size_t f = 0; f < faces.size(); ++f) {
    std::vector<OpenMesh::VertexHandle> loop;
    for (int k = 0; k < faceSize(faces[f]); ++k) loop.push_back(vh[faces[f][k]]);
    if (!mesh.add_face(loop).is_valid())
      failQuadTopology(quadFacePath(f) + ": the face makes the mesh non-manifold or is oriented against its neighbours "
           "(faces must be counter-clockwise seen from the front and meet edge to edge)");
  }

  // Edges with the faces on each side.
  std::map<std::array<int, 2>, int> edgeIndex;
  std::vector<int> edgeFaceCount;
  std::map<std::array<int, 2>, int> directed;  // directed edge a→b of a face ↦ face
  vertexFaces_.assign(vertexCount, {});
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const Face& face = faces[f];
    const int n = faceSize(face);
    for (int k = 0; k < n; ++k) {
      const int a = face[k], b = face[(k + 1) % n];
      vertexFaces_[a].push_back(static_cast<int>(f));
      directed[{a, b}] = static_cast<int>(f);
      auto [it, inserted] = edgeIndex.emplace(edgeKey(a, b), static_cast<int>(edges_.size()));
      if (inserted) {
        edges_.push_back(edgeKey(a, b));
        edgeFaceCount.push_back(0);
      }
      ++edgeFaceCount[it->second];
    }
  }
  for (int v = 0; v < vertexCount; ++v)
    if (vertexFaces_[v].empty()) failQuadTopology("mesh[" + std::to_string(v) + "]: the vertex belongs to no face");

  edgeOnBoundary_.assign(edges_.size(), 0);
  vertexOnBoundary_.assign(vertexCount, 0);
  std::vector<std::vector<int>> vertexEdges(vertexCount);
  for (std::size_t e = 0; e < edges_.size(); ++e) {
    vertexEdges[edges_[e][0]].push_back(static_cast<int>(e));
    vertexEdges[edges_[e][1]].push_back(static_cast<int>(e));
    if (edgeFaceCount[e] == 1) {
      edgeOnBoundary_[e] = 1;
      vertexOnBoundary_[edges_[e][0]] = vertexOnBoundary_[edges_[e][1]] = 1;
    }
  }
  auto other = [this](int e, int v) { return edges_[e][0] == v ? edges_[e][1] : edges_[e][0]; };

  // Polyline triples.
  for (int v = 0; v < vertexCount; ++v) {
    const std::vector<int>& incident = vertexEdges[v];
    if (!vertexOnBoundary_[v] && incident.size() == 4) {
      // Rotation around v: in a ccw face (… p, v, n …) the neighbours n and p are consecutive.
      std::map<int, int> rotation;  // n ↦ p
      for (int f : vertexFaces_[v]) {
        const Face& face = faces_[f];
        const int n = faceSize(face);
        for (int k = 0; k < n; ++k)
          if (face[k] == v) rotation[face[(k + 1) % n]] = face[(k + n - 1) % n];
      }
      if (rotation.size() != 4) continue;
      std::array<int, 4> ring{};
      ring[0] = rotation.begin()->first;
      bool closed = true;
      for (int k = 1; k < 4; ++k) {
        auto it = rotation.find(ring[k - 1]);
        if (it == rotation.end()) {
          closed = false;
          break;
        }
        ring[k] = it->second;
      }
      if (!closed) continue;
      triples_.push_back({ring[0], v, ring[2]});
      triples_.push_back({ring[1], v, ring[3]});
    } else if (vertexOnBoundary_[v] && incident.size() == 3) {
      std::vector<int> ends;
      for (int e : incident)
        if (edgeOnBoundary_[e]) ends.push_back(other(e, v));
      if (ends.size() == 2) triples_.push_back({ends[0], v, ends[1]});
    }
  }
  for (const auto& t : triples_)
    for (int e : vertexEdges[t[1]]) {
      const int l = other(e, t[1]);
      if (l != t[0] && l != t[2]) quadruples_.push_back({t[0], t[1], t[2], l});
    }

  // Boundary loops: directed boundary edges a→b of faces (the mesh on their left).
  std::map<int, std::vector<int>> next;
  for (const auto& [ab, f] : directed)
    if (!directed.count({ab[1], ab[0]})) next[ab[0]].push_back(ab[1]);
  std::map<std::array<int, 2>, bool> used;
  for (auto& [start, targets] : next) {
    std::sort(targets.begin(), targets.end());
    for (int firstTarget : targets) {
      if (used[{start, firstTarget}]) continue;
      std::vector<int> loop{start};
      int a = start, b = firstTarget;
      while (!used[{a, b}]) {
        used[{a, b}] = true;
        if (b == start) break;
        loop.push_back(b);
        const std::vector<int>& candidates = next[b];
        int c = -1;
        for (int t : candidates)
          if (!used[{b, t}]) {
            c = t;
            break;
          }
        if (c < 0) break;
        a = b;
        b = c;
      }
      auto smallest = std::min_element(loop.begin(), loop.end());
      std::rotate(loop.begin(), smallest, loop.end());
      boundaryLoops_.push_back(std::move(loop));
    }
  }

  // Components over faces.
  std::vector<int> parent(vertexCount);
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& e : edges_) parent[findRoot(parent, e[0])] = findRoot(parent, e[1]);
  component_.assign(vertexCount, -1);
  std::map<int, int> componentOfRoot;
  for (int v = 0; v < vertexCount; ++v) {
    auto [it, inserted] = componentOfRoot.emplace(findRoot(parent, v), componentCount_);
    if (inserted) ++componentCount_;
    component_[v] = it->second;
  }
}

}  // namespace devsurf::models::quad_mesh
