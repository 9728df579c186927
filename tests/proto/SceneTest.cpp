#include "devsurf/proto/Scene.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <fstream>
#include <sstream>

#include "devsurf/proto/Report.h"

namespace devsurf::proto {
namespace {

using nlohmann::json;

json validScene() {
  return json::parse(R"({
    "format": "devsurf-scene", "version": 1, "name": "test strip",
    "model": { "kind": "strip",
      "a": { "degree": 3, "points": [[0,0,0],[1,0,0],[2,0,0],[3,0,0],[4,0,0]] },
      "b": { "degree": 3, "points": [[0,1,0],[1,1,0],[2,1,0],[3,1,0],[4,1,0]] },
      "normals": { "type": "vectors" },
      "fixed": [ { "curve": "a", "index": 0 } ],
      "handles": [ { "curve": "b", "index": 4, "position": [4.0, 1.0, 0.5], "weight": 2.0 } ] },
    "solver": { "iterations": 7, "fairness": 0.02 } })");
}

/// The error a broken document gives: its path and message.
SceneError errorOf(const json& doc) {
  try {
    sceneFromJson(doc);
  } catch (const SceneError& e) {
    return e;
  }
  ADD_FAILURE() << "expected a SceneError for " << doc.dump();
  return SceneError("", "", "");
}

TEST(Scene, ParsesAStripWithDefaultsForOmittedSolverFields) {
  const Scene s = sceneFromJson(validScene());
  EXPECT_EQ(s.name, "test strip");
  EXPECT_EQ(s.solver.iterations, 7);
  EXPECT_DOUBLE_EQ(s.solver.fairness, 0.02);
  EXPECT_DOUBLE_EQ(s.solver.fairnessDecay, 0.8);
  EXPECT_DOUBLE_EQ(s.solver.regularization, 0.01);
  const auto& d = std::get<models::strip::StripDesign>(s.model);
  EXPECT_EQ(d.a.points.rows(), 5);
  EXPECT_EQ(d.a.knots.knots(), spline::KnotVector::clampedUniform(3, 5).knots());
  ASSERT_EQ(d.handles.size(), 1u);
  EXPECT_EQ(d.handles[0].point.curve, models::strip::Curve::B);
  EXPECT_DOUBLE_EQ(d.handles[0].weight, 2.0);
  EXPECT_EQ(d.handles[0].position, Eigen::Vector3d(4.0, 1.0, 0.5));
}

TEST(Scene, RoundTripsThroughJsonWithTheSameCurveStructure) {
  json doc = validScene();
  doc["model"]["a"]["knots"] = {0, 0, 0, 0, 0.3, 1, 1, 1, 1};
  doc["model"]["b"]["knots"] = {0, 0, 0, 0, 0.3, 1, 1, 1, 1};
  doc["model"]["b"]["weights"] = {1, 2, 1, 0.5, 1};
  const Scene s = sceneFromJson(doc);
  const json out = sceneToJson(s);
  EXPECT_EQ(out["model"]["a"]["knots"], doc["model"]["a"]["knots"]);
  EXPECT_EQ(out["model"]["b"]["weights"], doc["model"]["b"]["weights"]);
  EXPECT_EQ(out["model"]["a"]["points"], doc["model"]["a"]["points"]);
  EXPECT_FALSE(sceneToJson(sceneFromJson(validScene()))["model"]["a"].contains("knots"));
  const Scene again = sceneFromJson(out);
  EXPECT_EQ(sceneToJson(again), out);
}

TEST(Scene, UnitsDefaultToMillimetresAndRoundTrip) {
  const Scene plain = sceneFromJson(validScene());
  EXPECT_EQ(plain.units, "mm");
  EXPECT_FALSE(sceneToJson(plain).contains("units"));  // the default stays implicit
  EXPECT_EQ(schemaRegistry().get("scene.schema.json")["properties"]["units"]["default"], plain.units);
  for (const char* u : {"mm", "cm", "m", "in"}) {
    json doc = validScene();
    doc["units"] = u;
    const Scene s = sceneFromJson(doc);
    EXPECT_EQ(s.units, u);
    EXPECT_EQ(sceneFromJson(sceneToJson(s)).units, u) << u;
  }
  EXPECT_DOUBLE_EQ(millimetresPerUnit("mm"), 1.0);
  EXPECT_DOUBLE_EQ(millimetresPerUnit("cm"), 10.0);
  EXPECT_DOUBLE_EQ(millimetresPerUnit("m"), 1000.0);
  EXPECT_DOUBLE_EQ(millimetresPerUnit("in"), 25.4);
  EXPECT_THROW(millimetresPerUnit("ft"), std::invalid_argument);
}

TEST(Scene, AnUnknownUnitIsRejectedNamingTheField) {
  json doc = validScene();
  doc["units"] = "ft";
  EXPECT_EQ(errorOf(doc).path(), "units");
  doc["units"] = 25.4;
  EXPECT_EQ(errorOf(doc).path(), "units");
}

TEST(Scene, MalformedDocumentsNameTheFieldAndRule) {
  struct Case {
    std::function<void(json&)> breakIt;
    std::string path;
    std::string messagePart;
  };
  const std::vector<Case> cases = {
      {[](json& d) { d["model"]["kind"] = "sphere"; }, "model.kind", "unknown kind"},
      {[](json& d) { d["model"].erase("kind"); }, "model.kind", "required"},
      {[](json& d) { d["model"]["a"]["points"][3] = {1, 2}; }, "model.a.points[3]", "expected 3 numbers"},
      {[](json& d) { d["model"]["a"]["points"][2][1] = "x"; }, "model.a.points[2]", "expected 3 numbers"},
      {[](json& d) { d["model"]["b"]["degree"] = 2; }, "model.b.degree", "must equal a.degree"},
      {[](json& d) {
         d["model"]["b"]["knots"] = {0, 0, 0, 0, 0.7, 1, 1, 1, 1};
       }, "model.b.knots", "must equal a.knots"},
      {[](json& d) { d["model"]["a"]["knots"] = {0, 0, 0, 0, 1, 1, 1}; }, "model.a.knots", "expected 9"},
      {[](json& d) { d["model"]["a"]["knots"] = {0, 0, 0, 0, 0.6, 0.4, 1, 1, 1}; }, "model.a.knots", "non-decreasing"},
      {[](json& d) {
         d["model"]["a"]["points"] = json::array({{0, 0, 0}, {1, 0, 0}});
         d["model"]["b"]["points"] = json::array({{0, 1, 0}, {1, 1, 0}});
       }, "model.a.points", "at least 4 control points"},
      {[](json& d) { d["model"]["b"]["points"].erase(4); }, "model.b.points", "expected 5 control points"},
      {[](json& d) { d["model"]["fixed"][0]["index"] = 9; }, "model.fixed[0].index", "out of range"},
      {[](json& d) { d["model"]["fixed"][0]["curve"] = "c"; }, "model.fixed[0].curve", ""},
      {[](json& d) { d["model"]["handles"][0]["index"] = -1; }, "model.handles[0].index", ""},
      {[](json& d) { d["model"]["handles"][0]["weight"] = 0; }, "model.handles[0].weight", ""},
      {[](json& d) { d["model"]["normals"] = {{"type", "quaternions"}}; }, "model.normals.type", ""},
      {[](json& d) { d["solver"]["iterations"] = -3; }, "solver.iterations", ""},
      {[](json& d) { d["solver"]["speed"] = 11; }, "solver.speed", "unknown field"},
      {[](json& d) { d["model"]["b"]["weights"] = {1, 1, 1}; }, "model.b.weights", "expected 5 weights"},
      {[](json& d) { d["format"] = "obj"; }, "format", ""},
      {[](json& d) { d["model"]["b"]["points"] = d["model"]["a"]["points"]; }, "model.b.points", "no width"},
  };
  for (const Case& c : cases) {
    json doc = validScene();
    c.breakIt(doc);
    const SceneError e = errorOf(doc);
    EXPECT_EQ(e.path(), c.path) << e.what();
    EXPECT_NE(std::string(e.what()).find(c.messagePart), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind(c.path + ": ", 0), 0u) << e.what();
  }
}

TEST(Scene, NonFiniteAndNonJsonInputIsRejected) {
  std::string text = validScene().dump();
  const std::string needle = "[1,0,0]";
  const std::size_t at = text.find(needle);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, needle.size(), "[1e999,0,0]");
  try {
    sceneFromText(text);
    ADD_FAILURE() << "infinite coordinate accepted";
  } catch (const SceneError& e) {
    // nlohmann refuses numbers beyond double range while parsing.
    EXPECT_EQ(e.rule(), "json");
    EXPECT_NE(std::string(e.what()).find("1e999"), std::string::npos) << e.what();
  }
  // A non-finite value that reaches the document by other means is caught by the schema.
  json doc = validScene();
  doc["model"]["a"]["points"][1][0] = std::numeric_limits<double>::infinity();
  EXPECT_EQ(errorOf(doc).path(), "model.a.points[1]");
  // NaN is not JSON at all.
  std::string nan = validScene().dump();
  nan.replace(nan.find(needle), needle.size(), "[NaN,0,0]");
  EXPECT_THROW(sceneFromText(nan), SceneError);
  try {
    sceneFromText("{\"format\": ");
  } catch (const SceneError& e) {
    EXPECT_EQ(e.rule(), "json");
    EXPECT_NE(std::string(e.what()).find("(root): not valid JSON"), std::string::npos);
  }
}

