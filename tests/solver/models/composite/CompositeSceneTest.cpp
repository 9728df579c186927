// Composite scenes through the proto layer: JSON conversion, semantic errors with JSON paths,
// and the presets of examples/ solved as `devsurf solve` solves them.

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "CompositeFixtures.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/models/composite/CompositePieces.h"
#include "devsurf/proto/Scene.h"
#include "support/Presets.h"

namespace devsurf::models::composite {
namespace {

using nlohmann::json;

std::string readSceneExample(const std::string& name) {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + name);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

json sheetScene() {
  proto::Scene s;
  CompositeDesign d = fixtures::flatSheet();
  d.fixed = {PointRef::ofVertex(0), PointRef::ofEdgePoint(6, 2)};
  d.handles = {{PointRef::ofVertex(3), Eigen::Vector3d(1.8, 2, 0.8), 2.0}};
  d.edges[2].crease = CreaseKind::None;
  // Non-uniform knots, the same on all three S edges (symmetric, so the reversed edge 6 matches).
  for (int e : {0, 3, 6}) d.edges[e].curve.knots = spline::KnotVector::clamped(3, {0, 0, 0, 0, 0.3, 0.7, 1, 1, 1, 1}, 6);
  s.model = d;
  return proto::sceneToJson(s);
}

void expectSceneError(const json& doc, const std::string& path, const std::string& fragment) {
  try {
    proto::sceneFromJson(doc);
    ADD_FAILURE() << "expected an error at " << path;
  } catch (const proto::SceneError& e) {
    EXPECT_EQ(e.path(), path) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(CompositeScene, RoundTripsThroughJson) {
  const json doc = sheetScene();
  EXPECT_EQ(doc["model"]["kind"], "composite");
  EXPECT_EQ(doc["model"]["edges"][0]["crease"], "fold");
  EXPECT_EQ(doc["model"]["edges"][0]["points"].size(), 4u);  // interior control points only
  EXPECT_FALSE(doc["model"]["edges"][2].contains("knots"));
  EXPECT_TRUE(doc["model"]["edges"][3].contains("knots"));
  EXPECT_FALSE(doc["model"]["edges"][1].contains("points"));
  EXPECT_TRUE(proto::schemaRegistry().validate(doc, "scene.schema.json").empty());
  const proto::Scene back = proto::sceneFromJson(doc);
  const auto& d = std::get<CompositeDesign>(back.model);
  EXPECT_EQ(d.edges[0].curve.points.rows(), 6);
  EXPECT_EQ(Eigen::RowVector3d(d.edges[0].curve.points.row(0)), Eigen::RowVector3d(d.vertices.row(1)));
  ASSERT_EQ(d.handles.size(), 1u);
  EXPECT_EQ(d.handles[0].weight, 2.0);
  EXPECT_EQ(d.fixed[1], PointRef::ofEdgePoint(6, 2));
  EXPECT_EQ(proto::sceneToJson(back), doc);

  // A solved state round-trips as well.
  CompositeModel model(d, back.solver.compositeOptions());
  engine::SolverOptions o = back.solver.solverOptions();
  o.maxIterations = 3;
  model.solve(o);
  proto::Scene solved = back;
  solved.model = model.design();
  const json again = proto::sceneToJson(solved);
  EXPECT_EQ(proto::sceneToJson(proto::sceneFromJson(again)), again);
}

TEST(CompositeScene, ErrorsNameTheJsonPath) {
  {
    json doc = sheetScene();
    doc["model"]["edges"][0]["points"].erase(0);
    doc["model"]["edges"][0]["points"].erase(0);
    doc["model"]["edges"][0]["points"].erase(0);
    expectSceneError(doc, "model.edges[0].points", "a degree-3 edge needs at least 2 interior control points, got 1");
  }
  {
    json doc = sheetScene();
    doc["model"]["edges"][1]["points"] = json::array({{0.5, 0, 0}});
    expectSceneError(doc, "model.edges[1].points", "an R edge (ruling) is straight");
  }
  {
    json doc = sheetScene();
    doc["model"]["edges"][1]["v"] = {0, 9};
    expectSceneError(doc, "model.edges[1].v[1]", "vertex 9 does not exist (6 vertices)");
  }
  {
    json doc = sheetScene();
    doc["model"]["faces"][1] = {2, 3, 0, 4};
    expectSceneError(doc, "model.faces[1][2]", "does not continue the boundary at vertex 3");
  }
  {
    json doc = sheetScene();
    doc["model"]["edges"][1]["type"] = "S";
    doc["model"]["edges"][1]["degree"] = 1;
    doc["model"]["edges"][5]["type"] = "S";
    doc["model"]["edges"][5]["degree"] = 1;
    expectSceneError(doc, "model.faces[0]", "has 4 S edges");
  }
  {
    json doc = sheetScene();
    doc["model"]["edges"][3]["knots"] = {0, 0, 0, 0.5, 1, 1, 1};
    expectSceneError(doc, "model.edges[3].knots", "");
  }
  {
    json doc = sheetScene();
    doc["model"]["fixed"][1]["index"] = 7;
    expectSceneError(doc, "model.fixed[1].index", "7 is out of range (edge 6 has 6 control points");
  }
  {
    json doc = sheetScene();
    doc["model"]["fixed"][1].erase("index");
    expectSceneError(doc, "model.fixed[1].index", "is required with \"edge\"");
  }
  {
    json doc = sheetScene();
    doc["model"]["edges"][0]["crease"] = "pleat";
    expectSceneError(doc, "model.edges[0].crease", "");
  }
  {
    json doc = sheetScene();
    doc["model"]["edges"][4]["crease"] = "smooth";
    expectSceneError(doc, "model.edges[4].crease", "needs faces on both sides");
  }
}

/// Solves a preset exactly as `devsurf solve` does and checks the quality the issue asks for.
CompositeQuality solvePreset(const std::string& name, CompositeDesign& before, CompositeDesign& after) {
  const proto::Scene scene = proto::sceneFromText(readSceneExample(name));
  before = std::get<CompositeDesign>(scene.model);
  CompositeModel model(before, scene.solver.compositeOptions());
  const engine::SolveSummary summary = model.solve(scene.solver.solverOptions());
  after = model.design();
  const CompositeQuality q = model.quality();
  std::cout << name << ": " << summary.stepsTaken() << " iterations, warp_angle_max_deg " << q.warpAngleMaxDeg
            << ", face_flatness_max " << q.faceFlatnessMax << ", face_flatness_mean " << q.faceFlatnessMean
            << ", vertex_curvature_max " << q.vertexCurvatureMax << ", crease_fold_residual_max "
            << q.creaseFoldResidualMax << ", fold angle max " << q.foldAngleMaxDeg << " deg\n";
  for (const PointRef& f : before.fixed) {
    if (f.isVertex()) {
      EXPECT_EQ(Eigen::RowVector3d(after.vertices.row(f.vertex)), Eigen::RowVector3d(before.vertices.row(f.vertex)));
    }
  }
  return q;
}

TEST(CompositePresets, CurvedFoldLiftedVertex) {
  CompositeDesign before, after;
  const CompositeQuality q = solvePreset("composite-curved-fold.json", before, after);
  EXPECT_LT(q.warpAngleMaxDeg, 0.05);
  EXPECT_LE(q.faceFlatnessMax, 1e-3);
  EXPECT_LT(q.creaseFoldResidualMax, 1e-2);
  EXPECT_GT(q.foldAngleMaxDeg, 20.0);  // it really folds
}

TEST(CompositePresets, TwoCreasesMeetingAtAVertex) {
  CompositeDesign before, after;
  const CompositeQuality q = solvePreset("composite-two-creases.json", before, after);
  EXPECT_LT(q.warpAngleMaxDeg, 0.05);
  EXPECT_LE(q.faceFlatnessMax, 1e-3);
  EXPECT_LT(q.creaseFoldResidualMax, 1e-2);
  EXPECT_GT(q.foldAngleMaxDeg, 20.0);
}

/// Vertex curvature measures one flat sheet. A cover's strips meet along seams (no crease, no
/// development): the pieces are cut apart there, and the seams' points are boundary points of each
/// piece. The same strips declared folded along those edges are one sheet, and the points count.
TEST(CompositeQualityOfSeams, AShapesCoverIsCutAlongItsSeamsButNotAlongFolds) {
  const proto::Scene scene = proto::sceneFromText(readSceneExample("composite-cover-bunny.json"));
  CompositeDesign design = std::get<CompositeDesign>(scene.model);
  ASSERT_EQ(design.developmentSamples, 0);
  const CompositeQuality seams = CompositeModel(design, scene.solver.compositeOptions()).quality();
  EXPECT_EQ(seams.interiorVertices, 0);
  EXPECT_EQ(seams.vertexCurvatureMax, 0.0);
  int folded = 0;
  std::vector<int> uses(design.edges.size(), 0);
  for (const std::vector<int>& face : design.faces)
    for (const int e : face) ++uses[static_cast<std::size_t>(e)];
  for (std::size_t e = 0; e < design.edges.size(); ++e)
    if (uses[e] == 2 && design.edges[e].type == EdgeType::Spline) {
      design.edges[e].crease = CreaseKind::Fold;
      ++folded;
    }
  EXPECT_EQ(folded, 7) << "eight strips side by side share seven edges";
  const CompositeQuality folds = CompositeModel(design, scene.solver.compositeOptions()).quality();
  EXPECT_GT(folds.interiorVertices, 7 * 4);
  // Strips fitted to a doubly curved back do not unfold into one sheet: angle defects appear.
  EXPECT_GT(folds.vertexCurvatureMax, 1e-3);
}

/// Every composite preset of examples/: solved as `devsurf solve` solves it (handles held), then
/// released — the handles dropped, the model rebuilt from the result as a session does — and 10
/// more iterations; the quality must then meet the thresholds of issue 5 (000_… Fig. 17 reports
/// δ_max from 1.6e-4 to 5.8e-3). A preset is one sheet with a development, or pieces cut apart
/// along seams (strips covering a shape): then each piece must be developable (warp) instead.
class CompositePresetQuality : public ::testing::TestWithParam<std::string> {};

TEST_P(CompositePresetQuality, MeetsThePapersThresholdsTenIterationsAfterRelease) {
  const proto::Scene scene = proto::sceneFromText(readSceneExample(GetParam()));
  CompositeDesign design = std::get<CompositeDesign>(scene.model);
  const bool pieces = design.developmentSamples == 0;
  if (pieces)
    ASSERT_TRUE(hasSeams(design, CompositeModel(design, scene.solver.compositeOptions()).topology()))
        << "a preset manages a development, or is pieces cut along seams";
  CompositeModel held(design, scene.solver.compositeOptions());
  held.solve(scene.solver.solverOptions());
  CompositeDesign released = held.design();
  released.handles.clear();
  CompositeModel model(released, scene.solver.compositeOptions());
  engine::SolverOptions o = scene.solver.solverOptions();
  o.maxIterations = 10;
  model.solve(o);
  const CompositeQuality q = model.quality();
  std::cout << GetParam() << " after release: face_flatness_max " << q.faceFlatnessMax << ", face_flatness_mean "
            << q.faceFlatnessMean << ", vertex_curvature_max " << q.vertexCurvatureMax
            << ", development_length_error " << model.developmentLengthError() << ", crease_fold_residual_max "
            << q.creaseFoldResidualMax << ", fold angle max " << q.foldAngleMaxDeg << " deg, unknowns "
            << model.numUnknowns() << "\n";
  EXPECT_LE(q.faceFlatnessMax, 1e-3);
  EXPECT_LE(q.faceFlatnessMean, 2e-4);
  EXPECT_LE(q.vertexCurvatureMax, 1e-3);
  if (pieces) EXPECT_LE(q.warpAngleMaxDeg, 0.05) << "every piece developable";
  else EXPECT_LE(model.developmentLengthError(), 5e-3);
  EXPECT_GT(q.foldAngleMaxDeg, 10.0) << "the preset really folds";
}

std::vector<std::string> compositePresets() {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(DEVSURF_SOURCE_DIR) + "/examples")) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("composite-", 0) == 0 && entry.path().extension() == ".json") names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

INSTANTIATE_TEST_SUITE_P(Examples, CompositePresetQuality, ::testing::ValuesIn(compositePresets()),
                         devsurf::testing::presetTestName<::testing::TestParamInfo<std::string>>);

TEST(CompositePresetQuality, EveryPresetIsFound) { EXPECT_GE(compositePresets().size(), 4u); }

}  // namespace
}  // namespace devsurf::models::composite
