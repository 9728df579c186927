// `devsurf import PATTERN.fold` and the service behind POST /api/imports (issue 16, item 1): a
// composite scene from a FOLD crease pattern, read back by the scene parser and solved.

#include "devsurf/server/CreasePatternImport.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "devsurf/io/FoldWriter.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/server/SceneSolver.h"
#include "devsurf/server/ShapeUpload.h"
#include "server/CliTesting.h"
#include "support/TempDir.h"

namespace devsurf::server {
namespace {

std::string foldExamplePath(const std::string& file) { return std::string(DEVSURF_SOURCE_DIR) + "/tests/data/fold/" + file; }

std::string foldExampleText(const std::string& file) {
  std::ifstream in(foldExamplePath(file));
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

CreasePatternImportRequest foldRequest() {
  CreasePatternImportRequest r;
  r.format = "fold";
  return r;
}

/// Every shipped SVG drawing (tests/data/svg), discovered, in a stable order.
std::vector<std::filesystem::path> shippedSvgDrawings() {
  std::vector<std::filesystem::path> paths;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(DEVSURF_SOURCE_DIR) + "/tests/data/svg"))
    if (entry.path().extension() == ".svg") paths.push_back(entry.path());
  std::sort(paths.begin(), paths.end());
  return paths;
}

TEST(CreasePatternImport, EveryShippedFoldExampleBecomesACompositeSceneThatSolves) {
  for (const auto& entry : std::filesystem::directory_iterator(std::string(DEVSURF_SOURCE_DIR) + "/tests/data/fold")) {
    if (entry.path().extension() != ".fold") continue;
    SCOPED_TRACE(entry.path().filename().string());
    const testing::CliRun imported = testing::runCommand({"import", entry.path().string()});
    ASSERT_EQ(imported.code, 0) << imported.err;
    const nlohmann::json scene = nlohmann::json::parse(imported.out);
    EXPECT_EQ(scene["model"]["kind"], "composite");
    EXPECT_EQ(scene["model"]["development"]["samples"], 2);
    const testing::CliRun solved = testing::runCommand({"solve", "-"}, imported.out);
    ASSERT_EQ(solved.code, 0) << solved.err;
    const nlohmann::json report = nlohmann::json::parse(solved.out);
    EXPECT_LT(report["metrics"]["development_length_error"].get<double>(), 1e-6);
  }
}

TEST(CreasePatternImport, TheSummaryCountsAssignmentsAndTheSceneKeepsTheFoldedForm) {
  const CreasePatternImportResult r = importCreasePattern(foldExampleText("squaretwist.fold"), foldRequest());
  EXPECT_TRUE(r.foldedState);
  EXPECT_EQ(r.faces, 9);
  const nlohmann::json summary = r.summaryJson();
  EXPECT_EQ(summary["edges"]["mountain"].get<int>() + summary["edges"]["valley"].get<int>() +
                summary["edges"]["boundary"].get<int>() + summary["edges"]["flat"].get<int>(),
            24);
  EXPECT_EQ(r.scene.name, "Rigidly folded square twist");
  EXPECT_EQ(r.scene.units, "mm");  // no frame_unit: a unit-square sheet scaled to 200 mm, noted
  bool unitNote = false;
  for (const auto& n : r.notes) unitNote = unitNote || n.element == "frame_unit";
  EXPECT_TRUE(unitNote);
  const auto& design = std::get<models::composite::CompositeDesign>(r.scene.model);
  const nlohmann::json file = nlohmann::json::parse(foldExampleText("squaretwist.fold"));
  double fileSpan = 0.0;  // the file's largest coordinate extent (its folded form)
  for (int c = 0; c < 3; ++c) {
    double lo = 1e300, hi = -1e300;
    for (const auto& v : file["vertices_coords"]) lo = std::min(lo, v[c].get<double>()), hi = std::max(hi, v[c].get<double>());
    fileSpan = std::max(fileSpan, hi - lo);
  }
  const Eigen::Vector3d span = design.vertices.colwise().maxCoeff() - design.vertices.colwise().minCoeff();
  EXPECT_GT(span.maxCoeff() / fileSpan, 10.0);  // scaled up from the unit square
}

TEST(CreasePatternImport, NamesUnitsAndTheFilesUnitCarryOver) {
  CreasePatternImportRequest request = foldRequest();
  request.name = "my twist";
  request.units = "cm";
  const CreasePatternImportResult r = importCreasePattern(foldExampleText("squaretwist.fold"), request);
  EXPECT_EQ(r.scene.name, "my twist");
  EXPECT_EQ(r.scene.units, "cm");
  const std::string inPoints = R"({"frame_unit": "pt", "vertices_coords": [[0,0],[72,0],[0,72]], "faces_vertices": [[0,1,2]]})";
  const CreasePatternImportResult p = importCreasePattern(inPoints, foldRequest());
  EXPECT_EQ(p.scene.units, "mm");
  const auto& design = std::get<models::composite::CompositeDesign>(p.scene.model);
  EXPECT_NEAR(design.vertices.col(0).maxCoeff(), 25.4, 1e-12);  // 72 pt = 1 in
}

TEST(CreasePatternImport, BadRequestsNameTheFieldAndTooManyEdgesIsALimit) {
  auto fieldOf = [](const std::string& body, CreasePatternImportRequest request) {
    try {
      importCreasePattern(body, request);
    } catch (const ApproximationInputError& e) {
      return e.field() + (e.tooLarge() ? " (too large)" : "");
    }
    return std::string("(accepted)");
  };
  CreasePatternImportRequest dxf = foldRequest();
  dxf.format = "dxf";
  EXPECT_EQ(fieldOf(foldExampleText("simple.fold"), dxf), "format");
  CreasePatternImportRequest svg = foldRequest();
  svg.format = "svg";
  EXPECT_EQ(fieldOf(foldExampleText("simple.fold"), svg), "body");  // JSON is not an SVG drawing
  svg.maxEdges = 20;
  std::ifstream drawing(std::string(DEVSURF_SOURCE_DIR) + "/tests/data/svg/two-curved-creases.svg");
  std::ostringstream text;
  text << drawing.rdbuf();
  EXPECT_EQ(fieldOf(text.str(), svg), "body (too large)");
  CreasePatternImportRequest units = foldRequest();
  units.units = "furlong";
  EXPECT_EQ(fieldOf(foldExampleText("simple.fold"), units), "units");
  EXPECT_EQ(fieldOf("{not json", foldRequest()), "body");
  EXPECT_EQ(fieldOf(R"({"vertices_coords": [[0,0],[1,0],[0,1]], "faces_vertices": [[0,1,7]]})", foldRequest()), "body");
  CreasePatternImportRequest small = foldRequest();
  small.maxEdges = 10;
  EXPECT_EQ(fieldOf(foldExampleText("box.fold"), small), "body (too large)");
  // Numbers a double cannot hold, or coordinates too large to arrange: the body, not a failure.
  const std::string triangle = R"("faces_vertices": [[0,1,2]], "edges_vertices": [[0,1],[1,2],[2,0]],
                                  "edges_assignment": ["B","B","B"]})";
  EXPECT_EQ(fieldOf(R"({"vertices_coords": [[0,0],[1e400,0],[0,1]], )" + triangle, foldRequest()), "body");
  EXPECT_EQ(fieldOf(R"({"vertices_coords": [[0,0],[1e300,0],[0,1]], )" + triangle, foldRequest()), "body");
  EXPECT_EQ(fieldOf(R"({"vertices_coords": [[0,0],[1,0],[0,1]], "edges_foldAngle": [1e999,0,0], )" + triangle,
                    foldRequest()),
            "body");
}

