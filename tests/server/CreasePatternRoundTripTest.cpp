// Curved creases read back from FOLD and SVG files (issue 16: the place where a design starts and
// ends). Every composite preset's FOLD and SVG exports were refused on the way back: a FOLD file's
// curved creases are chains of straight edges (the composite read them as 288 straight quads whose
// hinges lay on degenerate faces), and an SVG side drawn through the ends of its creases bends by
// 1.6° there (read as one curve, its faces had no straight ends). Another tool's FOLD file with a
// curved crease sampled into straight edges, facets between, is read the same way.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <pugixml.hpp>

#include "devsurf/server/CreasePatternImport.h"
#include "devsurf/server/SceneSolver.h"
#include "server/SessionTesting.h"
#include "support/Presets.h"

namespace devsurf::server {
namespace {

using nlohmann::json;

/// The composite presets that have a development (those the fold and svg exports apply to).
std::vector<std::string> compositePresetsWithDevelopment() {
  std::vector<std::string> names;
  for (const std::string& file : devsurf::testing::presetFiles()) {
    const json doc = devsurf::testing::readPreset(file);
    if (doc["model"].value("kind", "") == "composite" && doc["model"].contains("development")) names.push_back(file);
  }
  return names;
}

/// Mean fold angle per crease as the file says it, read without devsurf's reader: an SVG's
/// mountain and valley strokes by their data-fold-angle; a FOLD file's M and V edges grouped by
/// edges_devsurf:curve, their edges_foldAngle weighted by length.
std::vector<double> fileCreaseAngles(const std::string& format, const std::string& content) {
  std::vector<double> angles;
  if (format == "svg") {
    pugi::xml_document doc;
    EXPECT_TRUE(doc.load_string(content.c_str()));
    for (const char* group : {"mountain", "valley"})
      for (const pugi::xpath_node& n : doc.select_nodes((std::string("//*[@id='") + group + "']/*").c_str()))
        angles.push_back(n.node().attribute("data-fold-angle").as_double());
    return angles;
  }
  const json fold = json::parse(content);
  // Creases: edges of one curve id; edges on no curve (straight creases) joined where they share a
  // vertex and their letter (union–find over the vertices).
  // vertex components per letter (a mountain and a valley meeting at a vertex stay two creases)
  std::map<std::string, std::vector<int>> parents;
  const auto root = [&parents, &fold](const std::string& letter, int v) {
    std::vector<int>& parent = parents[letter];
    if (parent.empty())
      for (std::size_t k = 0; k < fold["vertices_coords"].size(); ++k) parent.push_back(static_cast<int>(k));
    while (parent[static_cast<std::size_t>(v)] != v) v = parent[static_cast<std::size_t>(v)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(v)])];
    return v;
  };
  std::vector<std::size_t> creaseEdges;
  for (std::size_t e = 0; e < fold["edges_vertices"].size(); ++e) {
    const std::string letter = fold["edges_assignment"][e];
    if (letter != "M" && letter != "V") continue;
    creaseEdges.push_back(e);
    if (fold["edges_devsurf:curve"][e].is_null())
      parents[letter][static_cast<std::size_t>(root(letter, fold["edges_vertices"][e][0].get<int>()))] =
          root(letter, fold["edges_vertices"][e][1].get<int>());
  }
  std::map<std::pair<std::string, int>, std::pair<double, double>> byCrease;  // → (Σ length·angle, Σ length)
  for (std::size_t e : creaseEdges) {
    const json& ends = fold["edges_vertices"][e];
    const json& a = fold["vertices_coords"][ends[0].get<int>()];
    const json& b = fold["vertices_coords"][ends[1].get<int>()];
    const double length = std::hypot(a[0].get<double>() - b[0].get<double>(), a[1].get<double>() - b[1].get<double>());
    const json& curve = fold["edges_devsurf:curve"][e];
    const std::string letter = fold["edges_assignment"][e];
    const auto key = curve.is_null() ? std::make_pair(letter, root(letter, ends[0].get<int>()))
                                     : std::make_pair(std::string("curve"), curve.get<int>());
    auto& sum = byCrease[key];
    sum.first += length * fold["edges_foldAngle"][e].get<double>();
    sum.second += length;
  }
  for (const auto& [crease, sum] : byCrease) angles.push_back(sum.first / sum.second);
  return angles;
}

