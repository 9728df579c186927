// The real schema files proto/schemas/*.schema.json: valid documents pass, each kind of
// mistake gives exactly the expected error path.
#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "devsurf/proto/JsonSchemaValidator.h"

using devsurf::proto::SchemaError;
using devsurf::proto::SchemaRegistry;
using nlohmann::json;

namespace {

json loadSchema(const std::string& file) {
  const std::string path = std::string(DEVSURF_SOURCE_DIR) + "/proto/schemas/" + file;
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  return json::parse(in);
}

class SchemaFiles : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    registry_ = new SchemaRegistry;
    registry_->add("scene.schema.json", loadSchema("scene.schema.json"));
    registry_->add("report.schema.json", loadSchema("report.schema.json"));
  }
  static void TearDownTestSuite() {
    delete registry_;
    registry_ = nullptr;
  }

  static json scene() {
    return json::parse(R"({
      "format": "devsurf-scene", "version": 1, "name": "twisted strip", "description": "a test",
      "model": { "kind": "strip",
        "a": { "degree": 3, "points": [[0,0,0], [1,0,0], [2,0,0], [3,0,0]] },
        "b": { "degree": 3, "points": [[0,1,0], [1,1,0], [2,1,0], [3,1,0]],
               "knots": [0,0,0,0,1,1,1,1], "weights": [1,1,1,1], "closed": false },
        "normals": { "type": "vectors" },
        "fixed":   [ { "curve": "a", "index": 0 } ],
        "handles": [ { "curve": "b", "index": 3, "position": [1.0, 2.0, 0.5], "weight": 1.0 } ] },
      "solver": { "iterations": 20, "fairness": 0.01, "fairness_decay": 0.8, "regularization": 0.001 }
    })");
  }

  static json report() {
    json r = json::parse(R"({
      "format": "devsurf-report", "version": 1, "iterations": 2, "converged": true,
      "termination": "residual_tolerance", "time_ms": 12.5,
      "history": [
        { "iteration": 0, "residuals": { "developability": 0.5, "fairness": 0.01 }, "total": 0.51 },
        { "iteration": 1, "residuals": { "developability": 1e-15 }, "total": 1e-15, "step_norm": 0.2,
          "fairness_weight": 0.008,
          "time_ms": { "assembly": 1.0, "factorization": 2.0, "solve": 0.5, "total": 3.5 } } ],
      "metrics": { "warp_angle_max_deg": 0.01, "developability_rms": 1e-8 }
    })");
    r["scene"] = scene();
    return r;
  }

  static std::vector<SchemaError> scene(const json& doc) {
    return registry_->validate(doc, "scene.schema.json");
  }

  static std::string all(const std::vector<SchemaError>& errors) {
    std::string s;
    for (const auto& e : errors) s += e.toString() + " [" + e.rule + "]\n";
    return s;
  }

  /// Expects exactly one error, at `path`, with `rule`; returns its message.
  static std::string expectOne(const std::vector<SchemaError>& errors, const std::string& path,
                               const std::string& rule) {
    EXPECT_EQ(errors.size(), 1u) << all(errors);
    if (errors.empty()) return "";
    EXPECT_EQ(errors[0].path, path) << all(errors);
    EXPECT_EQ(errors[0].rule, rule) << all(errors);
    return errors[0].message;
  }

  static SchemaRegistry* registry_;
};

SchemaRegistry* SchemaFiles::registry_ = nullptr;

}  // namespace

TEST_F(SchemaFiles, IdsAreTheFileNames) {
  EXPECT_EQ(registry_->get("scene.schema.json")["$id"], "scene.schema.json");
  EXPECT_EQ(registry_->get("report.schema.json")["$id"], "report.schema.json");
  EXPECT_EQ(registry_->get("scene.schema.json")["$schema"],
            "https://json-schema.org/draft/2020-12/schema");
}

TEST_F(SchemaFiles, ValidSceneFromTheSpecPasses) {
  const auto errors = scene(scene());
  EXPECT_TRUE(errors.empty()) << all(errors);
}