TEST(CreasePatternImport, TheCommandRefusesNumbersADoubleCannotHoldAsBadInput) {
  const std::string path = ::testing::TempDir() + "/overflow.fold";
  {
    std::ofstream file(path);
    file << R"({"vertices_coords": [[0,0],[1e400,0],[0,1]], "faces_vertices": [[0,1,2]],
               "edges_vertices": [[0,1],[1,2],[2,0]], "edges_assignment": ["B","B","B"]})";
  }
  const testing::CliRun run = testing::runCommand({"import", path});
  EXPECT_EQ(run.code, 2) << run.err;  // bad input, not a runtime failure
  EXPECT_NE(run.err.find("out of the range"), std::string::npos) << run.err;
  std::filesystem::remove(path);
}

// Every shipped SVG drawing (tests/data/svg, discovered) imports through the command, solves flat,
// and folds with the slider: its fold-angle targets pull it to within 15 % of its drawn angles,
// measured from the solved scene's own exported crease pattern.
TEST(CreasePatternImport, EveryShippedSvgDrawingImportsSolvesAndFolds) {
  int drawings = 0;
  for (const std::filesystem::path& drawing : shippedSvgDrawings()) {
    ++drawings;
    SCOPED_TRACE(drawing.filename().string());
    const testing::CliRun imported = testing::runCommand({"import", drawing.string()});
    ASSERT_EQ(imported.code, 0) << imported.err;
    nlohmann::json scene = nlohmann::json::parse(imported.out);
    EXPECT_EQ(scene["model"]["kind"], "composite");
    ASSERT_TRUE(scene["model"].contains("fold_angles"));
    EXPECT_EQ(scene["model"]["fold_amount"], 0.0);
    double largest = 0.0;
    for (const auto& t : scene["model"]["fold_angles"]) largest = std::max(largest, std::abs(t["angle"].get<double>()));
    scene["model"]["fold_amount"] = 1.0;
    scene["solver"]["iterations"] = 80;
    const testing::CliRun solved = testing::runCommand({"solve", "-"}, scene.dump());
    ASSERT_EQ(solved.code, 0) << solved.err;
    const nlohmann::json report = nlohmann::json::parse(solved.out);
    EXPECT_LT(report["metrics"]["development_length_error"].get<double>(), 2e-3);
    EXPECT_LT(report["metrics"]["fold_angle_error_max_deg"].get<double>(), 0.15 * largest);
  }
  EXPECT_GE(drawings, 3);
}

TEST(CreasePatternImport, ACurvedSvgDrawingMakesSEdgesAndSaysSoInItsSummary) {
  std::ifstream drawing(std::string(DEVSURF_SOURCE_DIR) + "/tests/data/svg/two-curved-creases.svg");
  std::ostringstream text;
  text << drawing.rdbuf();
  CreasePatternImportRequest request;
  request.format = "svg";
  const CreasePatternImportResult result = importCreasePattern(text.str(), request);
  const nlohmann::json summary = result.summaryJson();
  EXPECT_EQ(summary["format"], "svg");
  EXPECT_EQ(summary["curved_creases"], 2);
  EXPECT_EQ(result.scene.name, "Two curved creases");
  EXPECT_EQ(result.scene.units, "mm");
  const nlohmann::json scene = proto::sceneToJson(result.scene);
  int curvedFolds = 0;
  for (const auto& e : scene["model"]["edges"]) curvedFolds += e["type"] == "S" && e.value("crease", "") == "fold" ? 1 : 0;
  EXPECT_EQ(curvedFolds, 4);  // two creases, each cut in half by a proposed ruling
}

