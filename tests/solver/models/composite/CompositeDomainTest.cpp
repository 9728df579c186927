// Developments with a prescribed domain (000_… §5 "Isometric mapping": corners pinned, boundary
// samples kept on the domain's boundary by tangent-distance rows renewed every iteration).

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/proto/Scene.h"

namespace devsurf::models::composite {
namespace {

using nlohmann::json;

json readExample(const std::string& name) {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + name);
  std::stringstream text;
  text << file.rdbuf();
  return json::parse(text.str());
}

/// Distance of p from the boundary of the axis-aligned rectangle [x0, x1] × [y0, y1].
double rectangleDistance(const Eigen::Vector2d& p, double x0, double x1, double y0, double y1) {
  return std::min({std::abs(p.x() - x0), std::abs(p.x() - x1), std::abs(p.y() - y0), std::abs(p.y() - y1)});
}

/// A 2 × 1 sheet (one strip: S edges along y = 0 and y = 1, rulings at x = 0 and x = 2) whose
/// left side is held while a weak handle lifts its right side: it bends like a cylinder. Its
/// development is confined to the 2 × 1 rectangle with all four corners pinned (Fig. 13 without
/// the crease).
json rectangleDomainScene(double dx = 0.0, double dy = 0.0) {
  auto p = [dx, dy](double x, double y) { return json::array({x + dx, y + dy, 0.0}); };
  auto q = [dx, dy](double x, double y) { return json::array({x + dx, y + dy}); };
  json model = {
      {"kind", "composite"},
      {"vertices", {p(0, 0), p(2, 0), p(2, 1), p(0, 1)}},
      {"edges",
       {{{"v", {0, 1}}, {"type", "S"}, {"degree", 3}, {"points", {p(0.5, 0), p(1, 0), p(1.5, 0)}}},
        {{"v", {1, 2}}, {"type", "R"}},
        {{"v", {3, 2}}, {"type", "S"}, {"degree", 3}, {"points", {p(0.5, 1), p(1, 1), p(1.5, 1)}}},
        {{"v", {3, 0}}, {"type", "R"}}}},
      {"faces", {{0, 1, 2, 3}}},
      {"fixed", {{{"vertex", 0}}, {{"vertex", 3}}}},
      {"handles",
       {{{"vertex", 1}, {"position", {1.7 + dx, 0.0 + dy, 0.9}}, {"weight", 0.05}},
        {{"vertex", 2}, {"position", {1.7 + dx, 1.0 + dy, 0.9}}, {"weight", 0.05}}}},
      {"development",
       {{"samples", 4},
        {"domain",
         {{"boundary", {{{"points", {q(0, 0), q(2, 0), q(2, 1), q(0, 1)}}, {"closed", true}}}},
          {"corners", {{{"vertex", 0}, {"at", q(0, 0)}}, {{"vertex", 1}, {"at", q(2, 0)}},
                       {{"vertex", 2}, {"at", q(2, 1)}}, {{"vertex", 3}, {"at", q(0, 1)}}}}}}}}};
  return {{"format", "devsurf-scene"}, {"version", 1}, {"model", model}, {"solver", {{"iterations", 40}}}};
}

TEST(CompositeDomain, TheDevelopmentStaysOnThePrescribedRectangleWhileTheSheetBends) {
  const proto::Scene scene = proto::sceneFromJson(rectangleDomainScene());
  CompositeModel model(std::get<CompositeDesign>(scene.model), scene.solver.compositeOptions());
  model.solve(scene.solver.solverOptions());
  const CompositeDesign bent = model.design();
  EXPECT_GT(bent.vertices(1, 2), 0.3) << "the sheet bends up";
  const CompositeQuality q = model.quality();
  EXPECT_LE(q.faceFlatnessMax, 1e-3);
  EXPECT_LE(model.developmentLengthError(), 1e-3);
  const CompositeDevelopment d = model.development();
  EXPECT_EQ(Eigen::RowVector2d(d.vertices2d.row(2)), Eigen::RowVector2d(2, 1));  // pinned exactly
  // Every development vertex is a sample of a boundary edge here: all on the rectangle.
  for (Eigen::Index v = 0; v < d.vertices2d.rows(); ++v)
    EXPECT_LT(rectangleDistance(d.vertices2d.row(v).transpose(), 0, 2, 0, 1), 1e-6) << "vertex " << v;
}

TEST(CompositeDomain, ADomainPlacesTheDevelopmentInItsFrame) {
  // Without corners the design's own x, y place the flat start: a sheet shifted by (5, 1) is
  // developed onto the rectangle shifted the same way, not at the origin.
  json doc = rectangleDomainScene(5.0, 1.0);
  doc["model"]["development"]["domain"].erase("corners");
  const proto::Scene scene = proto::sceneFromJson(doc);
  CompositeModel model(std::get<CompositeDesign>(scene.model), scene.solver.compositeOptions());
  const CompositeDevelopment start = model.development();
  EXPECT_NEAR(start.vertices2d(0, 0), 5.0, 1e-9);
  EXPECT_NEAR(start.vertices2d(0, 1), 1.0, 1e-9);
  EXPECT_NEAR(start.vertices2d(2, 0), 7.0, 1e-9);
  EXPECT_NEAR(start.vertices2d(2, 1), 2.0, 1e-9);
  model.solve(scene.solver.solverOptions());
  const CompositeDevelopment d = model.development();
  for (Eigen::Index v = 0; v < d.vertices2d.rows(); ++v)
    EXPECT_LT(rectangleDistance(d.vertices2d.row(v).transpose(), 5, 7, 1, 2), 1e-6) << "vertex " << v;
  EXPECT_LE(model.developmentLengthError(), 1e-3);
}

TEST(CompositeDomain, ScenesRoundTripTheDomain) {
  const json doc = rectangleDomainScene();
  const proto::Scene scene = proto::sceneFromJson(doc);
  EXPECT_EQ(proto::sceneToJson(scene)["model"]["development"], proto::sceneToJson(proto::sceneFromJson(proto::sceneToJson(scene)))["model"]["development"]);
  const auto& d = std::get<CompositeDesign>(scene.model);
  ASSERT_EQ(d.developmentDomain.corners.size(), 4u);
  EXPECT_TRUE(d.developmentDomain.boundary[0].closed);
}

TEST(CompositeDomain, BadDomainsNameTheField) {
  auto expectError = [](const json& doc, const std::string& fragment) {
    try {
      proto::sceneFromJson(doc);
      ADD_FAILURE() << "expected an error mentioning " << fragment;
    } catch (const proto::SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  {
    json doc = rectangleDomainScene();
    doc["model"]["development"]["domain"]["corners"][1]["vertex"] = 99;
    expectError(doc, "development.domain.corners[1].vertex");
  }
  {
    json doc = rectangleDomainScene();
    doc["model"]["development"]["domain"]["boundary"][0]["points"][2] = {2, 0};
    expectError(doc, "development.domain.boundary[0].points[2]");
  }
  {
    json doc = rectangleDomainScene();
    doc["model"]["development"]["domain"]["boundary"][0]["points"][1] = {2, "x"};
    expectError(doc, "development.domain.boundary[0].points[1]");
  }
}

}  // namespace
}  // namespace devsurf::models::composite