TEST_F(SchemaFiles, MinimalSceneAndFullSolverPass) {
  json doc = {{"format", "devsurf-scene"},
              {"version", 1},
              {"model",
               {{"kind", "strip"},
                {"a", {{"degree", 1}, {"points", {{0, 0, 0}, {1, 0, 0}}}}},
                {"b", {{"degree", 1}, {"points", {{0, 1, 0}, {1, 1, 0}}}}}}}};
  EXPECT_TRUE(scene(doc).empty()) << all(scene(doc));
  doc["model"]["normals"] = {{"type", "spline"}, {"degree", 3}, {"points", 5}};
  doc["solver"] = json::object();
  for (const auto& [name, property] :
       registry_->get("scene.schema.json")["$defs"]["solver"]["properties"].items()) {
    ASSERT_TRUE(property.contains("default")) << name;
    ASSERT_TRUE(property.contains("description")) << name;
    doc["solver"][name] = property["default"];
  }
  EXPECT_TRUE(scene(doc).empty()) << all(scene(doc));
}

TEST_F(SchemaFiles, EveryDefaultIsValidForItsOwnSchema) {
  const json& defs = registry_->get("scene.schema.json")["$defs"];
  for (const char* def : {"solver", "normals_spline", "handle", "curve"}) {
    for (const auto& [name, property] : defs[def]["properties"].items()) {
      if (!property.contains("default")) continue;
      const std::string ref =
          std::string("scene.schema.json#/$defs/") + def + "/properties/" + name;
      const auto errors = registry_->validateRef(property["default"], ref);
      EXPECT_TRUE(errors.empty()) << ref << ": " << all(errors);
    }
  }
}

TEST_F(SchemaFiles, SubschemasByRef) {
  EXPECT_TRUE(
      registry_->validateRef(scene()["model"]["a"], "scene.schema.json#/$defs/curve").empty());
  const auto errors = registry_->validateRef(json{{"degree", 0}, {"points", {{0, 0, 0}}}},
                                             "scene.schema.json#/$defs/curve");
  ASSERT_EQ(errors.size(), 2u) << all(errors);
  EXPECT_EQ(errors[0].toString(), "degree: must be ≥ 1, got 0");
  EXPECT_EQ(errors[1].toString(), "points: expected at least 2 items, got 1");
}

TEST_F(SchemaFiles, MissingModelKind) {
  json doc = scene();
  doc["model"].erase("kind");
  EXPECT_EQ(expectOne(scene(doc), "model.kind", "required"), "is required");
}

TEST_F(SchemaFiles, UnknownModelKind) {
  json doc = scene();
  doc["model"]["kind"] = "sphere";
  EXPECT_EQ(expectOne(scene(doc), "model.kind", "enum"),
            "unknown kind \"sphere\" (expected one of: strip, composite, quasi_strip, conical_strip, quad_mesh)");
}

TEST_F(SchemaFiles, PointWithTwoNumbers) {
  json doc = scene();
  doc["model"]["a"]["points"][3] = {3, 0};
  EXPECT_EQ(expectOne(scene(doc), "model.a.points[3]", "minItems"), "expected 3 numbers");
  doc = scene();
  doc["model"]["a"]["points"][3] = {3, 0, "0"};
  EXPECT_EQ(expectOne(scene(doc), "model.a.points[3]", "items"), "expected 3 numbers");
  EXPECT_EQ(scene(doc)[0].toString(), "model.a.points[3]: expected 3 numbers");
}

TEST_F(SchemaFiles, InfiniteNumbers) {
  // json::parse("1e999") throws in nlohmann 3.11, so infinity reaches the validator only from
  // documents built in code or read from binary formats (CBOR, MessagePack).
  const std::string text = scene().dump();
  std::string overflow = text;
  overflow.replace(overflow.find("0.001"), 5, "1e999");
  EXPECT_THROW({ const json j = json::parse(overflow); }, json::out_of_range);

  const double inf = std::numeric_limits<double>::infinity();
  json doc = scene();
  doc["solver"]["regularization"] = inf;
  EXPECT_EQ(expectOne(scene(doc), "solver.regularization", "type"), "expected a finite number");
  doc = json::from_cbor(json::to_cbor(doc));  // survives a binary round trip
  EXPECT_EQ(expectOne(scene(doc), "solver.regularization", "type"), "expected a finite number");

  doc = scene();
  doc["model"]["b"]["points"][1][2] = -inf;
  EXPECT_EQ(expectOne(scene(doc), "model.b.points[1]", "items"), "expected 3 numbers");
  doc = scene();
  doc["model"]["b"]["knots"][4] = inf;
  EXPECT_EQ(expectOne(scene(doc), "model.b.knots[4]", "type"), "expected a finite number");
}