// Origami Simulator's SVG convention reads a fully opaque crease as a full fold, 180°, which only a
// straight crease reaches. The two-curved-creases drawing without its stroke-opacity (as most files
// are drawn) aimed its curved creases at ±180°: the batch solve at 100 % folded nothing (fold error
// 179.8°, edge strain 3.76). Curved creases at a full fold now aim at ±90° and the import says so;
// a straight crease keeps its 180°.
TEST(CreasePatternImport, CurvedCreasesAtAFullFoldAimAtNinetyDegreesAndFoldThere) {
  std::ifstream drawing(std::string(DEVSURF_SOURCE_DIR) + "/tests/data/svg/two-curved-creases.svg");
  std::ostringstream read;
  read << drawing.rdbuf();
  std::string text = read.str();
  for (std::size_t at; (at = text.find(" stroke-opacity=\"0.5\"")) != std::string::npos;) text.erase(at, 21);
  ASSERT_EQ(text.find("opacity=\""), std::string::npos);
  // And a straight valley across a corner of the left flap, opaque too.
  text.insert(text.find("</svg>"), R"(<line x1="0" y1="80" x2="20" y2="100" stroke="#0000ff" stroke-width="0.5"/>)");
  CreasePatternImportRequest request;
  request.format = "svg";
  const CreasePatternImportResult result = importCreasePattern(text, request);
  const nlohmann::json summary = result.summaryJson();
  EXPECT_NE(summary.dump().find("aim at ±90°"), std::string::npos) << summary.dump();
  nlohmann::json scene = proto::sceneToJson(result.scene);
  int curved = 0, straight = 0;
  for (const nlohmann::json& t : scene["model"]["fold_angles"]) {
    const nlohmann::json& edge = scene["model"]["edges"][t["edge"].get<std::size_t>()];
    const double angle = std::abs(t["angle"].get<double>());
    if (edge.value("type", "S") == "S") {
      ++curved;
      EXPECT_EQ(angle, 90.0) << t.dump();
    } else {
      ++straight;
      EXPECT_EQ(angle, 180.0) << t.dump();
    }
  }
  EXPECT_GE(curved, 2);
  EXPECT_GE(straight, 1);
  // Without the straight valley (a corner folded flat onto the sheet: not what is measured here),
  // the curved creases reach their angles at 100 %.
  std::string curvedOnly = text;
  curvedOnly.erase(curvedOnly.find("<line x1=\"0\""), curvedOnly.find("</svg>") - curvedOnly.find("<line x1=\"0\""));
  nlohmann::json folded = proto::sceneToJson(importCreasePattern(curvedOnly, request).scene);
  folded["model"]["fold_amount"] = 1.0;
  folded["solver"]["iterations"] = 80;
  const testing::CliRun solved = testing::runCommand({"solve", "-"}, folded.dump());
  ASSERT_EQ(solved.code, 0) << solved.err;
  const nlohmann::json metrics = nlohmann::json::parse(solved.out)["metrics"];
  EXPECT_LT(metrics["fold_angle_error_max_deg"].get<double>(), 1.0);  // 1.4e-5° measured; 179.8° at ±180°
  EXPECT_GT(metrics["crease_fold_angle_max_deg"].get<double>(), 80.0);
  EXPECT_LT(metrics["development_length_error"].get<double>(), 2e-3);
}

// A tryout's grid of 150 × 150 lines was refused by the scene's schema (23 104 corners of at most
// 10 000) only once the whole composite was built: 5–14 s. It is refused where its lines are laid
// out, as too large, naming the count (0.34 s from the CLI on this machine, measured by hand).
TEST(CreasePatternImport, AGridOfLinesMeetingAtMoreCornersThanADesignHoldsIsRefusedAsTooLarge) {
  std::ostringstream svg;
  svg << R"(<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="200mm" viewBox="0 0 200 200">)"
      << R"(<rect x="0" y="0" width="200" height="200" stroke="#000" fill="none"/>)";
  for (int k = 1; k <= 110; ++k) {
    const double at = 200.0 * k / 111.0;
    svg << "<line x1=\"" << at << "\" y1=\"0\" x2=\"" << at << "\" y2=\"200\" stroke=\"#f00\"/>"
        << "<line x1=\"0\" y1=\"" << at << "\" x2=\"200\" y2=\"" << at << "\" stroke=\"#00f\"/>";
  }
  svg << "</svg>";
  CreasePatternImportRequest request;
  request.format = "svg";
  try {
    importCreasePattern(svg.str(), request);
    FAIL() << "a grid of 110 × 110 creases was imported";
  } catch (const ApproximationInputError& e) {
    EXPECT_TRUE(e.tooLarge());
    EXPECT_EQ(e.field(), "body");
    // 110² crossings and 4 × 110 ends on the outline (the outline's own corners join two of its pieces).
    EXPECT_NE(std::string(e.what()).find("meet at 12540 points; a design holds at most 10000"), std::string::npos) << e.what();
  }
}

TEST(CreasePatternImport, ASheetOfThirtyCurvedPleatsImportsAsAValidSceneThatFolds) {
  // A tryout's pleated sheet: 20 and more vertical curved creases, mountain and valley in turn,
  // were refused by the scene's own schema ("model.development.domain.boundary: expected at most
  // 64 items, got 66": the outline is cut where every crease meets it).
  std::ostringstream svg;
  svg << R"(<svg xmlns="http://www.w3.org/2000/svg" width="300mm" height="200mm" viewBox="0 0 300 200">)"
      << R"(<rect x="0" y="0" width="300" height="200" stroke="#000" fill="none"/>)";
  for (int k = 0; k < 30; ++k) {
    const double x = 5.0 + 10.0 * k;
    svg << "<path d=\"M " << x << " 0 C " << x + 2 << " 60, " << x - 2 << " 140, " << x << " 200\" stroke=\""
        << (k % 2 ? "#f00" : "#00f") << "\" fill=\"none\"/>";
  }
  svg << "</svg>";
  CreasePatternImportRequest request;
  request.format = "svg";
  const CreasePatternImportResult result = importCreasePattern(svg.str(), request);
  EXPECT_EQ(result.summaryJson()["curved_creases"], 30);
  const nlohmann::json scene = proto::sceneToJson(result.scene);
  EXPECT_GT(scene["model"]["development"]["domain"]["boundary"].size(), 64u);
  EXPECT_NO_THROW(proto::sceneFromJson(scene));  // the schema and the model's own checks
  // Folded a little, as a batch solve does: the pleats fold and the sheet keeps its lengths.
  proto::Scene folded = result.scene;
  std::get<models::composite::CompositeDesign>(folded.model).foldAmount = 0.2;
  SceneSolver solver(std::move(folded));
  solver.solve(30);
  const proto::Metrics m = solver.metrics();
  EXPECT_GT(m.at("crease_fold_angle_max_deg"), 10.0);
  EXPECT_LT(m.at("development_length_error"), 5e-3);
}

TEST(CreasePatternImport, TheCommandRefusesMeshOptionsOnACreasePatternAndReportsNotesOnStderr) {
  const testing::CliRun withMeshOption = testing::runCommand({"import", foldExamplePath("simple.fold"), "--proximity"});
  EXPECT_EQ(withMeshOption.code, 2);
  const testing::CliRun folded = testing::runCommand({"import", foldExamplePath("diagonal-folded.fold")});
  ASSERT_EQ(folded.code, 0) << folded.err;
  EXPECT_NE(folded.err.find("note: the key frame: a flat-folded form"), std::string::npos) << folded.err;
}

}  // namespace
}  // namespace devsurf::server