/// The distinct values of `angles` (degrees), sorted, those within 0.01° of a smaller one dropped.
std::vector<double> distinctAngles(std::vector<double> angles) {
  std::sort(angles.begin(), angles.end());
  std::vector<double> out;
  for (double a : angles)
    if (out.empty() || a - out.back() > 0.01) out.push_back(a);
  return out;
}

/// Fold targets of an imported scene (the targets along one crease repeat its angle).
std::vector<double> importedTargets(const json& scene) {
  std::vector<double> angles;
  for (const json& t : scene["model"]["fold_angles"]) angles.push_back(t["angle"].get<double>());
  return angles;
}

/// A preset solved as a demo session starts it, exported as `format` and imported again.
struct RoundTrip {
  ExportedFile exported;
  CreasePatternImportResult imported;
};

RoundTrip roundTrip(const std::string& preset, const std::string& format) {
  const proto::Scene solved = SceneSolver::solvedScene(proto::sceneFromJson(devsurf::testing::readPreset(preset)));
  RoundTrip r;
  r.exported = SceneSolver::exportScene(proto::sceneToJson(solved), format);
  CreasePatternImportRequest request;
  request.format = format;
  r.imported = importCreasePattern(r.exported.content, request);
  return r;
}

class CreasePatternRoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(CreasePatternRoundTrip, ThePresetsFoldAndSvgExportsImportAgainWithEveryCreaseAndItsAngle) {
  for (const std::string format : {"fold", "svg"}) {
    SCOPED_TRACE(format);
    RoundTrip r;
    ASSERT_NO_THROW(r = roundTrip(GetParam(), format));
    const json scene = proto::sceneToJson(r.imported.scene);
    ASSERT_TRUE(scene["model"].contains("fold_angles"));
    // As many creases as the file draws, each with the file's angle (distinct values compared:
    // creases of one angle merge in both lists alike; the SVG writes three decimals).
    const std::vector<double> expected = fileCreaseAngles(format, r.exported.content);
    int creases = 0;
    for (const json& stroke : scene["model"]["drawing"]["strokes"]) creases += stroke["assignment"] == "M" || stroke["assignment"] == "V";
    EXPECT_EQ(creases, static_cast<int>(expected.size()));
    const std::vector<double> expectedDistinct = distinctAngles(expected), importedDistinct = distinctAngles(importedTargets(scene));
    ASSERT_EQ(importedDistinct.size(), expectedDistinct.size());
    for (std::size_t k = 0; k < expectedDistinct.size(); ++k) EXPECT_NEAR(importedDistinct[k], expectedDistinct[k], 2e-3);
  }
}

