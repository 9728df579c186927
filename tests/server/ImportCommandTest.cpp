// `devsurf import`: a quad_mesh scene from an OBJ/OFF/PLY mesh (issue 13, item 6), read back by
// the scene parser and solved; and the issue's shorthand spelling of a quad_mesh model.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "devsurf/io/PolygonMesh.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/server/Cli.h"
#include "server/CliTesting.h"

namespace devsurf::server {
namespace {

using testing::CliRun;
using testing::examplePath;
using testing::runCommand;

using nlohmann::json;

std::string importTempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("devsurf_import_" + std::to_string(::getpid()) + "_" + name)).string();
}

/// A saddle grid of n × n quads with a fan of triangles closing one corner, written as OBJ.
std::string writeSaddle(const std::string& name, int n, bool planar = false) {
  Eigen::MatrixXd v((n + 1) * (n + 1), 3);
  std::vector<io::PolygonFace> faces;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = i / double(n) - 0.5, y = j / double(n) - 0.5;
      v.row(j * (n + 1) + i) << x, y, planar ? 0.0 : 0.3 * (x * x - y * y);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      if (i == 0 && j == 0) {  // one quad as two triangles
        faces.push_back({a, a + 1, a + n + 2, -1});
        faces.push_back({a, a + n + 2, a + n + 1, -1});
      } else {
        faces.push_back({a, a + 1, a + n + 2, a + n + 1});
      }
    }
  const std::string path = importTempPath(name);
  io::writeObj(v, faces, path);
  return path;
}

TEST(ImportCommand, MakesAQuadMeshSceneThatSolvesFromAnObjFile) {
  const std::string mesh = writeSaddle("saddle.obj", 8);
  const CliRun r = runCommand({"import", mesh, "--proximity", "--units", "cm"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json scene = json::parse(r.out);
  const json& m = scene["model"];
  EXPECT_EQ(m["kind"], "quad_mesh");
  EXPECT_EQ(m["mesh"]["vertices"].size(), 81u);
  EXPECT_EQ(m["mesh"]["faces"].size(), 65u);
  EXPECT_EQ(m["mesh"]["faces"][0].size(), 3u) << "triangles kept as triangles";
  EXPECT_EQ(m["variables"], "both");
  EXPECT_EQ(m["reference"]["faces"].size(), 2u + 2u * 63u);
  EXPECT_EQ(scene["units"], "cm");
  // It is a scene like any other: the solver makes the saddle developable near itself.
  const std::string scenePath = importTempPath("saddle.json");
  std::ofstream(scenePath) << r.out;
  const CliRun solved = runCommand({"solve", scenePath});
  ASSERT_EQ(solved.code, 0) << solved.err;
  const json report = json::parse(solved.out);
  EXPECT_LT(report["metrics"]["length_error"].get<double>(), 5e-3);
  std::filesystem::remove(mesh);
  std::filesystem::remove(scenePath);
}

TEST(ImportCommand, TakesAnUnfoldingWithTheSameFacesAndRefusesOneWithout) {
  const std::string mesh = writeSaddle("m.obj", 4), flat = writeSaddle("flat.obj", 4, true),
                    other = writeSaddle("other.obj", 5, true);
  const CliRun r = runCommand({"import", mesh, "--unfolding", flat});
  ASSERT_EQ(r.code, 0) << r.err;
  const json m = json::parse(r.out)["model"];
  EXPECT_EQ(m["variables"], "mesh");
  EXPECT_EQ(m["unfolding"]["vertices"][3].size(), 2u) << "a planar unfolding is written as [x, y]";
  EXPECT_FALSE(m["unfolding"].contains("planar")) << "planar is the default, written only when false";
  const CliRun bad = runCommand({"import", mesh, "--unfolding", other});
  EXPECT_EQ(bad.code, 2);  // bad input (README's exit codes)
  EXPECT_NE(bad.err.find("the unfolding must have the mesh's vertices and faces"), std::string::npos) << bad.err;
  for (const std::string& p : {mesh, flat, other}) std::filesystem::remove(p);
}

TEST(ImportCommand, BadFilesAndOptionsAreNamed) {
  EXPECT_EQ(runCommand({"import"}).code, 2);
  EXPECT_EQ(runCommand({"import", "x.obj", "--variables", "all"}).code, 2);
  // Every kind of bad input exits 2, as `solve` (README): before, a missing mesh or crease pattern
  // and a mesh the model refuses exited 1, a missing scene for `solve` 2.
  const CliRun missing = runCommand({"import", importTempPath("missing.obj")});
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("cannot read mesh file"), std::string::npos);
  const CliRun missingPattern = runCommand({"import", importTempPath("missing.svg")});
  EXPECT_EQ(missingPattern.code, 2);
  EXPECT_NE(missingPattern.err.find("cannot read"), std::string::npos) << missingPattern.err;
  EXPECT_EQ(runCommand({"solve", importTempPath("missing.json")}).code, 2);
  const std::string pentagon = importTempPath("pentagon.obj");
  std::ofstream(pentagon) << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0.5 1.5 0\nv 0 1 0\nf 1 2 3 4 5\n";
  const CliRun r = runCommand({"import", pentagon});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("face 0 has more than four vertices"), std::string::npos) << r.err;
  std::filesystem::remove(pentagon);
  const std::string drawing = std::string(DEVSURF_SOURCE_DIR) + "/tests/data/svg/pleat.svg";
  const CliRun unwritable = runCommand({"import", drawing, "--out", importTempPath("no-such-dir") + "/scene.json"});
  EXPECT_EQ(unwritable.code, 2);
  EXPECT_NE(unwritable.err.find("--out: cannot write"), std::string::npos) << unwritable.err;
}