namespace devsurf::server {
namespace {

// A slit as FOLD writes it (C), and as an SVG draws it (green), imported: the sheet is cut along it
// (issue 16 item 1), the notes say so, and the slider opens it — the folded scene's two copies of
// the slit's mouth, read from the solved report, are apart.
TEST(CreasePatternImport, ASlitInAFoldFileOrAGreenSvgLineIsCutAndOpensWhenTheSheetFolds) {
  const std::string fold = R"({"file_spec": 1.2, "frame_classes": ["creasePattern"],
    "vertices_coords": [[0,0],[100,0],[200,0],[0,100],[100,100],[200,100],[0,200],[100,200],[200,200]],
    "edges_vertices": [[0,1],[1,2],[2,5],[5,8],[8,7],[7,6],[6,3],[3,0],[3,4],[4,5],[4,7],[1,4]],
    "edges_assignment": ["B","B","B","B","B","B","B","B","V","M","F","C"],
    "edges_foldAngle": [0,0,0,0,0,0,0,0,90,-90,0,0]})";
  const CreasePatternImportResult r = importCreasePattern(fold, foldRequest());
  EXPECT_EQ(r.cut, 1);
  bool noted = false;
  for (const io::ImportNote& n : r.notes) noted = noted || n.message.find("cut along") != std::string::npos;
  EXPECT_TRUE(noted) << r.summaryJson().dump();
  nlohmann::json scene = proto::sceneToJson(r.scene);
  EXPECT_EQ(scene["model"]["vertices"].size(), 10u);
  scene["model"]["fold_amount"] = 1.0;
  const testing::CliRun solved = testing::runCommand({"solve", "-", "--iterations", "80"}, scene.dump());
  ASSERT_EQ(solved.code, 0) << solved.err;
  const nlohmann::json report = nlohmann::json::parse(solved.out);
  const nlohmann::json& v = report["scene"]["model"]["vertices"];
  // The mouth of the slit: the two vertices at (100, 0) of the drawing.
  std::vector<std::size_t> mouth;
  const nlohmann::json& flat = report["scene"]["model"]["development"]["vertices"];
  for (std::size_t k = 0; k < flat.size() && k < v.size(); ++k)
    if (std::abs(flat[k][0].get<double>() - 100.0) < 1e-6 && std::abs(flat[k][1].get<double>()) < 1e-6) mouth.push_back(k);
  ASSERT_EQ(mouth.size(), 2u) << flat.dump();
  double apart = 0.0;
  for (int c = 0; c < 3; ++c) apart += std::pow(v[mouth[0]][c].get<double>() - v[mouth[1]][c].get<double>(), 2);
  std::printf("imported slit folded: mouth %.1f mm open, fold-angle error %.3g°\n", std::sqrt(apart),
              report["metrics"].value("fold_angle_error_max_deg", -1.0));
  EXPECT_GT(std::sqrt(apart), 150.0);

