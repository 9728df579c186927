// Reading a user's shape (issue 15): text clouds, meshes through OpenMesh, limits, errors by line;
// counts checked against the files' own headers and lines (CGAL's demo data, libcgal-demo).
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <tuple>

#include <Eigen/Geometry>

#include "devsurf/reference/ReferenceShape.h"
#include "support/TempDir.h"

namespace devsurf::reference {
namespace {

std::string write(const testing::TempDir& dir, const std::string& name, const std::string& text) {
  const std::string path = (dir.path() / name).string();
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::string refusal(const std::string& path, const ReferenceLimits& limits = {}) {
  try {
    readReferenceShape(path, limits);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "accepted";
}

/// Files of CGAL's demo data (Debian's libcgal-demo), unpacked into `dir`.
std::string cgalData(const testing::TempDir& dir, const std::string& member) {
  const std::string archive = "/usr/share/doc/libcgal-dev/data.tar.gz";
  const std::string command = "tar -xzf '" + archive + "' -C '" + dir.str() + "' '" + member + "' 2>/dev/null";
  EXPECT_EQ(std::system(command.c_str()), 0) << "libcgal-demo's data (scripts/setup.sh installs it): " << member;
  return (dir.path() / member).string();
}

TEST(ReferenceShape, AnXyzCloudIsReadWithOrWithoutNormals) {
  testing::TempDir dir;
  const ReferenceShape plain = readReferenceShape(write(dir, "a.xyz", "# scan\n0 0 0\n1 0 0\n\n0 2 0.5  # last\n"));
  ASSERT_EQ(plain.points.rows(), 3);
  EXPECT_EQ(plain.normals.rows(), 0);
  EXPECT_FALSE(plain.isMesh());
  EXPECT_DOUBLE_EQ(plain.points(2, 1), 2.0);
  EXPECT_DOUBLE_EQ(plain.diagonal(), std::sqrt(1.0 + 4.0 + 0.25));
  const ReferenceShape withNormals = readReferenceShape(write(dir, "b.pwn", "0 0 0 0 0 2\n1 0 0 0 3 4\n"));
  ASSERT_EQ(withNormals.normals.rows(), 2);
  EXPECT_NEAR(withNormals.normals(0, 2), 1.0, 1e-15) << "normals are made unit";
  EXPECT_NEAR(withNormals.normals(1, 1), 0.6, 1e-15);
}

TEST(ReferenceShape, MalformedCloudsAreRefusedNamingTheLine) {
  testing::TempDir dir;
  EXPECT_NE(refusal(write(dir, "a.xyz", "0 0 0\n1 0 zero\n")).find("a.xyz: line 2: \"zero\" is not a number"),
            std::string::npos);
  EXPECT_NE(refusal(write(dir, "b.xyz", "0 0 0\n1 0\n")).find("line 2: 2 numbers"), std::string::npos);
  EXPECT_NE(refusal(write(dir, "c.xyz", "0 0 0 0 0 1\n1 0 0\n")).find("line 2: 3 numbers after lines of 6"),
            std::string::npos);
  EXPECT_NE(refusal(write(dir, "d.xyz", "0 0 0\nnan 0 0\n")).find("line 2: a coordinate is not finite"),
            std::string::npos);
  EXPECT_NE(refusal(write(dir, "e.xyz", "0 0 0\n1e999 0 0\n")).find("line 2"), std::string::npos);
  EXPECT_NE(refusal(write(dir, "f.xyz", "# nothing\n")).find("no points"), std::string::npos);
  EXPECT_NE(refusal(write(dir, "g.dwg", "0 0 0\n")).find("unknown extension \".dwg\""), std::string::npos);
  EXPECT_NE(refusal((dir.path() / "missing.xyz").string()).find("cannot open"), std::string::npos);
  EXPECT_NE(refusal(write(dir, "h.obj", "this is not a mesh\n")).find("h.obj: no points"), std::string::npos)
      << refusal(write(dir, "h.obj", "this is not a mesh\n"));
}

TEST(ReferenceShape, CoordinatesPastTheScenesBoundAreRefusedNamingTheLineOrTheVertex) {
  // A tryout's cloud at 1e200 reported null distances; a mesh at 1e10 made a fit whose scene
  // every job then refused. The surfaces fitted to a shape are scenes in its units (±1e9).
  testing::TempDir dir;
  const std::string cloud = refusal(write(dir, "far.xyz", "0 0 0\n1 0 0\n0 1e200 0\n"));
  EXPECT_NE(cloud.find("far.xyz: line 3: coordinate 1e200 is outside ±1e9"), std::string::npos) << cloud;
  EXPECT_NE(cloud.find("shift or scale"), std::string::npos) << cloud;
  // Normals are directions: any finite size.
  EXPECT_EQ(refusal(write(dir, "n.xyz", "0 0 0 0 0 1e12\n1 0 0 0 0 1\n0 1 0 0 0 1\n")), "accepted");
  const std::string mesh = refusal(write(dir, "far.obj", "v 0 0 0\nv 1e10 0 0\nv 0 1 0\nf 1 2 3\n"));
  EXPECT_NE(mesh.find("far.obj: vertex 2: coordinate 1e+10 is outside ±1e9"), std::string::npos) << mesh;
  // At the bound, still read: a scan in large but plausible units.
  EXPECT_EQ(refusal(write(dir, "near.xyz", "0 0 0\n1e9 0 0\n0 -1e9 0\n")), "accepted");
}

TEST(ReferenceShape, FilesOverALimitAreRefusedNamingIt) {
  testing::TempDir dir;
  std::string text;
  for (int i = 0; i < 11; ++i) text += std::to_string(i) + " 0 0\n";
  ReferenceLimits limits;
  limits.maxPoints = 10;
  EXPECT_NE(refusal(write(dir, "a.xyz", text), limits).find("more than 10 points"), std::string::npos);
  limits = {};
  limits.maxFileBytes = 16;
  EXPECT_NE(refusal(write(dir, "b.xyz", text), limits).find("over the limit of 16"), std::string::npos);
  limits = {};
  limits.maxTriangles = 1;
  const std::string quad = "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
  EXPECT_NE(refusal(write(dir, "q.off", quad), limits).find("more than 1 triangles"), std::string::npos);
}

TEST(ReferenceShape, AHeaderDeclaringMoreThanALimitIsRefusedBeforeOpenMeshReservesForIt) {
  testing::TempDir dir;
  // 30 bytes that would have OpenMesh reserve room for four billion vertices.
  EXPECT_NE(refusal(write(dir, "forged.off", "OFF\n4000000000 1 0\n")).find("more than 5000000 points"),
            std::string::npos);
  EXPECT_NE(refusal(write(dir, "forged2.off", "OFF\n3 4000000000 0\n0 0 0\n1 0 0\n0 1 0\n"))
                .find("declares 4000000000 faces"),
            std::string::npos);
  const std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex 999999999\nproperty float x\n"
                          "property float y\nproperty float z\nend_header\n";
  EXPECT_NE(refusal(write(dir, "forged.ply", ply)).find("forged.ply: more than 5000000 points"), std::string::npos);
  // A binary STL whose count disagrees with its size.
  std::string stl(84, '\0');
  stl[80] = '\x10';  // 16 triangles, no data
  EXPECT_NE(refusal(write(dir, "short.stl", stl)).find("declares 16 triangles but has 84 bytes"), std::string::npos);
  // The mesh path holds the point limit too (counted from the OBJ's "v" lines).
  ReferenceLimits limits;
  limits.maxPoints = 4;
  EXPECT_NE(refusal(write(dir, "five.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\n"), limits)
                .find("more than 4 points"),
            std::string::npos);
  EXPECT_NE(refusal(write(dir, "binary.off", "OFF BINARY\n")).find("binary OFF"), std::string::npos);
}

TEST(ReferenceShape, MeshesInEveryFormatSplitPolygonsIntoTriangles) {
  testing::TempDir dir;
  const std::string off = "OFF\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0.5 0\n4 0 1 2 3\n3 1 4 2\n";
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0.5 0\nf 1 2 3 4\nf 2 5 3\n";
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0.5 0\n"
      "4 0 1 2 3\n3 1 4 2\n";
  const std::string stl =
      "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nendloop\nendfacet\n"
      "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n";
  for (const auto& [name, text, vertices, triangles] :
       {std::tuple<std::string, std::string, int, int>{"m.off", off, 5, 3}, {"m.obj", obj, 5, 3}, {"m.ply", ply, 5, 3},
        {"m.stl", stl, 4, 2}}) {
    const ReferenceShape s = readReferenceShape(write(dir, name, text));
    EXPECT_EQ(s.points.rows(), vertices) << name;
    EXPECT_EQ(s.triangles.rows(), triangles) << name;
    EXPECT_EQ(s.facesSkipped, 0) << name;
    EXPECT_TRUE(s.isMesh()) << name;
    // The triangles cover the unit square and the side triangle (area 0.5): nothing lost or doubled.
    double area = 0.0;
    for (Eigen::Index t = 0; t < s.triangles.rows(); ++t) {
      const Eigen::Vector3d a = s.points.row(s.triangles(t, 0)), b = s.points.row(s.triangles(t, 1)),
                            c = s.points.row(s.triangles(t, 2));
      area += 0.5 * (b - a).cross(c - a).norm();
    }
    EXPECT_NEAR(area, name == "m.stl" ? 1.0 : 1.5, 1e-6) << name;
  }
  // A non-manifold face (a third face on one edge) is kept: OpenMesh adds it with its own copies
  // of the vertices, so a reference loses no face to the half-edge structure.
  const std::string fan = "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n";
  const ReferenceShape nonManifold = readReferenceShape(write(dir, "fan.off", fan));
  EXPECT_EQ(nonManifold.triangles.rows(), 3);
  EXPECT_EQ(nonManifold.facesSkipped, 0);
}

TEST(ReferenceShape, CgalDemoDataReadsWithTheCountsTheFilesDeclare) {
  testing::TempDir dir;
  // kitten.xyz: one point with normal per line.
  const std::string kitten = cgalData(dir, "data/points_3/kitten.xyz");
  long lines = 0;
  {
    std::ifstream in(kitten);
    std::string line;
    while (std::getline(in, line)) lines += line.find_first_not_of(" \t\r") != std::string::npos;
  }
  const ReferenceShape k = readReferenceShape(kitten);
  EXPECT_EQ(k.points.rows(), lines);
  EXPECT_EQ(k.normals.rows(), lines);
  // hippo1.ply: a binary cloud with normals; its header declares the count.
  const std::string hippo = cgalData(dir, "data/points_3/hippo1.ply");
  long declared = -1;
  {
    std::ifstream in(hippo, std::ios::binary);
    std::string line;
    while (std::getline(in, line) && line.rfind("end_header", 0) != 0)
      if (line.rfind("element vertex ", 0) == 0) declared = std::stol(line.substr(15));
  }
  const ReferenceShape h = readReferenceShape(hippo);
  EXPECT_EQ(h.points.rows(), declared);
  EXPECT_EQ(h.normals.rows(), declared);
  EXPECT_FALSE(h.isMesh());
  EXPECT_TRUE(h.points.allFinite());
  // bunny00.off (a triangle mesh) and pig.stl.
  const std::string bunny = cgalData(dir, "data/meshes/bunny00.off");
  long v = 0, f = 0;
  {
    std::ifstream in(bunny);
    std::string word;
    in >> word >> v >> f;
  }
  const ReferenceShape b = readReferenceShape(bunny);
  EXPECT_EQ(b.points.rows(), v);
  EXPECT_EQ(b.triangles.rows() + b.facesSkipped, f);
  const ReferenceShape pig = readReferenceShape(cgalData(dir, "data/meshes/pig.stl"));
  EXPECT_GT(pig.triangles.rows(), 1000);
  EXPECT_GT(pig.diagonal(), 0.0);
}

}  // namespace
}  // namespace devsurf::reference
