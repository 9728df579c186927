// STL exports (issue 11, item 6): every preset in examples/ exported as STL is made of triangles —
// two per quad of its OBJ export, less the ones of zero area — and covers the same area, in
// millimetres where the OBJ is in the scene's units (cm, m, in presets among them). Both files
// are read back by the small parsers here, not by OpenMesh that wrote them.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "devsurf/proto/Scene.h"
#include "devsurf/server/SceneSolver.h"
#include "support/ExportChecks.h"
#include "support/Presets.h"
#include "support/TempDir.h"

namespace devsurf::server {
namespace {

using Triangle = std::array<Eigen::Vector3d, 3>;

double area(const Triangle& t) { return 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).norm(); }

/// Zero area up to the files' printed digits: twice the area at most 1e-9 × the longest edge².
bool degenerate(const Triangle& t) {
  const double longest =
      std::max({(t[1] - t[0]).squaredNorm(), (t[2] - t[1]).squaredNorm(), (t[0] - t[2]).squaredNorm()});
  return 2.0 * area(t) <= 1e-9 * longest;
}

/// The facets of an ASCII STL file ("solid … facet normal … outer loop vertex ×3 endloop endfacet …
/// endsolid"). Fails the test on anything else, in particular on a facet without three vertices.
std::vector<Triangle> readAsciiStl(const std::string& path) {
  std::ifstream file(path);
  std::string token;
  file >> token;
  EXPECT_EQ(token, "solid") << path << " is not ASCII STL";
  std::getline(file, token);  // the solid's name
  std::vector<Triangle> facets;
  Triangle current;
  int vertices = -1;  // -1: outside a facet
  while (file >> token) {
    if (token == "facet") {
      EXPECT_EQ(vertices, -1) << path << ": facet inside a facet";
      vertices = 0;
    } else if (token == "vertex") {
      if (vertices < 0 || vertices >= 3) {
        ADD_FAILURE() << path << ": vertex " << vertices + 1 << " of facet " << facets.size();
        return facets;
      }
      Eigen::Vector3d& p = current[static_cast<std::size_t>(vertices++)];
      file >> p.x() >> p.y() >> p.z();
    } else if (token == "endfacet") {
      EXPECT_EQ(vertices, 3) << path << ": facet " << facets.size() << " has " << vertices << " vertices";
      if (vertices == 3) facets.push_back(current);
      vertices = -1;
    } else if (token == "normal") {
      // Read as text: a stream reading a double stops at "-nan" without saying what it saw.
      for (int k = 0; k < 3; ++k) {
        std::string value;
        file >> value;
        char* end = nullptr;
        const double x = std::strtod(value.c_str(), &end);
        EXPECT_TRUE(end != value.c_str() && *end == '\0' && std::isfinite(x))
            << path << ": facet " << facets.size() << " has the normal component \"" << value << "\"";
      }
    } else if (token == "endsolid") {
      break;
    }
    // "outer loop", "endloop": nothing to keep (the normals' directions are not compared).
  }
  EXPECT_EQ(token, "endsolid") << path << " ends early";
  return facets;
}

/// The quads of an OBJ file, read with the suites' independent OBJ reader (support/ExportChecks.h);
/// a triangle (quad_mesh faces may be triangles) as a quad with its last vertex repeated.
std::vector<std::array<Eigen::Vector3d, 4>> readObjQuads(const std::string& path) {
  std::ifstream file(path);
  std::ostringstream text;
  text << file.rdbuf();
  const devsurf::testing::ObjMesh mesh = devsurf::testing::parseObj(text.str());
  std::vector<std::array<Eigen::Vector3d, 4>> quads;
  for (const std::vector<int>& f : mesh.faces) {
    EXPECT_TRUE(f.size() == 4u || f.size() == 3u) << path;
    if (f.size() != 4 && f.size() != 3) continue;
    std::array<Eigen::Vector3d, 4> q;
    for (std::size_t c = 0; c < 4; ++c) q[c] = mesh.vertices.at(static_cast<std::size_t>(f[std::min(c, f.size() - 1)]));
    quads.push_back(q);
  }
  return quads;
}

TEST(StlExport, EveryPresetIsWrittenAsTwoTrianglesPerQuadCoveringTheObjExportsArea) {
  std::vector<std::filesystem::path> files;
  for (const std::string& name : devsurf::testing::presetFiles())
    files.push_back(std::filesystem::path(DEVSURF_SOURCE_DIR) / "examples" / name);
  ASSERT_GE(files.size(), 16u);
  devsurf::testing::TempDir dir;
  int degenerateTotal = 0;
  for (const std::filesystem::path& file : files) {
    const std::string name = file.stem().string();
    SCOPED_TRACE(name);
    std::ifstream in(file);
    const nlohmann::json scene = nlohmann::json::parse(in);
    // STL in millimetres, OBJ in the scene's units (mm per unit by the scene's own word).
    const std::map<std::string, double> mmPer = {{"mm", 1.0}, {"cm", 10.0}, {"m", 1000.0}, {"in", 25.4}};
    const double mm = mmPer.at(scene.value("units", std::string("mm")));
    SceneSolver solver(proto::sceneFromJson(scene));
    solver.solve();
    const std::string obj = (dir.path() / (name + ".obj")).string(), stl = (dir.path() / (name + ".stl")).string();
    solver.exportTo("obj:" + obj);
    solver.exportTo("stl:" + stl);
    const auto quads = readObjQuads(obj);
    const std::vector<Triangle> facets = readAsciiStl(stl);
    ASSERT_FALSE(quads.empty());
    // Each OBJ quad (v0, v1, v2, v3) as the triangles (v0, v1, v2) and (v0, v2, v3).
    int degenerates = 0;
    double objArea = 0.0;
    for (const auto& q : quads) {
      for (const Triangle& t : {Triangle{q[0], q[1], q[2]}, Triangle{q[0], q[2], q[3]}}) {
        degenerates += degenerate(t);
        objArea += area(t);
      }
    }
    double stlArea = 0.0;
    int zeroFacets = 0;
    for (const Triangle& t : facets) {
      stlArea += area(t);
      zeroFacets += degenerate(t);
    }
    EXPECT_EQ(facets.size(), 2 * quads.size() - static_cast<std::size_t>(degenerates));
    EXPECT_EQ(zeroFacets, 0);
    EXPECT_NEAR(stlArea, mm * mm * objArea, 1e-7 * mm * mm * objArea);
    degenerateTotal += degenerates;
    std::cout << name << ": " << quads.size() << " quads, " << facets.size() << " triangles (" << degenerates
              << " of zero area left out), area " << stlArea << " (OBJ " << objArea << ")\n";
  }
  std::cout << files.size() << " presets, " << degenerateTotal << " zero-area triangles left out\n";
}

TEST(StlExport, AStripPinchedToAPointWritesNoFacetWithoutANormal) {
  // A tryout's quasi strip whose second curve ends on the first's end point: its last ruling has
  // no length, and triangles whose corners were 1e-10 apart (one point in STL's floats) were
  // written with the normal "-nan -nan -nan".
  std::ifstream in(std::filesystem::path(DEVSURF_SOURCE_DIR) / "examples" / "quasi-strip-twisted.json");
  nlohmann::json scene = nlohmann::json::parse(in);
  scene["model"]["c2"]["points"].back() = scene["model"]["c1"]["points"].back();
  SceneSolver solver(proto::sceneFromJson(scene));
  solver.solve();
  devsurf::testing::TempDir dir;
  const std::string stl = (dir.path() / "pinched.stl").string();
  solver.exportTo("stl:" + stl);
  const std::vector<Triangle> facets = readAsciiStl(stl);  // every normal finite (above)
  ASSERT_FALSE(facets.empty());
  int repeated = 0;
  for (const Triangle& t : facets)
    for (int k = 0; k < 3; ++k) repeated += t[static_cast<std::size_t>(k)].cast<float>() == t[static_cast<std::size_t>((k + 1) % 3)].cast<float>();
  EXPECT_EQ(repeated, 0) << "facets with two corners one point in single precision";
}

TEST(StlExport, ASceneNameWithLineBreaksStaysOneCommentInObjAndDxf) {
  // A tryout's part named "my part\nv 1 1 1": its OBJ (REST) got a vertex more, every face then
  // pointing at the wrong one, and its DXF's group codes and values fell out of step.
  std::ifstream in(std::filesystem::path(DEVSURF_SOURCE_DIR) / "examples" / "strip-twisted.json");
  nlohmann::json plain = nlohmann::json::parse(in);
  plain["name"] = "my part";
  nlohmann::json broken = plain;
  broken["name"] = "my part\nv 1 1 1\r\n0\nSECTION\t\x7f";
  for (const std::string format : {"obj", "dxf"}) {
    SCOPED_TRACE(format);
    const std::string good = SceneSolver::exportScene(plain, format).content;
    const std::string text = SceneSolver::exportScene(broken, format).content;
    std::vector<std::string> goodLines, lines;
    for (auto [from, to] : {std::pair{&good, &goodLines}, std::pair{&text, &lines}}) {
      std::istringstream stream(*from);
      for (std::string line; std::getline(stream, line);) to->push_back(line);
    }
    // The same records, line for line; only the comment differs (its breaks written as spaces).
    ASSERT_EQ(lines.size(), goodLines.size());
    int differing = 0;
    for (std::size_t k = 0; k < lines.size(); ++k) differing += lines[k] != goodLines[k];
    EXPECT_EQ(differing, 1);
    if (format == "dxf") {
      // Group code lines are integers, at every other line (an independent check of the pairs).
      for (std::size_t k = 0; k < lines.size(); k += 2) {
        std::string code = lines[k];
        code.erase(0, code.find_first_not_of(' '));
        if (!code.empty() && code.back() == '\r') code.pop_back();
        char* end = nullptr;
        std::strtol(code.c_str(), &end, 10);
        EXPECT_TRUE(!code.empty() && *end == '\0') << "line " << k + 1 << " is no group code: \"" << lines[k] << "\"";
      }
    }
  }
}

}  // namespace
}  // namespace devsurf::server