  // The same drawn as an SVG: black outline, red mountain, blue valley, green cut, yellow flat.
  const std::string svg = R"(<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="200mm" viewBox="0 0 200 200">
    <rect x="0" y="0" width="200" height="200" fill="none" stroke="#000000"/>
    <line x1="0" y1="100" x2="100" y2="100" stroke="#0000ff"/>
    <line x1="100" y1="100" x2="200" y2="100" stroke="#ff0000"/>
    <line x1="100" y1="0" x2="100" y2="100" stroke="#ffff00"/>
    <line x1="100" y1="100" x2="100" y2="200" stroke="#00ff00"/></svg>)";
  CreasePatternImportRequest svgRequest;
  svgRequest.format = "svg";
  const CreasePatternImportResult s = importCreasePattern(svg, svgRequest);
  EXPECT_EQ(s.cut, 1);
  EXPECT_EQ(proto::sceneToJson(s.scene)["model"]["vertices"].size(), 10u) << s.summaryJson().dump();
}

// box.fold's folded form folds creases against their letters (its faces wind the other way): the
// import keeps the folded form and says so, naming the creases; a consistent file has no such note.
TEST(CreasePatternImport, CreasesFoldedAgainstTheirLettersAreNoted) {
  auto againstNote = [](const CreasePatternImportResult& r) {
    for (const io::ImportNote& n : r.notes)
      if (n.element == "edges_assignment" && n.message.find("against their letter") != std::string::npos) return n.message;
    return std::string();
  };
  const std::string box = againstNote(importCreasePattern(foldExampleText("box.fold"), foldRequest()));
  EXPECT_NE(box.find("edges_assignment["), std::string::npos) << box;
  EXPECT_EQ(againstNote(importCreasePattern(foldExampleText("diagonal-folded.fold"), foldRequest())), "");
}

// A flat sheet's crease pattern exported before it is folded (its folded frame flat, inheriting the
// designed angles) imports again as that flat pattern at 0 %, its valley still a valley at 180°.
TEST(CreasePatternImport, AFlatSheetsFoldExportImportsAgainAsTheFlatPatternWithItsDesign) {
  const CreasePatternImportResult first = importCreasePattern(foldExampleText("diagonal-cp.fold"), foldRequest());
  const auto& design = std::get<models::composite::CompositeDesign>(first.scene.model);
  ASSERT_EQ(design.foldAmount, 0.0);
  const models::composite::CompositeModel model(design);
  const std::string exported = io::foldDocument(model.creasePattern()).dump();
  const CreasePatternImportResult again = importCreasePattern(exported, foldRequest());
  const nlohmann::json scene = proto::sceneToJson(again.scene);
  EXPECT_EQ(scene["model"]["fold_amount"].get<double>(), 0.0) << again.summaryJson().dump();
  EXPECT_EQ(again.valley, 1);
  ASSERT_EQ(scene["model"]["fold_angles"].size(), 1u);
  EXPECT_NEAR(scene["model"]["fold_angles"][0]["angle"].get<double>(), 180.0, 1e-9);
}

// A stroke that is a point (a path of zero length, a Bézier whose points coincide) on the outline
// is left out whole: it leaves no vertex behind, and the scene opens and folds (it left a vertex on
// the outline whose faces were degenerate there: "fold_angles[1]: edge 26 has no hinge there").
TEST(CreasePatternImport, AStrokeOfNoLengthIsLeftOutWithANoteAndTheSceneOpens) {
  for (const std::string point : {R"(<path d="M 20 0 L 20 0" stroke="#0000ff"/>)",
                                  R"(<path d="M 20 0 C 20 0, 20 0, 20 0" stroke="#0000ff"/>)",
                                  R"(<line x1="50" y1="50" x2="50" y2="50" stroke="#0000ff"/>)"}) {
    SCOPED_TRACE(point);
    const std::string svg = R"(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
      <rect x="0" y="0" width="100" height="100" fill="none" stroke="#000000"/>)" + point +
                            R"(<line x1="50" y1="0" x2="50" y2="100" stroke="#ff0000"/></svg>)";
    CreasePatternImportRequest request;
    request.format = "svg";
    const CreasePatternImportResult r = importCreasePattern(svg, request);
    bool noted = false;
    for (const io::ImportNote& n : r.notes) noted = noted || n.message.find("no length") != std::string::npos;
    EXPECT_TRUE(noted) << r.summaryJson().dump();
    const nlohmann::json scene = proto::sceneToJson(r.scene);
    for (const nlohmann::json& v : scene["model"]["vertices"])
      EXPECT_FALSE(std::abs(v[0].get<double>() - 20.0) < 1e-9 && std::abs(v[1].get<double>() - 100.0) < 1e-9)
          << "a vertex where the point was";
    // Folded to 100 % as `devsurf solve` solves it.
    devsurf::testing::TempDir dir;
    nlohmann::json folded = scene;
    folded["model"]["fold_amount"] = 1.0;
    const std::string path = (dir.path() / "point.json").string(), report = (dir.path() / "r.json").string();
    std::ofstream(path) << folded.dump();
    const CliRun solve = runCommand({"solve", path, "--iterations", "30", "--out", report});
    EXPECT_EQ(solve.code, 0) << solve.err;
  }
}

}  // namespace
}  // namespace devsurf::server

