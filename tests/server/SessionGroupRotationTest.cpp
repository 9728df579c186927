// Rotating a selected group of points (issue 16, item 3; 000_… §4.1 Fig. 8): the group turns about
// an axis, the solve keeps the composite developable, one undo step; bad input names its field.

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "devsurf/server/CreasePatternImport.h"
#include "server/SessionTesting.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
using testing::ExampleEditor;

/// A 200 × 150 mm sheet with one straight crease along y = 100 that folds freely (no fold-angle
/// target: a target would pull the crease to the fold slider's amount); the larger part below is
/// fixed.
proto::Scene sheetWithOneCrease() {
  const std::string svg =
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"200mm\" height=\"150mm\" viewBox=\"0 0 200 150\">"
      "<rect x=\"0\" y=\"0\" width=\"200\" height=\"150\" fill=\"none\" stroke=\"#000\"/>"
      "<line x1=\"0\" y1=\"50\" x2=\"200\" y2=\"50\" stroke=\"#00f\"/></svg>";  // y down in SVG: y = 100 on the sheet
  CreasePatternImportRequest request;
  request.format = "svg";
  nlohmann::json scene = proto::sceneToJson(importCreasePattern(svg, request).scene);
  scene["model"].erase("fold_angles");
  scene["model"].erase("fold_amount");
  return proto::sceneFromJson(scene);
}

Eigen::Vector3d vertexOf(const json& scene, int v) {
  const json& p = scene["model"]["vertices"][static_cast<std::size_t>(v)];
  return {p[0].get<double>(), p[1].get<double>(), p[2].get<double>()};
}

TEST(SessionGroupRotation, TurningTheFlapAboutItsCreaseFoldsItAndTheSolveKeepsIt) {
  ExampleEditor e(sheetWithOneCrease());
  const json flat = e.session->sceneJson();
  std::vector<int> flap;  // the two corners beyond the crease
  for (std::size_t v = 0; v < flat["model"]["vertices"].size(); ++v)
    if (flat["model"]["vertices"][v][1].get<double>() > 149.0) flap.push_back(static_cast<int>(v));
  ASSERT_EQ(flap.size(), 2u);
  json targets = json::array();
  for (int v : flap) targets.push_back({{"vertex", v}});
  e.send({{"type", "rotate_points"}, {"op", 1}, {"targets", targets}, {"axis", {1, 0, 0}}, {"centre", {0, 100, 0}},
          {"angle", 60}, {"iterations", 40}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  ASSERT_FALSE(e.inbox.ofType("solved").empty());
  const json folded = e.session->sceneJson();
  for (int v : flap) {
    const Eigen::Vector3d p = vertexOf(folded, v);
    // 50 mm beyond the crease, turned by 60° about it: y = 100 + 50 cos 60°, z = 50 sin 60°.
    EXPECT_NEAR(p.y(), 125.0, 0.5) << v;
    EXPECT_NEAR(p.z(), 50.0 * std::sin(M_PI / 3.0), 0.5) << v;
  }
  const json metrics = e.inbox.last("solved")["metrics"];
  EXPECT_LT(metrics["development_length_error"].get<double>(), 1e-3);
  // One undo step: flat again.
  e.send({{"type", "undo"}, {"op", 2}});
  EXPECT_EQ(e.session->sceneJson()["model"]["vertices"], flat["model"]["vertices"]);
}

TEST(SessionGroupRotation, AHandleOnATurnedPointTurnsWithIt) {
  ExampleEditor e("composite-two-creases");
  const json before = e.session->sceneJson();
  ASSERT_FALSE(before["model"]["handles"].empty());
  const json handle = before["model"]["handles"][0];
  json target = handle;
  target.erase("position");
  target.erase("weight");
  e.send({{"type", "rotate_points"}, {"op", 1}, {"targets", {target}}, {"axis", {0, 0, 1}}, {"centre", {0, 0, 0}},
          {"angle", 90}, {"iterations", 0}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  const json turned = e.session->sceneJson()["model"]["handles"][0]["position"];
  // (x, y, z) turned by 90° about z through the origin: (−y, x, z).
  EXPECT_NEAR(turned[0].get<double>(), -handle["position"][1].get<double>(), 1e-12);
  EXPECT_NEAR(turned[1].get<double>(), handle["position"][0].get<double>(), 1e-12);
  EXPECT_NEAR(turned[2].get<double>(), handle["position"][2].get<double>(), 1e-12);
}

TEST(SessionGroupRotation, BadAxesTargetsAndKindsAreRefusedNamingTheField) {
  ExampleEditor e(sheetWithOneCrease());
  const json before = e.session->sceneJson();
  struct Case {
    json message;
    std::string path;
  };
  const std::vector<Case> cases = {
      {{{"type", "rotate_points"}, {"op", 1}, {"targets", {{{"vertex", 0}}}}, {"axis", {0, 0, 0}}, {"angle", 10}}, "axis"},
      {{{"type", "rotate_points"}, {"op", 2}, {"targets", json::array()}, {"axis", {0, 0, 1}}, {"angle", 10}}, "targets"},
      {{{"type", "rotate_points"}, {"op", 3}, {"targets", {{{"vertex", 999}}}}, {"axis", {0, 0, 1}}, {"angle", 10}},
       "targets[0].vertex"},
      {{{"type", "rotate_points"}, {"op", 4}, {"targets", {{{"vertex", 0}}}}, {"axis", {0, 0, 1}}, {"angle", 1000}}, "angle"},
      {{{"type", "rotate_points"}, {"op", 5}, {"targets", {{{"vertex", 0}}}}, {"axis", {0, 0, 1}}, {"angle", 10},
        {"centre", {1e30, 0, 0}}}, "centre"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.message.dump());
    e.inbox.messages.clear();
    e.send(c.message);
    const json error = e.inbox.last("error");
    ASSERT_TRUE(error.is_object());
    EXPECT_EQ(error["path"], c.path) << error.dump();
    EXPECT_TRUE(e.session->sceneJson() == before);
  }
  ExampleEditor strip("strip-lifted-corner");
  strip.send({{"type", "rotate_points"}, {"op", 1}, {"targets", {{{"curve", "a"}, {"index", 0}}}}, {"axis", {0, 0, 1}},
              {"angle", 10}});
  EXPECT_EQ(strip.inbox.last("error")["path"], "type");
}

}  // namespace
}  // namespace devsurf::server