// Degenerate quad meshes are refused naming the field: an unfolding (or a mesh) shrunk to a point
// has no size to bend from, and a face's index is named where it is, in model.mesh.faces.
TEST(Scene, DegenerateQuadMeshesNameTheirField) {
  std::ifstream file(std::filesystem::path(DEVSURF_SOURCE_DIR) / "examples" / "quad-bend-sheet.json");
  const json sheet = json::parse(file);
  struct Case {
    std::function<void(json&)> breakIt;
    std::string path;
    std::string messagePart;
  };
  const std::vector<Case> cases = {
      {[](json& d) { for (json& v : d["model"]["unfolding"]["vertices"]) v = {0.0, 0.0}; }, "model.unfolding.vertices", "one point"},
      {[](json& d) { for (json& v : d["model"]["mesh"]["vertices"]) v = {1.0, 2.0, 3.0}; }, "model.mesh.vertices", "one point"},
      {[](json& d) { d["model"]["mesh"]["faces"][0] = {0, 0, 0, 0}; }, "model.mesh.faces[0]", ""},
  };
  for (const Case& c : cases) {
    json doc = sheet;
    c.breakIt(doc);
    const SceneError e = errorOf(doc);
    EXPECT_EQ(e.path(), c.path) << e.what();
    EXPECT_NE(std::string(e.what()).find(c.messagePart), std::string::npos) << e.what();
  }
}