TEST_F(SchemaFiles, NegativeIterations) {
  json doc = scene();
  doc["solver"]["iterations"] = -3;
  EXPECT_EQ(expectOne(scene(doc), "solver.iterations", "minimum"), "must be ≥ 0, got -3");
  doc["solver"]["iterations"] = 2.5;
  EXPECT_EQ(expectOne(scene(doc), "solver.iterations", "type"), "expected an integer, got 2.5");
  doc["solver"]["iterations"] = 10001;
  EXPECT_EQ(expectOne(scene(doc), "solver.iterations", "maximum"), "must be ≤ 10000, got 10001");
}

TEST_F(SchemaFiles, UnknownFieldInSolver) {
  json doc = scene();
  doc["solver"]["iteratons"] = 5;
  EXPECT_EQ(expectOne(scene(doc), "solver.iteratons", "additionalProperties"), "unknown field");
}

TEST_F(SchemaFiles, UnknownFieldsElsewhere) {
  json doc = scene();
  doc["colour"] = "red";
  expectOne(scene(doc), "colour", "additionalProperties");
  doc = scene();
  doc["model"]["a"]["order"] = 4;
  expectOne(scene(doc), "model.a.order", "additionalProperties");
  doc = scene();
  doc["model"]["handles"][0]["pos"] = {0, 0, 0};
  expectOne(scene(doc), "model.handles[0].pos", "additionalProperties");
}

TEST_F(SchemaFiles, BadNormalsType) {
  json doc = scene();
  doc["model"]["normals"]["type"] = "per_vertex";
  EXPECT_EQ(expectOne(scene(doc), "model.normals.type", "enum"),
            "unknown type \"per_vertex\" (expected one of: vectors, spline)");
  doc["model"]["normals"] = {{"type", "spline"}, {"points", 1}};
  EXPECT_EQ(expectOne(scene(doc), "model.normals.points", "minimum"), "must be ≥ 2, got 1");
  doc["model"]["normals"] = {{"type", "vectors"}, {"degree", 3}};
  expectOne(scene(doc), "model.normals.degree", "additionalProperties");
  doc["model"]["normals"] = json::object();
  expectOne(scene(doc), "model.normals.type", "required");
}

TEST_F(SchemaFiles, HandleWithWeightZero) {
  json doc = scene();
  doc["model"]["handles"][0]["weight"] = 0;
  EXPECT_EQ(expectOne(scene(doc), "model.handles[0].weight", "exclusiveMinimum"),
            "must be > 0, got 0");
}

TEST_F(SchemaFiles, FixedWithUnknownCurve) {
  json doc = scene();
  doc["model"]["fixed"][0]["curve"] = "c";
  EXPECT_EQ(expectOne(scene(doc), "model.fixed[0].curve", "enum"), "must be one of: a, b");
}

TEST_F(SchemaFiles, MoreMistakes) {
  json doc = scene();
  doc["format"] = "devsurf-report";
  expectOne(scene(doc), "format", "const");
  doc = scene();
  doc["version"] = 2;
  expectOne(scene(doc), "version", "const");
  doc = scene();
  doc.erase("model");
  expectOne(scene(doc), "model", "required");
  doc = scene();
  doc["name"] = std::string(201, 'x');
  expectOne(scene(doc), "name", "maxLength");
  doc = scene();
  doc["model"]["a"]["degree"] = 10;
  expectOne(scene(doc), "model.a.degree", "maximum");
  doc = scene();
  doc["model"]["b"]["weights"][2] = 0;
  expectOne(scene(doc), "model.b.weights[2]", "exclusiveMinimum");
  doc = scene();
  doc["model"]["b"]["closed"] = "no";
  expectOne(scene(doc), "model.b.closed", "type");
  doc = scene();
  doc["model"]["fixed"][0].erase("index");
  expectOne(scene(doc), "model.fixed[0].index", "required");
  doc = scene();
  doc["model"]["handles"][0]["position"] = {1, 2};
  EXPECT_EQ(expectOne(scene(doc), "model.handles[0].position", "minItems"), "expected 3 numbers");
  doc = scene();
  doc["solver"]["fairness_decay"] = 0;
  expectOne(scene(doc), "solver.fairness_decay", "exclusiveMinimum");
  doc["solver"]["fairness_decay"] = 1;
  EXPECT_TRUE(scene(doc).empty());
  doc["solver"]["linear_solver"] = "qr";
  EXPECT_EQ(expectOne(scene(doc), "solver.linear_solver", "enum"), "must be one of: auto, ldlt, cholmod");
  doc = scene();
  doc["model"] = "strip";
  EXPECT_EQ(expectOne(scene(doc), "model", "type"), "expected an object, got string");
  EXPECT_EQ(expectOne(scene(json::array()), "", "type"), "expected an object, got array");
}