TEST(QuadMeshSpelling, TheContractsSpellingIsWhatIsReadAndWrittenBack) {
  const json contract = json::parse(R"({"format":"devsurf-scene","version":1,"model":{"kind":"quad_mesh",
    "mesh":{"vertices":[[0,0,0],[1,0,0],[1,1,0.1],[0,1,0],[2,0,0],[2,1,0]],"faces":[[0,1,2,3],[1,4,5,2]]},
    "unfolding":{"vertices":[[0,0],[1,0],[1,1],[0,1],[2,0],[2,1]]},"variables":"mesh","fixed":[0,3],
    "handles":[{"vertex":5,"position":[2,1,0.5]}],"glue":[[4,0]],
    "reference":{"vertices":[[0,0,0],[2,0,0],[0,2,0]],"faces":[[0,1,2]]}}})");
  const proto::Scene scene = proto::sceneFromJson(contract);
  const json m = proto::sceneToJson(scene)["model"];
  for (const char* key : {"mesh", "unfolding", "variables", "fixed", "glue", "reference"})
    EXPECT_EQ(m[key], contract["model"][key]) << key << " is written as the contract spells it";
  for (const char* legacy : {"faces", "variable", "unfolding_planar"}) EXPECT_FALSE(m.contains(legacy)) << legacy;
  // And it reads back from its own spelling to the same document.
  EXPECT_EQ(proto::sceneToJson(proto::sceneFromJson(proto::sceneToJson(scene))), proto::sceneToJson(scene));
  // A bad index is named where it stands.
  json bad = contract;
  bad["model"]["glue"] = json::parse("[[4,0],[4,40]]");
  try {
    proto::sceneFromJson(bad);
    FAIL() << "accepted a glue pair with vertex 40";
  } catch (const proto::SceneError& e) {
    EXPECT_EQ(e.path(), "model.glue[1][1]");
  }
  bad = contract;
  bad["model"]["mesh"]["faces"][1][2] = 9;
  try {
    proto::sceneFromJson(bad);
    FAIL() << "accepted a face with vertex 9";
  } catch (const proto::SceneError& e) {
    EXPECT_EQ(e.path(), "model.mesh.faces[1][2]");
  }
}