namespace devsurf::server {
namespace {

CreasePatternImportRequest svgRequest(const std::string& units = "") {
  CreasePatternImportRequest r;
  r.format = "svg";
  r.units = units;
  return r;
}

/// The smallest and largest x and y of a scene's composite vertices.
Eigen::Vector4d extentOf(const proto::Scene& scene) {
  const auto& v = std::get<models::composite::CompositeDesign>(scene.model).vertices;
  return {v.col(0).minCoeff(), v.col(0).maxCoeff(), v.col(1).minCoeff(), v.col(1).maxCoeff()};
}

// What a new user's Inkscape, Illustrator and FOLD 1.0 files met (stop 55's tryout): units asked
// for relabelled the file's millimetres (a 120 mm drawing became a 1.2 m sheet in cm), a page
// whose shape differs from its viewBox was stretched, a drawing without a viewBox landed below
// the x axis, and FOLD 1.0's edges_foldAngles was ignored (its 60° became 180°).
TEST(CreasePatternImport, UnitsAskedForConvertAFileThatStatesItsOwnAndKeepAUnitlessFilesNumbers) {
  const std::string drawing = R"(<svg xmlns="http://www.w3.org/2000/svg" width="120mm" height="80mm" viewBox="0 0 120 80">
    <rect width="120" height="80" fill="none" stroke="#000"/><line x1="60" y1="0" x2="60" y2="80" stroke="#f00"/></svg>)";
  const CreasePatternImportResult cm = importCreasePattern(drawing, svgRequest("cm"));
  EXPECT_EQ(cm.scene.units, "cm");
  EXPECT_TRUE(extentOf(cm.scene).isApprox(Eigen::Vector4d(0.0, 12.0, 0.0, 8.0), 1e-12)) << extentOf(cm.scene).transpose();
  bool noted = false;
  for (const io::ImportNote& n : cm.notes) noted = noted || n.message.find("converted to cm") != std::string::npos;
  EXPECT_TRUE(noted);
  // The drawing travels in the same numbers (layout edits rebuild from it).
  for (const io::CreaseStroke& s : std::get<models::composite::CompositeDesign>(cm.scene.model).drawing)
    for (const Eigen::Vector2d& p : s.points) EXPECT_LE(p.x(), 12.0 + 1e-9);
  // A FOLD file in mm asked for in inches; a unitless one keeps its numbers in the units asked for.
  const std::string square = R"({"file_spec": 1.1, "frame_unit": "mm", "vertices_coords": [[0,0],[254,0],[254,254],[0,254]],
    "edges_vertices": [[0,1],[1,2],[2,3],[3,0],[0,2]], "edges_assignment": ["B","B","B","B","V"]})";
  CreasePatternImportRequest inches = foldRequest();
  inches.units = "in";
  EXPECT_TRUE(extentOf(importCreasePattern(square, inches).scene).isApprox(Eigen::Vector4d(0.0, 10.0, 0.0, 10.0), 1e-12));
  nlohmann::json unitless = nlohmann::json::parse(square);
  unitless.erase("frame_unit");
  EXPECT_TRUE(extentOf(importCreasePattern(unitless.dump(), inches).scene).isApprox(Eigen::Vector4d(0.0, 254.0, 0.0, 254.0), 1e-12));
}

TEST(CreasePatternImport, APageShapedUnlikeItsViewBoxIsFittedAsAViewerFitsItAndAPageWithoutOneSitsAboveTheAxis) {
  auto sheet = [](const std::string& svgAttributes, const std::string& side) {
    return "<svg xmlns=\"http://www.w3.org/2000/svg\" " + svgAttributes + "><rect width=\"" + side + "\" height=\"" + side +
           "\" fill=\"none\" stroke=\"#000\"/></svg>";
  };
  // A 100 × 100 viewBox on a 200 × 100 mm page: by default uniform (1 mm per unit), centred.
  EXPECT_TRUE(extentOf(importCreasePattern(sheet(R"(width="200mm" height="100mm" viewBox="0 0 100 100")", "100"), svgRequest()).scene)
                  .isApprox(Eigen::Vector4d(50.0, 150.0, 0.0, 100.0), 1e-12));
  EXPECT_TRUE(extentOf(importCreasePattern(sheet(R"(width="200mm" height="100mm" viewBox="0 0 100 100" preserveAspectRatio="xMinYMin meet")", "100"),
                                           svgRequest()).scene)
                  .isApprox(Eigen::Vector4d(0.0, 100.0, 0.0, 100.0), 1e-12));
  EXPECT_TRUE(extentOf(importCreasePattern(sheet(R"(width="200mm" height="100mm" viewBox="0 0 100 100" preserveAspectRatio="none")", "100"),
                                           svgRequest()).scene)
                  .isApprox(Eigen::Vector4d(0.0, 200.0, 0.0, 100.0), 1e-12));
  // No viewBox: user units are px on a page of the given height, y up from its bottom edge.
  const Eigen::Vector4d px = extentOf(importCreasePattern(sheet(R"(width="960" height="960")", "96"), svgRequest()).scene);
  EXPECT_TRUE(px.isApprox(Eigen::Vector4d(0.0, 25.4, 254.0 - 25.4, 254.0), 1e-9)) << px.transpose();
  const Eigen::Vector4d bare = extentOf(importCreasePattern(sheet("", "96"), svgRequest()).scene);
  EXPECT_TRUE(bare.isApprox(Eigen::Vector4d(0.0, 25.4, 0.0, 25.4), 1e-9)) << bare.transpose();
}

