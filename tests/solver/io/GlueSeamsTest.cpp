#include "devsurf/io/GlueSeams.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "devsurf/io/CuttingPatternSvg.h"
#include "devsurf/io/PolygonMesh.h"
#include "devsurf/io/QuadMeshFold.h"

namespace devsurf::io {
namespace {

/// A 3 × 1 strip of quads whose left side (0, 4) is glued to its right side (3, 7): a cylinder.
/// (Two quads would not do: gluing is known at vertices, and (0, 1), (1, 2) would have glued end
/// points too.)
///   4--5--6--7
///   |  |  |  |
///   0--1--2--3
const std::vector<PolygonFace> kStrip = {{0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}};
const std::vector<std::array<int, 2>> kStripGlue = {{0, 3}, {4, 7}};

TEST(GlueSeams, TheTwoEndsOfAStripGluedIntoACylinderAreOneSeamWithOneEdgeOnEachSide) {
  const GlueSeams s = findGlueSeams(8, kStrip, kStripGlue);
  ASSERT_EQ(s.edges.size(), 10u);
  EXPECT_EQ(s.seamCount, 1);
  int glued = 0, cut = 0, interior = 0;
  for (std::size_t e = 0; e < s.edges.size(); ++e) {
    const PolygonEdge& edge = s.edges[e];
    if (edge.faceCount == 2) {
      ++interior;
      EXPECT_EQ(edge.gluedTo, -1);
    } else if (edge.gluedTo >= 0) {
      ++glued;
      EXPECT_EQ(s.edges[static_cast<std::size_t>(edge.gluedTo)].gluedTo, static_cast<int>(e));
      EXPECT_EQ(edge.seam, 0);
    } else {
      ++cut;
      EXPECT_EQ(edge.seam, -1);
    }
  }
  EXPECT_EQ(interior, 2);
  EXPECT_EQ(glued, 2);
  EXPECT_EQ(cut, 6);
  // Face 0 meets (4, 0) as its fourth edge (edge 3), face 2 meets (3, 7) as edge 8: sides 0, 1.
  EXPECT_EQ(s.edges[3].v0, 4);
  EXPECT_EQ(s.edges[3].v1, 0);
  EXPECT_EQ(s.edges[3].side, 0);
  EXPECT_EQ(s.edges[3].gluedTo, 8);
  EXPECT_EQ(s.edges[8].v0, 3);
  EXPECT_EQ(s.edges[8].v1, 7);
  EXPECT_EQ(s.edges[8].side, 1);
}

TEST(GlueSeams, BoundaryEdgesWithoutGlueAreAllCut) {
  const GlueSeams s = findGlueSeams(8, kStrip, {});
  EXPECT_EQ(s.seamCount, 0);
  for (const PolygonEdge& e : s.edges) EXPECT_EQ(e.gluedTo, -1);
}

TEST(GlueSeams, BadInputIsRefusedNamingTheFaceOrPair) {
  auto message = [](auto&& call) {
    try {
      call();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  EXPECT_EQ(message([] { findGlueSeams(7, kStrip, {}); }), "face 2 has vertex index 7 outside [0, 7)");
  EXPECT_EQ(message([] { findGlueSeams(6, {{0, 1, 1, 3}}, {}); }), "face 0 repeats vertex 1");
  EXPECT_EQ(message([] { findGlueSeams(8, kStrip, {{0, 3}, {3, 3}}); }),
            "glue pair 1 glues vertex 3 to itself");
  EXPECT_EQ(message([] { findGlueSeams(8, kStrip, {{0, 8}}); }),
            "glue pair 0 has a vertex index outside [0, 8)");
  EXPECT_EQ(message([] { findGlueSeams(5, {{0, 1, 2, -1}, {1, 0, 3, -1}, {0, 1, 4, -1}}, {}); }),
            "face 2: edge (0, 1) has more than two faces");
}

TEST(PolygonMeshObj, WritesMixedFacesWithOneBasedIndicesAndExactCoordinates) {
  Eigen::MatrixXd v(4, 2);
  v << 0, 0, 1, 0, 1, 0.1, 0, 1;
  EXPECT_EQ(objString(v, {{0, 1, 2, -1}, {0, 2, 3, -1}}, "unfolding"),
            "# unfolding\nv 0 0 0\nv 1 0 0\nv 1 0.1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
  EXPECT_THROW(objString(Eigen::MatrixXd(4, 1), {}), std::invalid_argument);
}

TEST(CuttingPatternSvg, RefusesANonPositiveScale) {
  Eigen::MatrixXd v(8, 2);
  v << 0, 0, 1, 0, 2, 0, 3, 0, 0, 1, 1, 1, 2, 1, 3, 1;
  EXPECT_THROW(cuttingPatternSvg(v, kStrip, {}, 0.0), std::invalid_argument);
  EXPECT_NO_THROW(cuttingPatternSvg(v, kStrip, {}, 1.0));
}

TEST(QuadMeshFold, RefusesAMeshWithAnotherVertexCount) {
  Eigen::MatrixXd v(8, 2);
  v << 0, 0, 1, 0, 2, 0, 3, 0, 0, 1, 1, 1, 2, 1, 3, 1;
  EXPECT_THROW(quadMeshFoldDocument(v, Eigen::MatrixXd::Zero(7, 3), kStrip, {}), std::invalid_argument);
  const auto doc = quadMeshFoldDocument(v, Eigen::MatrixXd(0, 3), kStrip, kStripGlue);
  EXPECT_FALSE(doc.contains("file_frames"));
  EXPECT_EQ(doc["edges_assignment"], nlohmann::json({"B", "F", "B", "J", "B", "F", "B", "B", "J", "B"}));
  EXPECT_EQ(doc["frame_unit"], "mm");
}

}  // namespace
}  // namespace devsurf::io
