#include "devsurf/io/QuadMesh.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace devsurf::io {
namespace {

std::string quadMeshTempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("devsurf_io_" + std::to_string(::getpid()) + "_" + name)).string();
}

QuadMesh grid() {
  QuadMesh m;
  m.vertices.resize(6, 3);
  m.vertices << 0, 0, 0, 0, 1, 0, 1, 0, 0.5, 1, 1, 0.5, 2, 0, 0, 2, 1, 0;
  m.quads.resize(2, 4);
  m.quads << 0, 2, 3, 1, 2, 4, 5, 3;
  return m;
}

TEST(QuadMesh, ObjRoundTripKeepsQuadsAndCoordinates) {
  const std::string path = quadMeshTempPath("grid.obj");
  writeMesh(grid(), path);
  std::ifstream file(path);
  std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("f 1 3 4 2"), std::string::npos) << text;  // OBJ is 1-based
  const QuadMesh back = readQuadMesh(path);
  EXPECT_EQ(back.quads, grid().quads);
  EXPECT_LT((back.vertices - grid().vertices).cwiseAbs().maxCoeff(), 1e-12);
  std::remove(path.c_str());
}

TEST(QuadMesh, QuadsSplitIntoTwoTrianglesAndZeroAreaOnesAreLeftOut) {
  QuadMesh m = grid();
  m.vertices.row(5) = m.vertices.row(4);  // the second quad's edge 4–5 has zero length
  const Eigen::MatrixX3i t = triangulateQuads(m);
  ASSERT_EQ(t.rows(), 3);
  EXPECT_EQ(t.row(0), Eigen::RowVector3i(0, 2, 3));
  EXPECT_EQ(t.row(1), Eigen::RowVector3i(0, 3, 1));
  EXPECT_EQ(t.row(2), Eigen::RowVector3i(2, 5, 3));  // (2, 4, 5) has zero area
  m.quads(0, 1) = -1;
  EXPECT_THROW(triangulateQuads(m), std::runtime_error);
}

TEST(QuadMesh, StlFilesHoldTheTrianglesWithTheirVertices) {
  const std::string path = quadMeshTempPath("grid.stl");
  writeMesh(grid(), path);
  std::ifstream file(path);
  std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  std::size_t facets = 0, vertices = 0;
  for (std::size_t at = text.find("endfacet"); at != std::string::npos; at = text.find("endfacet", at + 1)) ++facets;
  for (std::size_t at = text.find("vertex"); at != std::string::npos; at = text.find("vertex", at + 1)) ++vertices;
  EXPECT_EQ(facets, 4u);
  EXPECT_EQ(vertices, 12u);
  std::remove(path.c_str());
}

/// The whitespace-separated words of a text, numbers read as numbers (OpenMesh writes files it
/// opens in fixed notation for some formats, streams in the shortest exact one).
std::vector<std::string> words(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> out;
  for (std::string w; in >> w;) {
    char* end = nullptr;
    const double x = std::strtod(w.c_str(), &end);
    out.push_back(end && *end == '\0' && !w.empty() ? std::to_string(x) : w);
  }
  return out;
}

TEST(QuadMesh, MeshStringsHoldWhatWriteMeshWritesToAFile) {
  for (const std::string format : {"obj", "off", "ply", "stl"}) {
    const std::string path = quadMeshTempPath("same." + format);
    writeMesh(grid(), path);
    std::ifstream file(path, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    EXPECT_EQ(words(meshString(grid(), format)), words(text)) << format;
    std::remove(path.c_str());
  }
  EXPECT_THROW(meshString(grid(), "dxf"), std::invalid_argument);
  QuadMesh bad = grid();
  bad.quads(1, 2) = 17;
  EXPECT_THROW(meshString(bad, "stl"), std::runtime_error);
}

TEST(QuadMesh, BadIndicesAndUnwritablePathsThrow) {
  QuadMesh m = grid();
  m.quads(1, 2) = 17;
  EXPECT_THROW(writeMesh(m, quadMeshTempPath("bad.obj")), std::runtime_error);
  EXPECT_THROW(writeMesh(grid(), "/nonexistent-dir/x.obj"), std::runtime_error);
  EXPECT_THROW(readQuadMesh("/nonexistent-dir/x.obj"), std::runtime_error);
}

}  // namespace
}  // namespace devsurf::io