TEST(CreasePatternImport, Fold10sEdgesFoldAnglesAreReadAndTheDescriptionCountsCreasesNotTheirPieces) {
  const std::string fold10 = R"({"file_spec": 1, "vertices_coords": [[0,0],[100,0],[100,100],[0,100]],
    "edges_vertices": [[0,1],[1,2],[2,3],[3,0],[0,2]], "edges_assignment": ["B","B","B","B","V"],
    "edges_foldAngles": [0,0,0,0,60]})";
  const CreasePatternImportResult r = importCreasePattern(fold10, foldRequest());
  const auto& design = std::get<models::composite::CompositeDesign>(r.scene.model);
  ASSERT_FALSE(design.foldAngles.empty());
  for (const models::composite::FoldAngleTarget& t : design.foldAngles) EXPECT_DOUBLE_EQ(t.angleDeg, 60.0);
  // One curved valley cut into pieces by the proposed rulings is one crease.
  const CreasePatternImportResult curved = importCreasePattern(
      R"(<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="100mm" viewBox="0 0 200 100">
      <rect width="200" height="100" fill="none" stroke="#000"/>
      <path d="M 60 0 C 80 30 40 70 60 100" fill="none" stroke="#00f" stroke-opacity="0.5"/></svg>)",
      svgRequest());
  EXPECT_GT(curved.valley, 1);  // the summary's edges: the pieces
  EXPECT_NE(curved.scene.description.find("(0 mountain and 1 valley crease)"), std::string::npos) << curved.scene.description;
}

TEST(CreasePatternImport, ARequestThatDoesNotSayTheFormatIsReadByTheFilesNameOrItsFirstCharacter) {
  EXPECT_EQ(creasePatternFormatOf("<svg/>"), "svg");
  EXPECT_EQ(creasePatternFormatOf("\xEF\xBB\xBF\n  <?xml version=\"1.0\"?><svg/>"), "svg");
  EXPECT_EQ(creasePatternFormatOf(" {\"file_spec\": 1.1}"), "fold");
  EXPECT_EQ(creasePatternFormatOf("not a pattern"), "fold");  // then refused as not JSON, naming body
  EXPECT_EQ(creasePatternFormatOf("{}", "pattern.SVG"), "svg");
  EXPECT_EQ(creasePatternFormatOf("<svg/>", "pattern.fold"), "fold");
}


// A flat drawing's own SVG fold pattern imports again with its fold angles: the export writes them
// as data-fold-angle (it wrote none, and every crease came back at 180°), and the importer leaves
// the legend's line samples out. Every shipped drawing, discovered.
TEST(CreasePatternImport, EveryShippedSvgDrawingsFoldPatternImportsAgainWithItsFoldAngles) {
  devsurf::testing::TempDir dir;
  int drawings = 0;
  for (const std::filesystem::path& drawing : shippedSvgDrawings()) {
    ++drawings;
    SCOPED_TRACE(drawing.filename().string());
    const testing::CliRun imported = testing::runCommand({"import", drawing.string()});
    ASSERT_EQ(imported.code, 0) << imported.err;
    const std::string exported = (dir.path() / drawing.filename()).string();
    const testing::CliRun solved = testing::runCommand({"solve", "-", "--iterations", "2", "--export", "svg:" + exported}, imported.out);
    ASSERT_EQ(solved.code, 0) << solved.err;
    const testing::CliRun again = testing::runCommand({"import", exported});
    ASSERT_EQ(again.code, 0) << again.err;
    EXPECT_NE(again.err.find("a legend (g#legend); left out"), std::string::npos) << again.err;
    auto angles = [](const std::string& sceneText) {
      std::vector<double> out;
      const nlohmann::json scene = nlohmann::json::parse(sceneText);  // alive through the loop
      for (const auto& t : scene["model"]["fold_angles"]) out.push_back(t["angle"].get<double>());
      std::sort(out.begin(), out.end());
      out.erase(std::unique(out.begin(), out.end(), [](double a, double b) { return std::abs(a - b) < 0.5; }), out.end());
      return out;
    };
    const std::vector<double> designed = angles(imported.out), read = angles(again.out);
    ASSERT_EQ(designed.size(), read.size());
    for (std::size_t k = 0; k < designed.size(); ++k) EXPECT_NEAR(read[k], designed[k], 0.5);
  }
  EXPECT_GE(drawings, 3);
}


// A crease drawn by hand 0.3 mm short of the outline at both ends was left out ("a stroke with a
// free end") and the import went on without it; it now meets the outline, as the editor's drawing
// tool snaps (within 1 % of the drawing's diagonal), the drawing kept with it, and a note says
// where. A crease ending far inside is still left out, the note saying where it runs.
TEST(CreasePatternImport, ACreaseStoppingJustShortOfTheOutlineMeetsItAndOneEndingInsideIsLeftOutSayingWhere) {
  const std::string shortOfIt = R"(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
    <rect width="100" height="100" fill="none" stroke="black"/>
    <line x1="50" y1="0.3" x2="50" y2="99.7" stroke="blue" stroke-opacity="0.5"/></svg>)";
  const CreasePatternImportResult r = importCreasePattern(shortOfIt, svgRequest());
  EXPECT_EQ(r.faces, 2);
  int joined = 0;
  for (const io::ImportNote& n : r.notes) joined += n.element == "line[0]" && n.message.find("joined to it") != std::string::npos;
  EXPECT_EQ(joined, 2);
  for (const io::CreaseStroke& s : std::get<models::composite::CompositeDesign>(r.scene.model).drawing)
    if (s.assignment == io::EdgeAssignment::Valley) {
      EXPECT_NEAR(std::min(s.points.front().y(), s.points.back().y()), 0.0, 1e-9);
      EXPECT_NEAR(std::max(s.points.front().y(), s.points.back().y()), 100.0, 1e-9);
    }
  const std::string inside = R"(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
    <rect width="100" height="100" fill="none" stroke="black"/>
    <line x1="50" y1="0" x2="50" y2="100" stroke="red"/>
    <line x1="50" y1="50" x2="80" y2="50" stroke="blue"/></svg>)";
  const CreasePatternImportResult free = importCreasePattern(inside, svgRequest());
  bool said = false;
  for (const io::ImportNote& n : free.notes)
    said = said || (n.element == "line[1]" && n.message.find("free end") != std::string::npos &&
                    n.message.find("(80, 50)") != std::string::npos);
  EXPECT_TRUE(said) << free.summaryJson().dump();
}


