// Issue 12: documents an outside fuzzer sent that crashed the daemon or the CLI, and their
// neighbours. Every one must be answered with a SceneError (or JsonTooDeep) naming the field.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "devsurf/proto/BoundedJson.h"
#include "devsurf/proto/Scene.h"
#include "support/Presets.h"

namespace devsurf::proto {
namespace {

using nlohmann::json;

json example(const std::string& name) {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + name);
  return json::parse(file);
}

/// The path (or, with `message`, the whole message) of the SceneError a document raises;
/// "<accepted>" when none.
std::string pathOfError(const json& doc, bool message = false) {
  try {
    sceneFromJson(doc);
  } catch (const SceneError& e) {
    return message ? std::string(e.what()) : e.path();
  }
  return "<accepted>";
}

std::string messageOfError(const json& doc) { return pathOfError(doc, true); }

TEST(BoundedJson, MeasuresNestingOutsideStringsOnly) {
  EXPECT_EQ(jsonNestingDepth("{}"), 1);
  EXPECT_EQ(jsonNestingDepth(R"({"a":[[1],[2,[3]]]})"), 4);
  EXPECT_EQ(jsonNestingDepth(R"({"a":"[[[[[[[[\"[[["})"), 1);
  EXPECT_EQ(jsonNestingDepth("42"), 0);
}

TEST(BoundedJson, RefusesADeepDocumentBeforeParsingIt) {
  // The frame that killed the daemon: an op nested 80 000 deep.
  const std::string deep = R"({"type":"ping","op":)" + std::string(80000, '[') + std::string(80000, ']') + "}";
  EXPECT_THROW(parseBoundedJson(deep), JsonTooDeep);
  const std::string ok = std::string(kMaxJsonDepth, '[') + std::string(kMaxJsonDepth, ']');
  EXPECT_EQ(parseBoundedJson(ok).size(), 1u);
  EXPECT_THROW(parseBoundedJson("[" + ok + "]"), JsonTooDeep);
  EXPECT_THROW(parseBoundedJson("{\"a\": [1,"), JsonSyntaxError);
  // Syntax errors say where and why, never repeating the input (nlohmann quotes what it read).
  try {
    parseBoundedJson("{\"a\": \"" + std::string(100000, 'x') + "\\q\"}");
    ADD_FAILURE() << "accepted";
  } catch (const JsonSyntaxError& e) {
    EXPECT_LT(std::string(e.what()).size(), 300u) << e.what();
    EXPECT_EQ(std::string(e.what()).find("xxxx"), std::string::npos);
  }
  try {
    parseBoundedJson("{\"a\": \"\xff\xfe\"}");
    ADD_FAILURE() << "accepted invalid UTF-8";
  } catch (const JsonSyntaxError& e) {
    for (const char ch : std::string(e.what())) EXPECT_TRUE(ch >= 0x20 && ch < 0x7f) << e.what();
  }
}

TEST(BoundedJson, EchoesOnlyShortIdentifiers) {
  EXPECT_EQ(echoableId(7), json(7));
  EXPECT_EQ(echoableId("op-1"), json("op-1"));
  EXPECT_TRUE(echoableId(std::string(65, 'x')).is_null());
  EXPECT_TRUE(echoableId(json::array({1, 2})).is_null());
  EXPECT_TRUE(echoableId(json::object()).is_null());
  EXPECT_TRUE(echoableId(1.5).is_null());
}

TEST(HostileScene, ADeepSceneIsRefusedWithAPath) {
  const std::string deep = R"({"format":"devsurf-scene","version":1,"model":)" + std::string(100000, '[') +
                           std::string(100000, ']') + "}";
  try {
    sceneFromText(deep);
    FAIL() << "accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.rule(), "depth");
  }
}

TEST(HostileScene, AnEdgeNamingAVertexThatDoesNotExistIsRefused) {
  json doc = example("composite-curved-fold.json");
  const int nv = static_cast<int>(doc["model"]["vertices"].size());
  for (const json v : {json(231), json(nv), json(2147483648LL), json(-1), json(9223372036854775807LL)}) {
    json bad = doc;
    bad["model"]["edges"][0]["v"][1] = v;
    EXPECT_EQ(pathOfError(bad).rfind("model.edges[0].v", 0), 0u) << v << ": " << pathOfError(bad);
  }
}

TEST(HostileScene, FacesFixedHandlesAndSeamsMustNameExistingElements) {
  const json doc = example("composite-curved-fold.json");
  const int ne = static_cast<int>(doc["model"]["edges"].size());
  json bad = doc;
  bad["model"]["faces"][0][1] = ne;
  EXPECT_EQ(pathOfError(bad), "model.faces[0][1]");
  bad = doc;
  bad["model"]["fixed"] = json::array({{{"vertex", 1000}}});
  EXPECT_EQ(pathOfError(bad), "model.fixed[0].vertex");
  bad = doc;
  bad["model"]["fixed"] = json::array({{{"edge", ne + 3}, {"index", 1}}});
  EXPECT_EQ(pathOfError(bad), "model.fixed[0].edge");
  bad = doc;
  int spline = -1;
  for (std::size_t e = 0; e < doc["model"]["edges"].size(); ++e)
    if (doc["model"]["edges"][e]["type"] == "S") spline = static_cast<int>(e);
  ASSERT_GE(spline, 0);
  bad["model"]["handles"] = json::array({{{"edge", spline}, {"index", 500}, {"position", {0, 0, 0}}}});
  EXPECT_EQ(pathOfError(bad), "model.handles[0].index");
  bad = doc;
  bad["model"]["tangent_continuity"] = json::array({{0, ne + 1}});
  EXPECT_EQ(pathOfError(bad), "model.tangent_continuity[0][1]");
}

TEST(HostileScene, AVertexOrEdgeIndexPastAnIntIsNamedWithTheCountItExceedsEveryTime) {
  // A tryout's vertex 2^31 was read as a negative int, the point taken for an edge point without
  // an edge, and its message quoted whatever memory the missing "edge" read (a different edge
  // number on each of three tries).
  const json doc = example("composite-curved-fold.json");
  const std::string nv = std::to_string(doc["model"]["vertices"].size()), ne = std::to_string(doc["model"]["edges"].size());
  for (const json index : {json(2147483648LL), json(3000000000LL), json(4294967295LL), json(4294967296LL), json(2147483647)}) {
    SCOPED_TRACE(index.dump());
    for (const char* list : {"fixed", "handles"}) {
      json bad = doc;
      json point = {{"vertex", index}};
      if (std::string(list) == "handles") point["position"] = {0, 0, 0};
      bad["model"][list] = json::array({point});
      const std::string first = messageOfError(bad);
      EXPECT_EQ(pathOfError(bad), std::string("model.") + list + "[0].vertex");
      EXPECT_NE(first.find("vertex " + index.dump() + " does not exist (" + nv + " vertices)"), std::string::npos) << first;
      for (int again = 0; again < 3; ++again) EXPECT_EQ(messageOfError(bad), first);
      json edgePoint = {{"edge", index}, {"index", 1}};
      if (std::string(list) == "handles") edgePoint["position"] = {0, 0, 0};
      bad["model"][list][0] = edgePoint;
      EXPECT_EQ(pathOfError(bad), std::string("model.") + list + "[0].edge");
      EXPECT_NE(messageOfError(bad).find("(" + ne + " edges)"), std::string::npos) << messageOfError(bad);
    }
  }
}

TEST(HostileScene, StripIndicesMustNameExistingControlPoints) {
  json bad = example("strip-twisted.json");
  bad["model"]["fixed"] = json::array({{{"curve", "a"}, {"index", 99}}});
  EXPECT_EQ(pathOfError(bad), "model.fixed[0].index");
  bad = example("strip-twisted.json");
  bad["model"]["handles"] = json::array({{{"curve", "b"}, {"index", 2147483648LL}, {"position", {0, 0, 0}}}});
  EXPECT_EQ(pathOfError(bad), "model.handles[0].index");
  // Not "(2147483647 control points)": the curve's count is checked by the model, later.
  EXPECT_EQ(messageOfError(bad).find("2147483647 control points"), std::string::npos) << messageOfError(bad);
}

TEST(HostileScene, AHugeCoordinateIsRefusedByName) {
  // The scene that was accepted and then lost: 1e200 turned every coordinate of b into NaN.
  json bad = example("strip-twisted.json");
  bad["model"]["b"]["points"][3][2] = 1e200;
  EXPECT_EQ(pathOfError(bad), "model.b.points[3][2]");
  bad = example("composite-curved-fold.json");
  bad["model"]["vertices"][2][0] = -3e9;
  EXPECT_EQ(pathOfError(bad), "model.vertices[2][0]");
  bad = example("composite-curved-fold.json");
  bad["model"]["vertices"][2][0] = 12345678901234LL;
  EXPECT_EQ(pathOfError(bad), "model.vertices[2][0]");
}

TEST(HostileScene, AHandleFarFromTheModelIsRefusedByNameAsASessionRefusesTheDrag) {
  json bad = example("strip-twisted.json");
  bad["model"]["handles"] = json::array({{{"curve", "b"}, {"index", 1}, {"position", {1e8, 0, 0}}}});
  EXPECT_EQ(pathOfError(bad), "model.handles[0].position");
  json near = bad;
  near["model"]["handles"][0]["position"] = {5, 5, 5};  // far, within 100× the model's size
  EXPECT_EQ(pathOfError(near), "<accepted>");
  bad = example("composite-curved-fold.json");
  ASSERT_FALSE(bad["model"]["handles"].empty());
  bad["model"]["handles"][0]["position"] = {0, -1e8, 0};
  EXPECT_EQ(pathOfError(bad), "model.handles[0].position");
}

TEST(HostileScene, CurvesWithoutLengthOrStripsWithoutWidthAreRefusedByName) {
  json bad = example("quasi-strip-twisted.json");
  bad["model"]["c2"] = bad["model"]["c1"];
  EXPECT_EQ(pathOfError(bad).rfind("model.c2", 0), 0u) << pathOfError(bad);
  bad = example("quasi-strip-twisted.json");
  for (json& p : bad["model"]["c1"]["points"]) p = {1, 2, 3};
  EXPECT_EQ(pathOfError(bad).rfind("model.c1", 0), 0u) << pathOfError(bad);
  // Both curves on one line, c2 beside c1: no width either.
  bad = example("quasi-strip-twisted.json");
  for (const char* curve : {"c1", "c2"}) {
    json& points = bad["model"][curve]["points"];
    for (std::size_t i = 0; i < points.size(); ++i)
      points[i] = {(curve[1] == '1' ? 0.0 : 2.0) + static_cast<double>(i) / static_cast<double>(points.size() - 1), 0, 0};
  }
  EXPECT_EQ(pathOfError(bad).rfind("model.c2", 0), 0u) << pathOfError(bad);
  bad = example("composite-curved-fold.json");
  std::size_t e = 0;
  while (bad["model"]["edges"][e].value("type", "") != "S") ++e;
  // The curve's ends are its vertices: both put where its control points all are.
  const json& v = bad["model"]["edges"][e]["v"];
  const json first = bad["model"]["vertices"][v[0].get<std::size_t>()];
  bad["model"]["vertices"][v[1].get<std::size_t>()] = first;
  for (json& p : bad["model"]["edges"][e]["points"]) p = first;
  EXPECT_EQ(pathOfError(bad).rfind("model.edges[" + std::to_string(e) + "]", 0), 0u) << pathOfError(bad);
}

TEST(HostileScene, AConicalStripBetweenACurveAndItselfAPointOrOneLineIsRefusedByName) {
  // A tryout's q equal to p solved to a strip folded back on itself (a warning, exit 0), where the
  // quasi strip refused the same pair.
  const json good = example("conical-strip-hull.json");
  ASSERT_EQ(pathOfError(good), "<accepted>");
  json bad = good;
  bad["model"]["q"] = bad["model"]["p"];
  EXPECT_EQ(pathOfError(bad), "model.q.points") << messageOfError(bad);
  EXPECT_NE(messageOfError(bad).find("q lies on p"), std::string::npos) << messageOfError(bad);
  bad = good;
  for (json& p : bad["model"]["p"]["points"]) p = {1, 2, 3};
  EXPECT_EQ(pathOfError(bad).rfind("model.p", 0), 0u) << messageOfError(bad);
  bad = good;
  for (const char* curve : {"p", "q"}) {
    json& points = bad["model"][curve]["points"];
    for (std::size_t i = 0; i < points.size(); ++i)
      points[i] = {(curve[0] == 'p' ? 0.0 : 2.0) + static_cast<double>(i) / static_cast<double>(points.size() - 1), 0, 0};
  }
  EXPECT_EQ(pathOfError(bad), "model.q.points") << messageOfError(bad);
  // q running along p backwards is still on it.
  bad = good;
  json reversed = json::array();
  for (auto it = good["model"]["p"]["points"].rbegin(); it != good["model"]["p"]["points"].rend(); ++it) reversed.push_back(*it);
  bad["model"]["q"]["points"] = reversed;
  bad["model"]["q"].erase("knots");
  bad["model"]["q"]["degree"] = good["model"]["p"].value("degree", 3);
  EXPECT_EQ(pathOfError(bad), "model.q.points") << messageOfError(bad);
}

TEST(HostileScene, WeightsAndSettingsPastABillionAreRefusedByNameBeforeTheyOverflowASolve) {
  // A tryout's handle weight of 1e300 passed validation; its solve then failed with "the solve
  // produced a non-finite value (history[0].residuals.handle)", a name the scene does not have.
  json bad = example("strip-lifted-corner.json");
  ASSERT_FALSE(bad["model"]["handles"].empty());
  bad["model"]["handles"][0]["weight"] = 1e300;
  EXPECT_EQ(pathOfError(bad), "model.handles[0].weight");
  EXPECT_NE(messageOfError(bad).find("outside ±1e9"), std::string::npos) << messageOfError(bad);
  bad["model"]["handles"][0]["weight"] = 1e6;  // heavy, but a weight
  EXPECT_EQ(pathOfError(bad), "<accepted>");
  for (const char* setting : {"fairness", "developability_weight", "handle_weight", "regularization", "time_budget_ms"}) {
    SCOPED_TRACE(setting);
    json doc = example("strip-lifted-corner.json");
    doc["solver"][setting] = 1e300;
    EXPECT_EQ(pathOfError(doc), std::string("solver.") + setting);
    doc["solver"][setting] = 2e9;
    EXPECT_EQ(pathOfError(doc), std::string("solver.") + setting);
  }
  json conical = example("conical-strip-hull.json");
  conical["model"]["h3"] = 1e100;
  EXPECT_EQ(pathOfError(conical), "model.h3");
  // Every shipped example stays inside the bound.
  for (const std::string& name : testing::presetFiles()) EXPECT_EQ(pathOfError(example(name)), "<accepted>") << name;
}

}  // namespace
}  // namespace devsurf::proto