TEST(QuadMeshSpelling, ScenesWrittenBeforeTheContractReadAsTheSameDesign) {
  // The spelling devsurf wrote until issue 13's contract was adopted: faces and mesh apart,
  // unfolding as a list with unfolding_planar, variable, {vertex} and {on, pairs} objects,
  // reference triangles. Files of that time still open, and M′ on its own glue group keeps its side.
  const json legacy = json::parse(R"({"format":"devsurf-scene","version":1,"model":{"kind":"quad_mesh",
    "faces":[[0,1,2,3],[1,4,5,2]],"mesh":[[0,0,0],[1,0,0],[1,1,0.1],[0,1,0],[2,0,0],[2,1,0]],
    "unfolding":[[0,0,0],[1,0,0],[1,1,0],[0,1,0],[2,0,0],[2,1,0]],"unfolding_planar":false,"variable":"both",
    "fixed":[{"vertex":0},{"vertex":3,"on":"unfolding"}],"handles":[{"vertex":5,"position":[2,1,0.5]}],
    "glue":[{"on":"mesh","pairs":[[4,0]]},{"on":"unfolding","pairs":[[5,3]]}],
    "reference":{"vertices":[[0,0,0],[2,0,0],[0,2,0]],"triangles":[[0,1,2]]}}})");
  const json m = proto::sceneToJson(proto::sceneFromJson(legacy))["model"];
  EXPECT_EQ(m["mesh"]["faces"], legacy["model"]["faces"]);
  EXPECT_EQ(m["mesh"]["vertices"], legacy["model"]["mesh"]);
  EXPECT_EQ(m["unfolding"], json::parse(R"({"planar":false,"vertices":[[0,0,0],[1,0,0],[1,1,0],[0,1,0],[2,0,0],[2,1,0]]})"));
  EXPECT_EQ(m["variables"], "both");
  EXPECT_EQ(m["fixed"], json::parse(R"([0,{"on":"unfolding","vertex":3}])"));
  EXPECT_EQ(m["glue"], json::parse(R"([[4,0],{"on":"unfolding","pairs":[[5,3]]}])"));
  EXPECT_EQ(m["reference"]["faces"], json::parse("[[0,1,2]]"));
  json bad = legacy;
  bad["model"]["faces"][0][0] = 6;
  try {
    proto::sceneFromJson(bad);
    FAIL() << "accepted a face with vertex 6";
  } catch (const proto::SceneError& e) {
    EXPECT_EQ(e.path(), "model.mesh.faces[0][0]") << "named in the spelling the scene is written in now";
  }
  // A control net written with a top-level faces list and no mesh (its refinement is the mesh).
  json spline = json::parse(std::ifstream(std::string(DEVSURF_SOURCE_DIR) + "/examples/spline-single-patch.json"));
  spline["model"].erase("mesh");
  spline["model"]["faces"] = json::parse("[[0,1,2,3]]");
  const json refined = proto::sceneToJson(proto::sceneFromJson(spline))["model"];
  EXPECT_GT(refined["mesh"]["faces"].size(), 100u) << "the refinement's faces, not the list given";
}

TEST(QuadMeshSpelling, AFaceIndexBeyondTheCoordinateRangeIsNamedAsAMissingVertex) {
  json doc = json::parse(R"({"format":"devsurf-scene","version":1,"model":{"kind":"quad_mesh",
    "mesh":{"vertices":[[0,0,0],[1,0,0],[1,1,0],[0,1,0]],"faces":[[0,1,2,3]]}}})");
  doc["model"]["mesh"]["faces"][0][2] = 3000000000LL;
  try {
    proto::sceneFromJson(doc);
    FAIL() << "accepted vertex 3000000000";
  } catch (const proto::SceneError& e) {
    EXPECT_EQ(e.path(), "model.mesh.faces[0][2]");
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what() << ": an index, not a coordinate";
  }
}

}  // namespace
}  // namespace devsurf::server
