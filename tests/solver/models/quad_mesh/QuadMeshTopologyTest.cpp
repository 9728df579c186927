#include <algorithm>

#include <gtest/gtest.h>

#include "devsurf/models/quad_mesh/QuadMeshTopology.h"

namespace devsurf::models::quad_mesh {
namespace {

/// nu × nv quads, vertex (i, j) ↦ j·(nu+1) + i, ccw.
std::vector<Face> grid(int nu, int nv) {
  std::vector<Face> faces;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int a = j * (nu + 1) + i;
      faces.push_back({a, a + 1, a + nu + 2, a + nu + 1});
    }
  return faces;
}

TEST(QuadMeshTopologyTest, AGridHasItsEdgesBoundaryAndPolylines) {
  const QuadMeshTopology t(4 * 3, grid(3, 2));
  EXPECT_EQ(t.edges().size(), 3u * 3 + 4u * 2);
  EXPECT_EQ(std::count(t.edgeOnBoundary().begin(), t.edgeOnBoundary().end(), 1), 10);
  // Interior vertices (1,1), (2,1): two triples each; boundary vertices of valence 3: six; corners: none.
  EXPECT_EQ(t.polylineTriples().size(), 2u * 2 + 6u);
  for (const auto& tr : t.polylineTriples()) {
    // successive vertices on a grid line: the middle one is the mean index of its neighbours
    EXPECT_EQ(tr[0] + tr[2], 2 * tr[1]) << tr[0] << " " << tr[1] << " " << tr[2];
  }
  ASSERT_EQ(t.boundaryLoops().size(), 1u);
  const std::vector<int> expected = {0, 1, 2, 3, 7, 11, 10, 9, 8, 4};
  EXPECT_EQ(t.boundaryLoops()[0], expected);
  EXPECT_EQ(t.componentCount(), 1);
  // E_map: every triple with every other edge at its middle vertex.
  EXPECT_EQ(t.mappingQuadruples().size(), 2u * 2 * 2 + 6u * 1);
}

TEST(QuadMeshTopologyTest, TrianglesAndSeparatePiecesAreAccepted) {
  std::vector<Face> faces = grid(2, 1);
  faces.push_back({6, 7, 8, -1});
  const QuadMeshTopology t(9, faces);
  EXPECT_EQ(t.componentCount(), 2);
  EXPECT_EQ(t.boundaryLoops().size(), 2u);
  EXPECT_EQ(t.vertexComponent()[8], t.vertexComponent()[6]);
  EXPECT_NE(t.vertexComponent()[0], t.vertexComponent()[6]);
}

TEST(QuadMeshTopologyTest, BadFacesAreNamed) {
  auto message = [](int V, const std::vector<Face>& faces) {
    try {
      QuadMeshTopology t(V, faces);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  std::vector<Face> faces = grid(2, 2);
  faces[2] = {0, 1, 1, 3};
  EXPECT_EQ(message(9, faces).rfind("faces[2]: vertex 1 appears twice", 0), 0u) << message(9, faces);
  faces = grid(2, 2);
  faces[3] = {faces[3][3], faces[3][2], faces[3][1], faces[3][0]};
  EXPECT_EQ(message(9, faces).rfind("faces[3]:", 0), 0u) << message(9, faces);
  faces = grid(2, 2);
  faces.push_back({0, 1, 4, -1});  // a third face on edge (0, 1)
  EXPECT_EQ(message(9, faces).rfind("faces[4]:", 0), 0u) << message(9, faces);
  EXPECT_EQ(message(10, grid(2, 2)).rfind("mesh[9]:", 0), 0u) << message(10, grid(2, 2));
  faces = grid(2, 2);
  faces[0][1] = 2147483;
  EXPECT_EQ(message(9, faces).rfind("faces[0]: vertex 2147483 is not in [0, 9)", 0), 0u);
}

}  // namespace
}  // namespace devsurf::models::quad_mesh
