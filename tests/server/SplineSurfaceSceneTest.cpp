// A quad_mesh scene with a control net (004_… Algorithm 2, issue 14): solved as `devsurf solve`
// solves it, its solved scene carries the control net and solves again to the same quality, and
// malformed nets are refused naming the field.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "devsurf/proto/Scene.h"
#include "devsurf/server/SceneSolver.h"
#include "devsurf/spline/CubicSubdivision.h"

namespace devsurf::server {
namespace {

using nlohmann::json;

/// The 7 × 7 net of z = 0.4x² + 0.12y² + 0.05xy over [−1, 1]², k = 2, the corners of S^k(M) held.
json splineScene() {
  json points = json::array();
  for (int r = 0; r < 7; ++r)
    for (int c = 0; c < 7; ++c) {
      const double x = -1.0 + c / 3.0, y = -1.0 + r / 3.0;
      points.push_back({x, y, 0.4 * x * x + 0.12 * y * y + 0.05 * x * y});
    }
  const int R = 19;
  json handles = json::array();
  for (auto [v, j] : {std::pair{0, 0}, {R - 1, 6}, {R * (R - 1), 42}, {R * R - 1, 48}})
    handles.push_back({{"vertex", v}, {"position", points[static_cast<std::size_t>(j)]}});
  return {{"format", "devsurf-scene"},
          {"version", 1},
          {"name", "spline dome"},
          {"model",
           {{"kind", "quad_mesh"},
            {"control", {{"rows", 7}, {"columns", 7}, {"rounds", 2}, {"points", points}}},
            {"variable", "both"},
            {"handles", handles},
            {"schedule", {{"round_iterations", 20}, {"rounds", 10}}}}},
          {"solver", {{"iterations", 200}}}};
}

TEST(SplineSurfaceScene, SolvesAndItsSolvedSceneSolvesAgainToTheSameQuality) {
  SceneSolver first(proto::sceneFromJson(splineScene()));
  first.solve();
  const double l1 = first.metrics().at("length_error");
  EXPECT_LE(l1, 1.2e-3);  // Fig. 22 row 13: 0.12 %
  const json solved = proto::sceneToJson(first.currentScene());
  ASSERT_TRUE(solved["model"].contains("control"));
  EXPECT_EQ(solved["model"]["mesh"]["vertices"].size(), 19u * 19u);
  EXPECT_EQ(solved["model"]["mesh"]["faces"].size(), 18u * 18u);
  // The mesh written is S^k of the control points written.
  Eigen::MatrixXd control(49, 3), mesh(361, 3);
  for (int j = 0; j < 49; ++j)
    for (int k = 0; k < 3; ++k) control(j, k) = solved["model"]["control"]["points"][j][k].get<double>();
  for (int i = 0; i < 361; ++i)
    for (int k = 0; k < 3; ++k) mesh(i, k) = solved["model"]["mesh"]["vertices"][i][k].get<double>();
  EXPECT_LT((spline::cubicGridSubdivisionMatrix(7, 7, 2) * control - mesh).cwiseAbs().maxCoeff(), 1e-12);

  SceneSolver again(proto::sceneFromJson(solved));
  again.solve();
  EXPECT_LE(again.metrics().at("length_error"), std::max(2.0 * l1, 2e-4)) << "solving a solved spline surface again";
}

TEST(SplineSurfaceScene, MalformedControlNetsAreRefusedNamingTheField) {
  auto refusal = [](const json& scene) -> std::string {
    try {
      proto::sceneFromJson(scene);
    } catch (const proto::SceneError& e) {
      return e.path();
    }
    return "accepted";
  };
  json s = splineScene();
  s["model"]["control"]["rows"] = 3;
  EXPECT_EQ(refusal(s), "model.control.rows");
  s = splineScene();
  s["model"]["control"]["points"].erase(48);
  EXPECT_EQ(refusal(s), "model.control");
  s = splineScene();
  s["model"]["control"]["points"][5][2] = "high";
  EXPECT_EQ(refusal(s), "model.control.points[5]");  // "expected 3 numbers", as every point3
  s = splineScene();
  s["model"]["control"]["rounds"] = 9;
  EXPECT_EQ(refusal(s), "model.control.rounds");
  s = splineScene();
  s["model"]["handles"][0]["vertex"] = 361;  // the refined mesh has 361 vertices
  EXPECT_EQ(refusal(s), "model.handles[0].vertex");
}

}  // namespace
}  // namespace devsurf::server
