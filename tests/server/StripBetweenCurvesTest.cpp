// The issue-6 presets (quasi_strip: Bo et al.; conical_strip: Chu et al.) solved end to end with
// `devsurf solve`: the report validates, the scene is the input, the outcomes the papers promise.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "devsurf/io/QuadMesh.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/server/Cli.h"
#include "devsurf/server/SceneSolver.h"
#include "support/TempDir.h"

namespace devsurf::server {
namespace {

using nlohmann::json;

json readJson(const std::string& path) {
  std::ifstream file(path);
  return json::parse(file);
}

std::string example(const std::string& name) { return std::string(DEVSURF_SOURCE_DIR) + "/examples/" + name; }

struct Solved {
  int code;
  json report;
  std::string err;
};

Solved solveExample(const std::string& name, const std::vector<std::string>& extra = {}) {
  std::vector<std::string> args{"solve", example(name)};
  args.insert(args.end(), extra.begin(), extra.end());
  std::istringstream in;
  std::ostringstream out, err;
  const int code = runCli(args, in, out, err);
  return {code, code == 0 && !out.str().empty() ? json::parse(out.str()) : json(), err.str()};
}

class StripBetweenCurvesPreset : public ::testing::TestWithParam<std::string> {};

TEST_P(StripBetweenCurvesPreset, SolvesToAValidReportWhoseSceneIsTheInput) {
  const Solved s = solveExample(GetParam());
  ASSERT_EQ(s.code, 0) << s.err;
  const auto errors = proto::schemaRegistry().validate(s.report, "report.schema.json");
  EXPECT_TRUE(errors.empty()) << errors[0].toString();
  // The input curves do not move: the reported scene is the input, as sceneToJson writes it.
  const json input = proto::sceneToJson(proto::sceneFromJson(readJson(example(GetParam()))));
  EXPECT_EQ(s.report["scene"], input);
  ASSERT_TRUE(s.report.contains("result"));
  EXPECT_EQ(s.report["result"]["kind"], input["model"]["kind"]);
  EXPECT_TRUE(readJson(example(GetParam())).contains("description"));
}

TEST_P(StripBetweenCurvesPreset, MeetsThePapersDevelopabilityPromises) {
  const Solved s = solveExample(GetParam());
  ASSERT_EQ(s.code, 0) << s.err;
  const json& m = s.report["metrics"];
  const json& result = s.report["result"];
  if (result["kind"] == "quasi_strip") {
    EXPECT_GE(m["warp_angle_max_deg_dense"].get<double>(), 0.0);
    EXPECT_LE(m["warp_angle_mean_deg"].get<double>(), m["warp_angle_max_deg"].get<double>());
    const json& mapping = result["mapping"];
    EXPECT_EQ(mapping["degree"], 2);
    EXPECT_EQ(mapping["coefficients"].size(), 50u);
    EXPECT_EQ(mapping["knots"].size(), 50u + 2u + 1u);
    for (std::size_t i = 1; i < mapping["coefficients"].size(); ++i)  // σ is monotone (eq. 5)
      EXPECT_GE(mapping["coefficients"][i].get<double>(), mapping["coefficients"][i - 1].get<double>());
    const json& surface = result["surface"];
    EXPECT_EQ(surface["degrees"][0], 1);
    EXPECT_EQ(surface["control_points"][0].size(), surface["control_points"][1].size());
    EXPECT_EQ(surface["knots"][1].size(),
              surface["control_points"][0].size() + surface["degrees"][1].get<std::size_t>() + 1);
    EXPECT_EQ(result["samples"]["warp_angle_deg"].size(), 100u);
    if (GetParam() == "quasi-strip-twisted.json") {
      EXPECT_LE(m["warp_angle_max_deg"].get<double>(), 2.0);
      EXPECT_LE(m["warp_angle_mean_deg"].get<double>(), 0.2);
    } else {
      EXPECT_LE(m["warp_angle_max_deg"].get<double>(), 2.0);
      EXPECT_LE(m["warp_angle_mean_deg"].get<double>(), 0.2);
    }
  } else {
    // Every patch is developable (eq. 3 and eq. 2 to 1e-12 relative) and the strip is G1.
    EXPECT_LE(m["projection_residual_max"].get<double>(), 1e-12);
    EXPECT_LE(m["coplanarity_residual_max"].get<double>(), 1e-12);
    EXPECT_LE(m["normal_jump_max_rad"].get<double>(), 1e-9);
    EXPECT_GT(m["greedy_normal_jump_max_rad"].get<double>(), m["normal_jump_max_rad"].get<double>());
    EXPECT_EQ(m["n3"].get<double>() + m["n4"].get<double>(), m["patches"].get<double>());
    EXPECT_GT(m["n4"].get<double>(), 0.0);  // the parameters let quadrilateral patches through
    ASSERT_EQ(result["patches"].size(), m["patches"].get<std::size_t>());
    ASSERT_EQ(result["unfolded"].size(), result["patches"].size());
    for (const json& patch : result["patches"]) {
      EXPECT_EQ(patch["a"].size(), 4u);  // cubic after the G1 adjustment
      EXPECT_EQ(patch["b"].size(), 4u);
    }
    const double h4 = readJson(example(GetParam()))["model"]["h4"].get<double>();
    EXPECT_LE(m["corner_deviation_max"].get<double>(), h4);
  }
}

INSTANTIATE_TEST_SUITE_P(Issue6, StripBetweenCurvesPreset,
                         ::testing::Values("quasi-strip-hull.json", "quasi-strip-brim.json",
                                           "quasi-strip-twisted.json", "conical-strip-hull.json",
                                           "conical-strip-brim.json", "conical-strip-twisted.json"),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param.substr(0, info.param.size() - 5);
                           for (char& c : name)
                             if (c == '-') c = '_';
                           return name;
                         });

TEST(StripBetweenCurves, ExportsTheSampledStripAsObjQuadsAndTheSurfacesAsIges) {
  devsurf::testing::TempDir dir;
  for (const std::string name : {"quasi-strip-hull.json", "conical-strip-hull.json"}) {
    const std::string obj = (dir.path() / (name + ".obj")).string(), igs = (dir.path() / (name + ".igs")).string();
    const Solved s = solveExample(name, {"--export", "obj:" + obj, "--export", "iges:" + igs});
    ASSERT_EQ(s.code, 0) << s.err;
    const io::QuadMesh mesh = io::readQuadMesh(obj);
    if (name.rfind("quasi", 0) == 0) {
      EXPECT_EQ(mesh.quads.rows(), 199 * 7);
    } else {
      EXPECT_EQ(mesh.quads.rows(), static_cast<Eigen::Index>(s.report["result"]["patches"].size()) * 24 * 4);
    }
    std::ifstream file(igs);
    std::stringstream text;
    text << file.rdbuf();
    EXPECT_NE(text.str().find("128,"), std::string::npos);  // entity 128 surfaces
    EXPECT_NE(text.str().find("126,"), std::string::npos);  // entity 126 curves
  }
}

TEST(StripBetweenCurves, AJobsSceneExportsTheSolvedStripAgain) {
  // exportScene solves a quasi/conical scene first: the export is the result, not the initial σ = t.
  const json scene = readJson(example("quasi-strip-twisted.json"));
  const ExportedFile iges = SceneSolver::exportScene(scene, "iges");
  EXPECT_EQ(iges.mediaType, "model/iges");
  EXPECT_EQ(iges.extension, "igs");
  SceneSolver solver(proto::sceneFromJson(scene));
  solver.solve();
  EXPECT_NE(iges.content.find("128,"), std::string::npos);
  const ExportedFile obj = SceneSolver::exportScene(scene, "obj");
  EXPECT_EQ(obj.content, solver.exportAs("obj").content);
  EXPECT_THROW(SceneSolver::exportScene(scene, "fold"), ExportUnavailable);
}

TEST(StripBetweenCurves, IterationsOnTheCommandLineLimitTheQuasiStripOptimizer) {
  const Solved limited = solveExample("quasi-strip-twisted.json", {"--iterations", "3"});
  const Solved full = solveExample("quasi-strip-twisted.json");
  ASSERT_EQ(limited.code, 0) << limited.err;
  ASSERT_EQ(full.code, 0) << full.err;
  EXPECT_EQ(limited.report["termination"], "max_iterations");
  EXPECT_LT(limited.report["iterations"].get<int>(), full.report["iterations"].get<int>());
  EXPECT_GT(limited.report["metrics"]["warp_angle_max_deg"].get<double>(),
            full.report["metrics"]["warp_angle_max_deg"].get<double>());
}

}  // namespace
}  // namespace devsurf::server