// Colours as Illustrator and Inkscape write them (stop 55's tryout left each out with a note): an
// id rule of a <style> (over a class rule, by specificity), 8- and 4-digit hex and rgba() whose
// alpha multiplies the opacity (the fold angle), and currentColor naming an inherited color.
// A hand-drawn 1 mm kink where a crease leaves the outline (a polyline, a path's first segment)
// was refused: "fold_angles[1]: edge 7 has no hinge there (its faces are degenerate at that end)".
// The jog is smoothed into its stroke with a note, and the pattern imports and folds.
TEST(CreasePatternImport, AJogAtACreasesEndIsSmoothedIntoItAndThePatternFolds) {
  const std::string kinked = R"(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
    <rect width="100" height="100" fill="none" stroke="#000"/>
    <polyline points="0,50 1,49.5 100,50" stroke="#00f" fill="none" stroke-opacity="0.5"/></svg>)";
  const CreasePatternImportResult r = importCreasePattern(kinked, svgRequest());
  EXPECT_EQ(r.faces, 2);
  bool noted = false;
  for (const io::ImportNote& n : r.notes) noted = noted || (n.element == "polyline[0]" && n.message.find("a jog of") != std::string::npos);
  EXPECT_TRUE(noted) << r.summaryJson().dump();
  nlohmann::json scene = proto::sceneToJson(r.scene);
  const testing::CliRun solved = testing::runCommand({"solve", "-", "--fold-amount", "1", "--iterations", "60"}, scene.dump());
  ASSERT_EQ(solved.code, 0) << solved.err;
  const nlohmann::json report = nlohmann::json::parse(solved.out);
  EXPECT_NEAR(report["metrics"]["crease_fold_angle_max_deg"].get<double>(), 90.0, 1.0);
  EXPECT_TRUE(report["quality"]["met"].get<bool>()) << report["quality"].dump();
}

TEST(CreasePatternImport, IdRulesColoursWithAlphaAndCurrentColorAreReadAsAViewerDrawsThem) {
  const std::string drawing = R"svg(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
    <style>.crease { stroke: #ff0000 } #valley { stroke: blue }</style>
    <rect width="100" height="100" fill="none" stroke="black"/>
    <line id="valley" class="crease" x1="20" y1="0" x2="20" y2="100"/>
    <line x1="40" y1="0" x2="40" y2="100" stroke="#0000ff80"/>
    <line x1="60" y1="0" x2="60" y2="100" stroke="rgba(255, 0, 0, 0.25)"/>
    <g color="#f00"><line x1="80" y1="0" x2="80" y2="100" stroke="currentColor" stroke-opacity="0.5"/></g></svg>)svg";
  const CreasePatternImportResult r = importCreasePattern(drawing, svgRequest());
  std::map<long, double> angleAtX;  // the creases' x → their fold-angle target
  const auto& design = std::get<models::composite::CompositeDesign>(r.scene.model);
  for (const io::CreaseStroke& s : design.drawing)
    if (s.foldAngle && s.assignment != io::EdgeAssignment::Boundary) angleAtX[std::lround(s.points.front().x())] = *s.foldAngle;
  ASSERT_EQ(angleAtX.size(), 4u) << r.summaryJson().dump();
  EXPECT_NEAR(angleAtX[20], 180.0, 1e-9);                 // the id rule's blue, over the class's red
  EXPECT_NEAR(angleAtX[40], 180.0 * 128.0 / 255.0, 1e-9);  // #0000ff80: a valley at half opacity
  EXPECT_NEAR(angleAtX[60], -45.0, 1e-9);                  // rgba red at 0.25
  EXPECT_NEAR(angleAtX[80], -90.0, 1e-9);                  // currentColor: the group's red
}

TEST(CreasePatternImport, AZigzagOfStraightCreasesIsRefusedSayingWhereItCannotFold) {
  // A new user's zigzag of four mountain lines across a 100 mm square: refused before with the
  // model's words ("fold_angles[1]: edge 7 has no hinge there"), which name nothing in the file.
  const std::string svg = R"(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
<rect x="0" y="0" width="100" height="100" fill="none" stroke="#000000"/>
<line stroke="#FF0000" x1="40" y1="0" x2="60" y2="25"/><line stroke="#FF0000" x1="60" y1="25" x2="40" y2="50"/>
<line stroke="#FF0000" x1="40" y1="50" x2="60" y2="75"/><line stroke="#FF0000" x1="60" y1="75" x2="40" y2="100"/></svg>)";
  CreasePatternImportRequest request;
  request.format = "svg";
  try {
    importCreasePattern(svg, request);
    FAIL() << "a zigzag of two-crease corners cannot fold";
  } catch (const ApproximationInputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("cannot fold at ("), std::string::npos) << message;
    EXPECT_EQ(message.find("has no hinge"), std::string::npos) << message;
    // At one of the zigzag's inner corners (y up: (60, 75), (40, 50) or (60, 25)).
    const bool atACorner = message.find("(60, 75)") != std::string::npos || message.find("(40, 50)") != std::string::npos ||
                           message.find("(60, 25)") != std::string::npos;
    EXPECT_TRUE(atACorner) << message;
  }
}

}  // namespace
}  // namespace devsurf::server