TEST_P(CreasePatternRoundTrip, TheImportedExportFoldsToItsAnglesWithTheSliderKeepingItsLengths) {
  int skipped = 0;
  for (const std::string format : {"fold", "svg"}) {
    SCOPED_TRACE(format);
    RoundTrip r;
    ASSERT_NO_THROW(r = roundTrip(GetParam(), format));
    // Creases in rings round a hole (islands the import bridged) do not fold from a flat import: a
    // known defect, docs/architecture.md ("Islands and holes", concentric creases).
    const bool ringsAroundAHole = std::any_of(r.imported.notes.begin(), r.imported.notes.end(), [](const io::ImportNote& n) {
      return n.message.find("island(s) inside the sheet") != std::string::npos && n.message.find("joined to") != std::string::npos;
    });
    if (ringsAroundAHole) {
      ++skipped;
      continue;
    }
    // The slider, as a user moves it (the web app's FoldPanel: steps of 10 %), to 100 %.
    testing::ExampleEditor e(r.imported.scene);
    int op = 1;
    for (int step = 1; step <= 10; ++step) e.send({{"type", "fold"}, {"op", op++}, {"amount", step / 10.0}});
    e.send({{"type", "fold_end"}, {"op", op++}});  // as the web app lets go: the session's release iterations
    const auto errors = e.inbox.ofType("error");
    ASSERT_TRUE(errors.empty()) << errors[0].dump();
    const json metrics = e.inbox.last("solved")["metrics"];
    double largest = 0.0;
    for (double a : fileCreaseAngles(format, r.exported.content)) largest = std::max(largest, std::abs(a));
    // The quality limits of a composite's report (SceneSolver::quality) for the fold and the
    // lengths; one development edge may stretch more than the report's 0.1 where the ruling the
    // import proposes halfway along a strip meets the outline (measured up to 0.42: a known
    // defect, docs/architecture.md), not by the multiples of a sheet torn to reach its targets.
    EXPECT_LT(metrics["fold_angle_error_max_deg"].get<double>(), 1.0 + 0.15 * largest);
    EXPECT_LT(metrics["development_length_error"].get<double>(), 5e-3);
    EXPECT_LT(metrics["development_edge_strain_max"].get<double>(), 0.5);

    // A second trip: the folded import exported and imported again is the same design (the
    // import's own split creases came back as two each, and the next import split them again).
    const ExportedFile again = SceneSolver::exportScene(e.session->sceneJson(), format);
    CreasePatternImportRequest request;
    request.format = format;
    CreasePatternImportResult second;
    ASSERT_NO_THROW(second = importCreasePattern(again.content, request));
    const auto creasesOf = [](const proto::Scene& scene) {
      const json document = proto::sceneToJson(scene);  // held: a loop over a temporary's member dangles
      int creases = 0;
      for (const json& stroke : document.at("model").at("drawing").at("strokes"))
        creases += stroke.at("assignment") == "M" || stroke.at("assignment") == "V";
      return creases;
    };
    const int creasesFirst = creasesOf(r.imported.scene);
    EXPECT_GT(creasesFirst, 0);
    EXPECT_EQ(creasesOf(second.scene), creasesFirst);
    // Its layout may gain rulings where the folded development moved (two creases, FOLD: 6 faces,
    // then 9), but the creases are not cut up trip after trip.
    EXPECT_LE(second.faces, 2 * r.imported.faces);
  }
  if (skipped == 2) GTEST_SKIP() << "creases in rings round a hole in both exports (see above)";
}