TEST(Scene, EveryExampleValidatesAndRoundTrips) {
  const std::filesystem::path dir = std::filesystem::path(DEVSURF_SOURCE_DIR) / "examples";
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".json") continue;
    std::ifstream file(entry.path());
    std::stringstream text;
    text << file.rdbuf();
    const Scene s = sceneFromText(text.str());
    EXPECT_TRUE(schemaRegistry().validate(sceneToJson(s), "scene.schema.json").empty()) << entry.path();
    ++count;
  }
  EXPECT_GE(count, 4);
}

TEST(Scene, SolverDefaultsInTheSchemaMatchTheCode) {
  json doc = validScene();
  doc.erase("solver");
  const json solver = sceneToJson(sceneFromJson(doc))["solver"];
  const json& properties = schemaRegistry().get("scene.schema.json")["$defs"]["solver"]["properties"];
  ASSERT_FALSE(properties.empty());
  for (const auto& [name, property] : properties.items()) {
    ASSERT_TRUE(property.contains("default")) << name;
    ASSERT_TRUE(solver.contains(name)) << name;
    EXPECT_EQ(solver[name], property["default"]) << name;
  }
}

TEST(Report, ValidatesAgainstTheReportSchema) {
  engine::SolveSummary summary;
  summary.termNames = {"developability", "fairness", "fairness"};
  engine::IterationRecord r0;
  r0.termResiduals = {1.0, 0.5, 0.25};
  engine::IterationRecord r1 = r0;
  r1.iteration = 1;
  summary.iterations = {r0, r1};
  const json report = reportToJson(summary, {{"warp_angle_max_deg", 0.01}},
                                   sceneToJson(sceneFromJson(validScene())), 12.5);
  const auto errors = schemaRegistry().validate(report, "report.schema.json");
  ASSERT_TRUE(errors.empty()) << errors[0].toString();
  EXPECT_EQ(report["iterations"], 1);
  EXPECT_DOUBLE_EQ(report["history"][1]["residuals"]["fairness"].get<double>(), 0.75);
  EXPECT_FALSE(report["history"][1].contains("alternating_step_scale")) << "only a solve that alternates has one";

  // A solve that alternated (solver.development_solve) records its second step's α.
  summary.alternating = true;
  summary.iterations[1].alternatingStepScale = 0.5;
  const json alternated = reportToJson(summary, {}, sceneToJson(sceneFromJson(validScene())), 1.0);
  const auto alternatedErrors = schemaRegistry().validate(alternated, "report.schema.json");
  ASSERT_TRUE(alternatedErrors.empty()) << alternatedErrors[0].toString();
  EXPECT_DOUBLE_EQ(alternated["history"][1]["alternating_step_scale"].get<double>(), 0.5);
  summary.iterations[1].alternatingStepScale = 1.5;  // the schema bounds it to [0, 1]
  EXPECT_FALSE(schemaRegistry().validate(reportToJson(summary, {}, sceneToJson(sceneFromJson(validScene())), 1.0),
                                         "report.schema.json")
                   .empty());
}

}  // namespace
}  // namespace devsurf::proto