TEST_F(SchemaFiles, SeveralMistakesAreAllReported) {
  json doc = scene();
  doc["solver"]["iterations"] = -1;
  doc["model"]["a"]["points"][1] = {0};
  doc["model"]["fixed"][0]["curve"] = "c";
  const auto errors = scene(doc);
  ASSERT_EQ(errors.size(), 3u) << all(errors);
  EXPECT_EQ(errors[0].path, "model.a.points[1]");
  EXPECT_EQ(errors[1].path, "model.fixed[0].curve");
  EXPECT_EQ(errors[2].path, "solver.iterations");
}

TEST_F(SchemaFiles, TooManyPointsIsOneError) {
  json doc = scene();
  json points = json::array();
  for (int i = 0; i < 100001; ++i) points.push_back({i, 0, 0});
  doc["model"]["a"]["points"] = points;
  EXPECT_EQ(expectOne(scene(doc), "model.a.points", "maxItems"),
            "expected at most 100000 items, got 100001");
  points.erase(points.size() - 1);
  doc["model"]["a"]["points"] = points;
  EXPECT_TRUE(scene(doc).empty());
}

TEST_F(SchemaFiles, ValidReportPasses) {
  const auto errors = registry_->validate(report(), "report.schema.json");
  EXPECT_TRUE(errors.empty()) << all(errors);
}

TEST_F(SchemaFiles, ReportMistakes) {
  json doc = report();
  doc["scene"]["model"]["a"]["points"][3] = {3, 0};  // via the cross-file $ref
  EXPECT_EQ(expectOne(registry_->validate(doc, "report.schema.json"), "scene.model.a.points[3]",
                      "minItems"),
            "expected 3 numbers");
  doc = report();
  doc["termination"] = "bored";
  expectOne(registry_->validate(doc, "report.schema.json"), "termination", "enum");
  doc = report();
  doc["metrics"]["warp_angle_max_deg"] = "small";
  expectOne(registry_->validate(doc, "report.schema.json"), "metrics.warp_angle_max_deg", "type");
  doc = report();
  doc["history"][1]["time_ms"]["assembly"] = -1;
  expectOne(registry_->validate(doc, "report.schema.json"), "history[1].time_ms.assembly",
            "minimum");
  doc = report();
  doc["history"][0].erase("total");
  expectOne(registry_->validate(doc, "report.schema.json"), "history[0].total", "required");
  doc = report();
  doc.erase("scene");
  expectOne(registry_->validate(doc, "report.schema.json"), "scene", "required");
}

TEST_F(SchemaFiles, ConcurrentValidationAndCopies) {
  const SchemaRegistry copy = *registry_;  // copies share the immutable schemas
  json bad = scene();
  bad["model"]["fixed"][0]["curve"] = "c";
  std::vector<std::thread> threads;
  std::atomic<int> failures{0};
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      const SchemaRegistry& reg = t % 2 == 0 ? *registry_ : copy;
      for (int i = 0; i < 50; ++i) {
        if (!reg.validate(scene(), "scene.schema.json").empty()) ++failures;
        const auto errors = reg.validate(bad, "scene.schema.json");
        if (errors.size() != 1 || errors[0].path != "model.fixed[0].curve") ++failures;
      }
    });
  }
  for (auto& th : threads) th.join();
  EXPECT_EQ(failures.load(), 0);
}
