// Issue 12 "bounded resources": every input that scales work is limited, and the estimated memory
// of a design is held to a budget before anything is built. Every refusal names its field.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "devsurf/proto/ResourceLimits.h"
#include "devsurf/proto/Scene.h"

namespace devsurf::proto {
namespace {

using nlohmann::json;

json limitsExample(const std::string& name) {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + name);
  return json::parse(file);
}

/// The refusal of a document as "path [rule]: message", or "<accepted>".
struct Refusal {
  std::string path, rule, message;
};
Refusal refusal(const json& doc, const ResourceLimits& limits = {}) {
  try {
    sceneFromJson(doc, limits);
  } catch (const SceneError& e) {
    return {e.path(), e.rule(), e.what()};
  }
  return {"<accepted>", "", ""};
}

TEST(ResourceLimits, EveryExampleIsWellWithinTheDefaultBudget) {
  for (const auto& entry : std::filesystem::directory_iterator(std::string(DEVSURF_SOURCE_DIR) + "/examples")) {
    const Scene scene = sceneFromJson(limitsExample(entry.path().filename().string()));
    const ResourceEstimate e = estimateResources(scene);
    EXPECT_LT(e.bytes, ResourceLimits{}.memoryBudgetBytes / 4) << entry.path().filename() << ": " << formatBytes(e.bytes);
    EXPECT_FALSE(e.parts.empty());
  }
}

TEST(ResourceLimits, TheRunawayQuasiStripMappingIsRefusedByItsEstimateNamingTheCoefficients) {
  // The outside tester's edit: degree 9, 10 000 coefficients grew the daemon to 17.6 GB.
  json doc = limitsExample("quasi-strip-twisted.json");
  doc["model"]["mapping"] = {{"degree", 9}, {"coefficients", 10000}};
  const Refusal r = refusal(doc);
  EXPECT_EQ(r.path, "model.mapping.coefficients");
  EXPECT_EQ(r.rule, "limit");
  EXPECT_NE(r.message.find("over the budget of 512 MiB"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("dense 10000 × 10000"), std::string::npos) << r.message;
  // The estimate says tens of gigabytes (the dense mapping block and its 100 sample blocks).
  ResourceLimits unlimited;
  unlimited.memoryBudgetBytes = 1e15;
  unlimited.maxWorkPerIteration = 1e30;
  EXPECT_GT(estimateResources(sceneFromJson(doc, unlimited)).bytes, 16.0 * (1 << 30));
}

TEST(ResourceLimits, QuasiStripSamplesAreRefusedByTheirEstimateNamingSamples) {
  json doc = limitsExample("quasi-strip-twisted.json");
  doc["model"]["samples"] = 100000;
  Refusal r = refusal(doc);
  EXPECT_EQ(r.path, "model.samples");
  EXPECT_EQ(r.rule, "limit");
  // The discrete method has one unknown per sample: a dense samples × samples block.
  doc["model"]["samples"] = 3000;
  doc["model"]["method"] = "discrete";
  r = refusal(doc);
  EXPECT_EQ(r.path, "model.samples");
  EXPECT_EQ(r.rule, "limit");
  doc["model"]["samples"] = 200;
  EXPECT_EQ(refusal(doc).path, "<accepted>");
}

TEST(ResourceLimits, TheQuasiStripEstimateGrowsWithTheSquareOfTheCoefficients) {
  json doc = limitsExample("quasi-strip-twisted.json");
  ResourceLimits unlimited;
  unlimited.memoryBudgetBytes = 1e15;
  unlimited.maxWorkPerIteration = 1e30;
  auto bytes = [&doc, &unlimited](int coefficients) {
    doc["model"]["mapping"] = {{"degree", 2}, {"coefficients", coefficients}};
    return estimateResources(sceneFromJson(doc, unlimited)).bytes;
  };
  const double ratio = (bytes(4000) - bytes(50)) / (bytes(2000) - bytes(50));
  EXPECT_GT(ratio, 3.5);
  EXPECT_LT(ratio, 4.5);
}

TEST(ResourceLimits, AHigherDegreeStripIsRefusedNamingItsCurveAndARaisedBudgetAcceptsIt) {
  // 2 × 1000 control points of degree 9: the guards' rows of 63 entries need about 2.4 GB.
  json doc = limitsExample("strip-twisted.json");
  json a = json::array(), b = json::array();
  for (int i = 0; i < 1000; ++i) {
    a.push_back({0.01 * i, 0.0, 0.0});
    b.push_back({0.01 * i, 1.0, 0.1});
  }
  doc["model"]["a"] = {{"degree", 9}, {"points", a}};
  doc["model"]["b"] = {{"degree", 9}, {"points", b}};
  doc["model"].erase("fixed");
  doc["model"].erase("handles");
  const Refusal r = refusal(doc);
  EXPECT_EQ(r.path, "model.a.points");
  EXPECT_EQ(r.rule, "limit");
  ResourceLimits large;
  large.memoryBudgetBytes = 4.0 * (1 << 30);
  EXPECT_EQ(refusal(doc, large).path, "<accepted>");
}

TEST(ResourceLimits, ACompositeDevelopmentIsRefusedNamingItsSamples) {
  json doc = limitsExample("composite-cylinder-crease.json");
  // 64 samples per span over long S edges: the development mesh dominates.
  for (json& e : doc["model"]["edges"])
    if (e["type"] == "S") {
      const json first = e["points"].front();
      json points = json::array();
      for (int i = 0; i < 600; ++i) points.push_back(first);
      e["points"] = points;
    }
  doc["model"]["development"] = {{"samples", 64}};
  const Refusal r = refusal(doc);
  EXPECT_EQ(r.path, "model.development.samples");
  EXPECT_EQ(r.rule, "limit");
}

TEST(ResourceLimits, ControlPointsPerSceneAndIterationsAreLimitedByField) {
  ResourceLimits limits;
  limits.maxControlPoints = 10;
  json doc = limitsExample("strip-twisted.json");  // 7 + 7 control points
  Refusal r = refusal(doc, limits);
  EXPECT_EQ(r.path, "model.a.points");
  EXPECT_EQ(r.rule, "limit");
  EXPECT_NE(r.message.find("14 control points"), std::string::npos) << r.message;

  limits = {};
  limits.maxIterations = 500;
  doc["solver"]["iterations"] = 501;
  r = refusal(doc, limits);
  EXPECT_EQ(r.path, "solver.iterations");
  EXPECT_EQ(r.rule, "limit");
  json quasi = limitsExample("quasi-strip-twisted.json");
  quasi["model"]["max_iterations"] = 600;
  r = refusal(quasi, limits);
  EXPECT_EQ(r.path, "model.max_iterations");
  EXPECT_EQ(r.rule, "limit");
}

TEST(ResourceLimits, FixedMaximaAreTheSchemasNamingTheField) {
  json conical = limitsExample("conical-strip-hull.json");
  conical["model"]["np"] = 100000;  // took over 30 s before
  EXPECT_EQ(refusal(conical).path, "model.np");
  conical["model"]["np"] = 55;
  conical["model"]["nq"] = 10001;
  EXPECT_EQ(refusal(conical).path, "model.nq");
  json strip = limitsExample("strip-twisted.json");
  strip["model"]["normals"] = {{"type", "spline"}, {"points", 2147483647}};
  EXPECT_EQ(refusal(strip).path, "model.normals.points");
  json quasi = limitsExample("quasi-strip-twisted.json");
  quasi["model"]["mapping"] = {{"degree", 2}, {"coefficients", 10001}};
  EXPECT_EQ(refusal(quasi).path, "model.mapping.coefficients");
}

TEST(ResourceLimits, ADevelopmentDomainWhoseProjectionsWouldStallAnIterationIsRefusedNamingTheBoundary) {
  // Each iteration projects every boundary sample onto its domain curve: samples × domain points,
  // in one step no deadline can interrupt.
  json doc = limitsExample("composite-folded-annulus.json");
  // 40 S edges of 29 spans at 8 samples per span: ~9 300 samples, within the memory budget.
  for (json& e : doc["model"]["edges"])
    if (e["type"] == "S") {
      const json first = e["points"].front();
      e["points"] = json::array();
      for (int i = 0; i < 30; ++i) e["points"].push_back(first);
    }
  doc["model"]["development"]["samples"] = 8;
  json& boundary = doc["model"]["development"]["domain"]["boundary"];
  for (json& curve : boundary) {
    json points = json::array();
    for (int i = 0; i < 100000; ++i) {
      const double t = 6.283185307179586 * i / 100000.0;
      points.push_back({std::cos(t), std::sin(t)});
    }
    curve["points"] = points;
  }
  const Refusal r = refusal(doc);
  EXPECT_EQ(r.path, "model.development.domain.boundary");
  EXPECT_EQ(r.rule, "limit");
  EXPECT_NE(r.message.find("one iteration would take about"), std::string::npos) << r.message;
}

}  // namespace
}  // namespace devsurf::proto
