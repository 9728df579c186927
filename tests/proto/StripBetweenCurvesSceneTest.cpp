// Scene kinds "quasi_strip" (Bo et al.) and "conical_strip" (Chu et al.): defaults, round trips and
// errors that name the JSON path.

#include <gtest/gtest.h>

#include "devsurf/proto/Scene.h"

namespace devsurf::proto {
namespace {

using nlohmann::json;
namespace quasi = models::quasi_strip;
namespace conical = models::conical_strip;

json curve(double y, double z) {
  return {{"degree", 3}, {"points", {{0, y, 0}, {1, y, z}, {2, y, 0}, {3, y, -z}, {4, y, 0}}}};
}

json quasiScene() {
  return {{"format", "devsurf-scene"}, {"version", 1},
          {"model", {{"kind", "quasi_strip"}, {"c1", curve(0.0, 0.2)}, {"c2", curve(1.0, 0.3)}}}};
}

json conicalScene() {
  return {{"format", "devsurf-scene"},
          {"version", 1},
          {"model",
           {{"kind", "conical_strip"},
            {"p", {{"degree", 1}, {"points", {{0, 0, 0}, {2, 0, 0.1}, {4, 0, 0}}}}},
            {"q", curve(1.0, 0.3)}}}};
}

SceneError curveStripErrorOf(const json& doc) {
  try {
    sceneFromJson(doc);
  } catch (const SceneError& e) {
    return e;
  }
  ADD_FAILURE() << "expected a SceneError for " << doc.dump();
  return SceneError("", "", "");
}

TEST(StripBetweenCurvesScene, AQuasiStripTakesTheDocumentedDefaults) {
  const Scene s = sceneFromJson(quasiScene());
  const QuasiStripScene& q = std::get<QuasiStripScene>(s.model);
  EXPECT_EQ(modelKind(s.model), std::string("quasi_strip"));
  EXPECT_EQ(q.design.mapping.degree, 2);
  EXPECT_EQ(q.design.mapping.coefficients, 50);
  EXPECT_EQ(q.design.samples, 100);
  EXPECT_FALSE(q.design.endPoints.enabled);
  EXPECT_EQ(q.options.method, quasi::MappingMethod::BSpline);
  EXPECT_EQ(q.options.optimizer, quasi::Optimizer::Lbfgs);
  EXPECT_EQ(q.options.lambda1, 100.0);
  EXPECT_EQ(q.options.lambda2, 1.0);
  EXPECT_EQ(q.maxIterations, 0);
  EXPECT_EQ(q.design.c1.points.rows(), 5);
}

TEST(StripBetweenCurvesScene, AQuasiStripRoundTripsWithEveryOptionalField) {
  json doc = quasiScene();
  json& m = doc["model"];
  m["mapping"] = {{"degree", 3}, {"coefficients", 12}};
  m["samples"] = 40;
  m["method"] = "discrete";
  m["optimizer"] = "guided_projection";
  m["fix_end_points"] = {{"weight", 250.0}};
  m["extension"] = {{"c1_end", 0.1}, {"automatic", false}};
  m["lambda1"] = 50.0;
  m["max_iterations"] = 77;
  const json written = sceneToJson(sceneFromJson(doc));
  EXPECT_TRUE(schemaRegistry().validate(written, "scene.schema.json").empty());
  EXPECT_EQ(sceneToJson(sceneFromJson(written)), written);
  const QuasiStripScene q = std::get<QuasiStripScene>(sceneFromJson(written).model);
  EXPECT_EQ(q.design.mapping.degree, 3);
  EXPECT_EQ(q.design.samples, 40);
  EXPECT_EQ(q.options.method, quasi::MappingMethod::Discrete);
  EXPECT_EQ(q.options.optimizer, quasi::Optimizer::GuidedProjection);
  EXPECT_TRUE(q.design.endPoints.enabled);
  EXPECT_EQ(q.design.endPoints.weight, 250.0);
  EXPECT_EQ(q.design.extension.c1End, 0.1);
  EXPECT_FALSE(q.design.extension.automatic);
  EXPECT_EQ(q.options.lambda1, 50.0);
  EXPECT_EQ(q.maxIterations, 77);
}

TEST(StripBetweenCurvesScene, AConicalStripTakesTheDocumentedDefaultsAndRoundTrips) {
  const Scene s = sceneFromJson(conicalScene());
  const conical::ConicalStripDesign& d = std::get<conical::ConicalStripDesign>(s.model);
  EXPECT_EQ(d.np, 55);
  EXPECT_EQ(d.nq, 65);
  EXPECT_EQ(d.h3, 4.0);
  EXPECT_EQ(d.h4, 4.0);
  EXPECT_EQ(d.ra, 1.2);
  EXPECT_EQ(d.objective, conical::Objective::NormalVariation);
  EXPECT_TRUE(d.g1);
  EXPECT_EQ(d.p.degree(), 1);  // a polyline
  const json written = sceneToJson(s);
  EXPECT_TRUE(schemaRegistry().validate(written, "scene.schema.json").empty());
  EXPECT_EQ(sceneToJson(sceneFromJson(written)), written);
  json doc = conicalScene();
  doc["model"]["objective"] = "bending_energy";
  doc["model"]["g1"] = false;
  doc["model"]["np"] = 9;
  const Scene roundTripped = sceneFromJson(sceneToJson(sceneFromJson(doc)));
  const auto& again = std::get<conical::ConicalStripDesign>(roundTripped.model);
  EXPECT_EQ(again.objective, conical::Objective::BendingEnergy);
  EXPECT_FALSE(again.g1);
  EXPECT_EQ(again.np, 9);
}

TEST(StripBetweenCurvesScene, SchemaDefaultsMatchTheModelDefaults) {
  const json& defs = schemaRegistry().get("scene.schema.json")["$defs"];
  const json conicalWritten = sceneToJson(sceneFromJson(conicalScene()))["model"];
  for (const auto& [name, property] : defs["conical_strip_model"]["properties"].items())
    if (property.contains("default")) EXPECT_EQ(conicalWritten[name], property["default"]) << name;
  const json quasiWritten = sceneToJson(sceneFromJson(quasiScene()))["model"];
  for (const auto& [name, property] : defs["quasi_strip_model"]["properties"].items())
    if (property.contains("default")) EXPECT_EQ(quasiWritten[name], property["default"]) << name;
  for (const auto& [name, property] : defs["quasi_strip_model"]["properties"]["mapping"]["properties"].items())
    EXPECT_EQ(quasiWritten["mapping"][name], property["default"]) << name;
}

TEST(StripBetweenCurvesScene, ErrorsNameTheJsonPathOfTheField) {
  struct Case {
    json doc;
    std::string path;
  };
  std::vector<Case> cases;
  auto quasiWith = [](const std::string& key, const json& value) {
    json d = quasiScene();
    d["model"][key] = value;
    return d;
  };
  auto conicalWith = [](const std::string& key, const json& value) {
    json d = conicalScene();
    d["model"][key] = value;
    return d;
  };
  cases.push_back({quasiWith("mapping", {{"degree", 4}, {"coefficients", 3}}), "model.mapping.coefficients"});
  cases.push_back({quasiWith("samples", 1), "model.samples"});
  cases.push_back({quasiWith("optimizer", "newton"), "model.optimizer"});
  cases.push_back({quasiWith("fix_end_points", {{"weight", 0}}), "model.fix_end_points.weight"});
  cases.push_back({quasiWith("extension", {{"c1_end", -1}}), "model.extension.c1_end"});
  json rational = quasiScene();
  rational["model"]["c2"]["weights"] = {1, 2, 1, 1, 1};
  cases.push_back({rational, "model.c2.weights"});
  json missing = quasiScene();
  missing["model"].erase("c2");
  cases.push_back({missing, "model.c2"});
  cases.push_back({quasiWith("a", curve(0, 0)), "model.a"});
  cases.push_back({conicalWith("ra", 0.5), "model.ra"});
  cases.push_back({conicalWith("np", 1), "model.np"});
  cases.push_back({conicalWith("h3", -1.0), "model.h3"});
  cases.push_back({conicalWith("objective", "area"), "model.objective"});
  json shortCurve = conicalScene();
  shortCurve["model"]["q"]["points"] = {{0, 0, 0}, {1, 0, 0}};
  cases.push_back({shortCurve, "model.q.points"});
  for (const Case& c : cases) {
    const SceneError e = curveStripErrorOf(c.doc);
    EXPECT_EQ(e.path(), c.path) << e.what();
  }
}

}  // namespace
}  // namespace devsurf::proto