/// The slider's progress per iteration, free of the machine's speed: every frame and the catch-up
/// get a fixed number of iterations and no time limit. With plain steps an imported column's
/// creases folded ~0.5° an iteration (a slow CI machine's catch-up stopped at 60–65° of 93°); with
/// the drag's correction steps (Session::foldLimits) they follow the slider.
TEST(CreasePatternRoundTripFold, TheSliderFoldsAnImportedColumnInAFixedNumberOfIterations) {
  const RoundTrip r = roundTrip("composite-column.json", "fold");
  SessionSettings settings;
  settings.dragIterations = 4;
  settings.dragTimeBudgetMs = 1e6;
  settings.releaseTimeBudgetMs = 1e6;
  testing::ExampleEditor e(r.imported.scene, settings);
  int op = 1;
  for (int step = 1; step <= 10; ++step) e.send({{"type", "fold"}, {"op", op++}, {"amount", step / 10.0}});
  e.send({{"type", "fold_end"}, {"op", op++}, {"iterations", 60}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.ofType("error")[0].dump();
  const json metrics = e.inbox.last("solved")["metrics"];
  EXPECT_LT(metrics["fold_angle_error_max_deg"].get<double>(), 1.0);
  EXPECT_LT(metrics["development_length_error"].get<double>(), 5e-3);
}

/// A 100 × 100 mm FOLD crease pattern as a tool that knows only straight edges writes a curved
/// valley (Origami Simulator's curved patterns, a cutter's export): the curve y = 50 + 15 sin(πx/100)
/// sampled at 17 points, flat (F) edges straight up and down from every sample to the outline as its
/// facets, the outline split where they meet it. No faces_vertices, edges_foldAngle 60° ± 3° along
/// the curve.
json samplesOfACurvedValleyAsFoldEdges() {
  json coords = json::array(), edges = json::array(), letters = json::array(), angles = json::array();
  const int n = 16;
  const auto add = [&coords](double x, double y) {
    coords.push_back({x, y});
    return static_cast<int>(coords.size()) - 1;
  };
  std::vector<int> bottom, top, crease;
  for (int i = 0; i <= n; ++i) {
    const double x = 100.0 * i / n;
    bottom.push_back(add(x, 0.0));
    top.push_back(add(x, 100.0));
    crease.push_back(add(x, 50.0 + 15.0 * std::sin(3.14159265358979 * x / 100.0)));
  }
  const auto edge = [&](int a, int b, const char* letter, double angle) {
    edges.push_back({a, b});
    letters.push_back(letter);
    angles.push_back(angle);
  };
  for (int i = 0; i < n; ++i) {
    edge(bottom[i], bottom[i + 1], "B", 0.0);
    edge(top[i], top[i + 1], "B", 0.0);
    edge(crease[i], crease[i + 1], "V", 60.0 + 3.0 * std::cos(3.14159265358979 * i / n));
  }
  for (int side : {0, n}) {
    edge(bottom[side], crease[side], "B", 0.0);
    edge(crease[side], top[side], "B", 0.0);
  }
  for (int i = 1; i < n; ++i) {
    edge(bottom[i], crease[i], "F", 0.0);
    edge(crease[i], top[i], "F", 0.0);
  }
  return {{"file_spec", 1.1}, {"frame_unit", "mm"}, {"vertices_coords", coords}, {"edges_vertices", edges},
          {"edges_assignment", letters}, {"edges_foldAngle", angles}};
}

TEST(CreasePatternImportOfFoldCurves, ACurvedCreaseDrawnAsStraightEdgesWithFacetsBetweenIsReadAsOneCurveThatFolds) {
  CreasePatternImportRequest request;
  request.format = "fold";
  const CreasePatternImportResult r = importCreasePattern(samplesOfACurvedValleyAsFoldEdges().dump(), request);
  EXPECT_EQ(r.curvedCreases, 1);
  const json scene = proto::sceneToJson(r.scene);
  int valleys = 0;
  for (const json& stroke : scene["model"]["drawing"]["strokes"]) valleys += stroke["assignment"] == "V";
  EXPECT_EQ(valleys, 1) << "one crease, not 16 hinges";
  bool flatNoted = false;
  for (const io::ImportNote& n : r.notes) flatNoted = flatNoted || n.message.find("the 30 flat edges between them") != std::string::npos;
  EXPECT_TRUE(flatNoted);
  // Its target: the mean of the file's angles along it, weighted by the edges' lengths.
  const json& targets = scene["model"]["fold_angles"];
  ASSERT_FALSE(targets.empty());
  const double target = targets[0]["angle"].get<double>();
  EXPECT_GT(target, 60.0 - 3.0);
  EXPECT_LT(target, 60.0 + 3.0);
  for (const json& t : targets) EXPECT_NEAR(t["angle"].get<double>(), target, 1e-9);
  // The slider folds it, as the web app moves it.
  testing::ExampleEditor e(r.scene);
  int op = 1;
  for (int step = 1; step <= 10; ++step) e.send({{"type", "fold"}, {"op", op++}, {"amount", step / 10.0}});
  e.send({{"type", "fold_end"}, {"op", op++}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.ofType("error")[0].dump();
  const json metrics = e.inbox.last("solved")["metrics"];
  EXPECT_LT(metrics["fold_angle_error_max_deg"].get<double>(), 1.0);
  EXPECT_LT(metrics["development_length_error"].get<double>(), 5e-3);
  EXPECT_LT(metrics["development_edge_strain_max"].get<double>(), 0.1);
}

INSTANTIATE_TEST_SUITE_P(Presets, CreasePatternRoundTrip, ::testing::ValuesIn(compositePresetsWithDevelopment()),
                         devsurf::testing::presetTestName<::testing::TestParamInfo<std::string>>);

}  // namespace
}  // namespace devsurf::server
