#include "devsurf/io/QuadMesh.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <cstdlib>
#include <fstream>
#include <atomic>
#include <sstream>
#include <string>
#include <thread>
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

/// A k×k grid of quads, its vertices lifted by `lift` (so two grids differ in every number).
QuadMesh liftedGrid(int k, double lift) {
  QuadMesh m;
  m.vertices.resize((k + 1) * (k + 1), 3);
  for (int i = 0; i <= k; ++i)
    for (int j = 0; j <= k; ++j) m.vertices.row(i * (k + 1) + j) << i, j, lift * (i + 0.5 * j);
  m.quads.resize(k * k, 4);
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      const int v = i * (k + 1) + j;
      m.quads.row(i * k + j) << v, v + k + 1, v + k + 2, v + 1;
    }
  return m;
}

/// OpenMesh reads and writes through one reader and one writer object per format for the whole
/// process, which keep the file being read in members (the PLY reader: its elements, counts and
/// options). The daemon reads uploaded shapes and writes exports on several route workers at once:
/// every file must read back as it does alone. Without io::openMeshIoMutex this test ended in a
/// segmentation fault.
TEST(QuadMesh, FilesReadAndWrittenOnTwoThreadsAtOnceAreTheFilesOfOneAtATime) {
  for (const std::string format : {"ply", "off", "obj"}) {
    const QuadMesh small = liftedGrid(20, 0.25), large = liftedGrid(50, -0.5);
    const std::string smallPath = quadMeshTempPath("small." + format), largePath = quadMeshTempPath("large." + format);
    writeMesh(small, smallPath);
    writeMesh(large, largePath);
    std::atomic<int> wrong{0};
    auto readAndWrite = [&wrong, &format](const std::string& path, const QuadMesh& expected) {
      const std::string text = meshString(expected, format);
      for (int round = 0; round < 60; ++round) {
        try {
          const QuadMesh back = readQuadMesh(path);
          if (back.quads != expected.quads || back.vertices.rows() != expected.vertices.rows() ||
              (back.vertices - expected.vertices).cwiseAbs().maxCoeff() > 1e-12)
            ++wrong;
          if (meshString(expected, format) != text) ++wrong;
        } catch (const std::exception&) {
          ++wrong;
        }
      }
    };
    std::thread other([&readAndWrite, &largePath, &large]() { readAndWrite(largePath, large); });
    readAndWrite(smallPath, small);
    other.join();
    EXPECT_EQ(wrong.load(), 0) << format << ": of 120 reads and 120 writes made two at a time";
    std::remove(smallPath.c_str());
    std::remove(largePath.c_str());
  }
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