#include <Eigen/Geometry>

#include "devsurf/proto/Geometry.h"

namespace devsurf::proto {
namespace {

TEST(Geometry, Base64RoundTripsAndMatchesTheRfcVectors) {
  EXPECT_EQ(base64Encode("foobar", 6), "Zm9vYmFy");
  EXPECT_EQ(base64Encode("fooba", 5), "Zm9vYmE=");
  EXPECT_EQ(base64Encode("foob", 4), "Zm9vYg==");
  EXPECT_EQ(base64Decode("Zm9vYg=="), "foob");
  EXPECT_THROW(base64Decode("Zm9v!g=="), std::invalid_argument);
  Eigen::MatrixXd m(2, 3);
  m << 1.5, -2, 3, 0.25, 1e-3, 7;
  EXPECT_LT((decodeFloat32Array(float32Array(m)) - m).cwiseAbs().maxCoeff(), 1e-6);
}

TEST(Geometry, UnrollingACylinderKeepsEveryLengthOfItsQuads) {
  // A cylinder over a circle arc is developable: its unrolled rulings are parallel, spaced by
  // arc length, and every quad keeps its edge and diagonal lengths.
  const int n = 20;
  Eigen::MatrixX3d a(n, 3), b(n, 3);
  for (int i = 0; i < n; ++i) {
    const double t = 1.5 * i / (n - 1);
    a.row(i) << std::cos(t), std::sin(t), 0.0;
    b.row(i) << std::cos(t), std::sin(t), 2.0;
  }
  const Eigen::MatrixXd flat = unrollRulingGrid(a, b);
  for (int i = 0; i + 1 < n; ++i) {
    EXPECT_NEAR((flat.row(2 * i + 2) - flat.row(2 * i)).norm(), (a.row(i + 1) - a.row(i)).norm(), 1e-12);
    EXPECT_NEAR((flat.row(2 * i + 3) - flat.row(2 * i)).norm(), (b.row(i + 1) - a.row(i)).norm(), 1e-12);
    EXPECT_NEAR((flat.row(2 * i + 1) - flat.row(2 * i)).norm(), 2.0, 1e-12);
  }
  // Total width = arc length 1.5 (chords sum to slightly less).
  EXPECT_NEAR((flat.row(2 * (n - 1)) - flat.row(0)).norm(), 2 * (n - 1) * std::sin(0.75 / (n - 1)), 1e-12);
}

}  // namespace
}  // namespace devsurf::proto
