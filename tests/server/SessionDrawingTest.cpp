// Layout edits on the flat sheet (issue 16, item 3): draw, relabel, reshape and erase creases of a
// composite drawn on a sheet. Each rebuilds the composite from its drawing; refused edits change
// nothing; undo, collaborators and the journal see them like any structural edit.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <sstream>

#include "devsurf/server/CreasePatternImport.h"
#include "server/SessionTesting.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
using testing::ExampleEditor;
using testing::Inbox;
using testing::ManualExecutor;

constexpr double kSheetWidth = 200.0, kSheetHeight = 150.0;

/// A blank sheet as the start page makes it: an SVG of one black rectangle, imported.
proto::Scene blankSheet() {
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kSheetWidth << "mm\" height=\"" << kSheetHeight
      << "mm\" viewBox=\"0 0 " << kSheetWidth << " " << kSheetHeight << "\"><rect x=\"0\" y=\"0\" width=\"" << kSheetWidth
      << "\" height=\"" << kSheetHeight << "\" fill=\"none\" stroke=\"#000\"/></svg>";
  CreasePatternImportRequest request;
  request.format = "svg";
  return importCreasePattern(svg.str(), request).scene;
}

json drawMessage(int op, const json& points, bool curved, const std::string& assignment, double angle = 90.0) {
  return {{"type", "draw_crease"}, {"op", op}, {"points", points}, {"curved", curved}, {"assignment", assignment},
          {"fold_angle", angle}};
}

std::size_t strokeCount(const json& scene) { return scene["model"]["drawing"]["strokes"].size(); }

int splineEdgeCount(const json& scene) {
  int n = 0;
  for (const json& e : scene["model"]["edges"]) n += e["type"] == "S";
  return n;
}

std::string lastErrorPath(const Inbox& inbox) {
  const json error = inbox.last("error");
  return error.is_null() ? std::string("(no error)") : error["path"].get<std::string>();
}

TEST(SessionDrawing, ABlankSheetTakesAStraightValleyThenACurvedMountainAndEachSplitsAFace) {
  ExampleEditor e(blankSheet());
  const json blank = e.session->sceneJson();
  ASSERT_EQ(blank["model"]["faces"].size(), 1u);
  const std::size_t outline = strokeCount(blank);

  // A straight valley across the sheet, its ends a little off the outline (snapped onto it).
  e.send(drawMessage(1, {{0.8, 50.0}, {199.5, 40.0}}, false, "V"));
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  json scene = e.session->sceneJson();
  EXPECT_EQ(strokeCount(scene), outline + 1);
  EXPECT_EQ(scene["model"]["faces"].size(), 2u);
  ASSERT_EQ(scene["model"]["fold_angles"].size(), 1u);
  EXPECT_DOUBLE_EQ(scene["model"]["fold_angles"][0]["angle"].get<double>(), 90.0);
  const json drawn = scene["model"]["drawing"]["strokes"][outline];
  EXPECT_DOUBLE_EQ(drawn["points"][0][0].get<double>(), 0.0);  // snapped onto the left edge
  EXPECT_DOUBLE_EQ(drawn["points"][1][0].get<double>(), kSheetWidth);

  // A curved mountain through three points, from the bottom edge to the top edge, crossing it.
  e.send(drawMessage(2, {{60.0, 0.0}, {80.0, 75.0}, {60.0, 150.0}}, true, "M", 60.0));
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  scene = e.session->sceneJson();
  EXPECT_EQ(strokeCount(scene), outline + 2);
  EXPECT_GE(scene["model"]["faces"].size(), 4u);  // two creases crossing: four faces, cut by proposed rulings
  EXPECT_GT(splineEdgeCount(scene), 0);            // the curved crease became S edges
  EXPECT_TRUE(scene["model"]["drawing"]["strokes"][outline + 1]["curved"].get<bool>());
  bool foldCrease = false;
  for (const json& edge : scene["model"]["edges"]) foldCrease |= edge.value("crease", "") == "fold";
  EXPECT_TRUE(foldCrease);
  EXPECT_EQ(scene["model"].value("fold_amount", 1.0), 0.0);  // rebuilt flat
  // A collaborator sees each as an edit; the journal holds both.
  EXPECT_EQ(e.journal.edits.size(), 2u);
  EXPECT_EQ(e.inbox.ofType("ack").size(), 2u);
}

TEST(SessionDrawing, RelabelReshapeEraseAndUndoWalkTheDrawingBackAndForth) {
  ExampleEditor e(blankSheet());
  const std::size_t outline = strokeCount(e.session->sceneJson());
  const int crease = static_cast<int>(outline);
  e.send(drawMessage(1, {{50.0, 0.0}, {70.0, 75.0}, {50.0, 150.0}}, true, "V"));
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  const json valley = e.session->sceneJson();

  e.send({{"type", "relabel_crease"}, {"op", 2}, {"crease", crease}, {"assignment", "M"}, {"fold_angle", 45}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  json scene = e.session->sceneJson();
  EXPECT_EQ(scene["model"]["drawing"]["strokes"][crease]["assignment"], "M");
  EXPECT_DOUBLE_EQ(scene["model"]["drawing"]["strokes"][crease]["fold_angle"].get<double>(), -45.0);
  for (const json& t : scene["model"]["fold_angles"]) EXPECT_DOUBLE_EQ(t["angle"].get<double>(), -45.0);

  // Reshape: a fourth point (the user inserted one), the ends moved along the outline.
  e.send({{"type", "reshape_crease"}, {"op", 3}, {"crease", crease},
          {"points", {{40.0, 0.0}, {60.0, 50.0}, {75.0, 100.0}, {60.0, 150.0}}}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  scene = e.session->sceneJson();
  EXPECT_EQ(scene["model"]["drawing"]["strokes"][crease]["points"].size(), 4u);
  EXPECT_GE(scene["model"]["faces"].size(), 2u);

  e.send({{"type", "erase_crease"}, {"op", 4}, {"crease", crease}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  scene = e.session->sceneJson();
  EXPECT_EQ(strokeCount(scene), outline);
  EXPECT_EQ(scene["model"]["faces"].size(), 1u);

  for (int op = 5; op < 7; ++op) e.send({{"type", "undo"}, {"op", op}});  // erase, reshape
  e.send({{"type", "undo"}, {"op", 7}});                                     // relabel
  EXPECT_EQ(e.session->sceneJson()["model"]["drawing"], valley["model"]["drawing"]);
  EXPECT_EQ(e.session->sceneJson()["model"]["faces"], valley["model"]["faces"]);
  e.send({{"type", "redo"}, {"op", 8}});
  EXPECT_EQ(e.session->sceneJson()["model"]["drawing"]["strokes"][crease]["assignment"], "M");

  // A restart replays the journal onto the blank sheet: the same drawing.
  ManualExecutor ex2;
  auto restored = std::make_shared<Session>("d1", blankSheet(), Session::Tokens{tokenHash("edit-token"), tokenHash("view-token")},
                                            SessionSettings{}, ex2.scheduler(), nullptr, nullptr);
  restored->restore(nullptr, 0, e.journal.edits, e.journal.edits.back().first);
  EXPECT_EQ(restored->sceneJson()["model"]["drawing"], e.session->sceneJson()["model"]["drawing"]);
}

TEST(SessionDrawing, RefusedLayoutEditsNameTheirFieldAndChangeNothing) {
  ExampleEditor e(blankSheet());
  const std::size_t outline = strokeCount(e.session->sceneJson());
  e.send(drawMessage(1, {{0.0, 75.0}, {200.0, 75.0}}, false, "V"));  // a crease across
  e.send(drawMessage(2, {{100.0, 0.0}, {100.0, 75.0}}, false, "M"));  // one ending on it
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  const json good = e.session->sceneJson();
  const std::size_t journalled = e.journal.edits.size();
  struct Case {
    json message;
    std::string path;
  };
  const std::vector<Case> cases = {
      {drawMessage(10, {{0.0, 20.0}, {120.0, 20.0}}, false, "V"), "points"},            // a free end mid-sheet
      {drawMessage(11, {{0.0, 20.0}, {300.0, 20.0}}, false, "V"), "points[1]"},         // outside the sheet
      {drawMessage(12, {{0.0, 20.0}, {50.0, 30.0}, {200.0, 20.0}}, false, "V"), "points"},  // straight with 3 points
      {drawMessage(13, {{0.0, 20.0}, {200.0, 20.0}}, true, "V"), "points"},             // curved with 2 points
      {drawMessage(14, {{0.0, 20.0}, {0.0, 20.0}}, false, "V"), "points[1]"},           // coinciding points
      {{{"type", "erase_crease"}, {"op", 15}, {"crease", 0}}, "crease"},                 // the outline
      {{{"type", "erase_crease"}, {"op", 16}, {"crease", 999}}, "crease"},               // no such stroke
      {{{"type", "erase_crease"}, {"op", 17}, {"crease", static_cast<int>(outline)}}, "crease"},  // another ends on it
      {{{"type", "relabel_crease"}, {"op", 18}, {"crease", static_cast<int>(outline)}, {"assignment", "B"}}, "assignment"},
      {{{"type", "reshape_crease"}, {"op", 19}, {"crease", static_cast<int>(outline) + 1},
        {"points", {{100.0, 0.0}, {100.0, 40.0}}}}, "points"},  // its end pulled off the other crease
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.message.dump());
    e.inbox.messages.clear();
    e.send(c.message);
    EXPECT_EQ(lastErrorPath(e.inbox), c.path) << e.inbox.last("error").dump();
    EXPECT_TRUE(e.session->sceneJson() == good) << "the scene changed";
  }
  EXPECT_EQ(e.journal.edits.size(), journalled);
  // Sessions without a drawing, and other kinds, say why.
  ExampleEditor preset("composite-two-creases");
  preset.send(drawMessage(1, {{0.0, 0.0}, {1.0, 1.0}}, false, "V"));
  EXPECT_EQ(lastErrorPath(preset.inbox), "type");
  EXPECT_NE(preset.inbox.last("error")["message"].get<std::string>().find("no drawing"), std::string::npos);
  ExampleEditor strip("strip-lifted-corner");
  strip.send({{"type", "erase_crease"}, {"op", 1}, {"crease", 0}});
  EXPECT_EQ(lastErrorPath(strip.inbox), "type");
}

/// A point on the outline of the blank sheet: side 0 bottom, 1 right, 2 top, 3 left, at t ∈ (0, 1).
json outlinePoint(int side, double t) {
  switch (side) {
    case 0: return {t * kSheetWidth, 0.0};
    case 1: return {kSheetWidth, t * kSheetHeight};
    case 2: return {t * kSheetWidth, kSheetHeight};
    default: return {0.0, t * kSheetHeight};
  }
}

TEST(SessionDrawing, RandomCreasesDrawnEdgeToEdgeEitherBuildAValidSheetOrAreRefusedWithNothingChanged) {
  // What a user draws: creases from one edge of the sheet to another, straight or through a few
  // clicked points, one to three per sheet, any assignment. Every one is either built (the scene
  // reads back, the drawing holds it, faces split) or refused naming a field, the scene unchanged.
  std::mt19937 rng(16003);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int built = 0, refused = 0;
  for (int sheet = 0; sheet < 100; ++sheet) {
    ExampleEditor e(blankSheet());
    const json blank = e.session->sceneJson();
    const int creases = 1 + static_cast<int>(unit(rng) * 3);
    for (int c = 0; c < creases; ++c) {
      const int from = static_cast<int>(unit(rng) * 4);
      const int to = (from + 1 + static_cast<int>(unit(rng) * 3)) % 4;
      json points = json::array({outlinePoint(from, 0.15 + 0.7 * unit(rng))});
      const bool curved = unit(rng) < 0.6;
      if (curved) {
        const int inner = 1 + static_cast<int>(unit(rng) * 3);
        const json a = points[0], b = outlinePoint(to, 0.15 + 0.7 * unit(rng));
        for (int k = 1; k <= inner; ++k) {
          const double s = static_cast<double>(k) / (inner + 1);
          const double x = (1 - s) * a[0].get<double>() + s * b[0].get<double>() + (unit(rng) - 0.5) * 0.15 * kSheetWidth;
          const double y = (1 - s) * a[1].get<double>() + s * b[1].get<double>() + (unit(rng) - 0.5) * 0.15 * kSheetHeight;
          points.push_back({std::clamp(x, 5.0, kSheetWidth - 5.0), std::clamp(y, 5.0, kSheetHeight - 5.0)});
        }
        points.push_back(b);
      } else {
        points.push_back(outlinePoint(to, 0.15 + 0.7 * unit(rng)));
      }
      static const char* kinds[] = {"M", "V", "V", "F"};
      const std::string kind = kinds[static_cast<int>(unit(rng) * 4)];
      const json before = e.session->sceneJson();
      e.inbox.messages.clear();
      e.send(drawMessage(100 + c, points, curved, kind, 30.0 + 150.0 * unit(rng)));
      const json after = e.session->sceneJson();
      SCOPED_TRACE("sheet " + std::to_string(sheet) + ", crease " + std::to_string(c) + ": " + points.dump());
      if (e.inbox.ofType("error").empty()) {
        ++built;
        EXPECT_EQ(strokeCount(after), strokeCount(before) + 1);
        if (kind != "F") {  // a flat line between planar faces merges them again
          EXPECT_GT(after["model"]["faces"].size(), 1u);
        }
        EXPECT_EQ(after["model"]["drawing"]["strokes"].back()["points"].size(), points.size());
        EXPECT_NO_THROW(proto::sceneFromJson(after));
        EXPECT_TRUE(e.inbox.last("update").is_object() || !e.inbox.ofType("solved").empty() || !e.inbox.ofType("ack").empty());
      } else {
        ++refused;
        if (std::getenv("DEVSURF_SHOW_REFUSALS")) std::printf("%s\n", e.inbox.last("error")["message"].get<std::string>().c_str());
        const json error = e.inbox.last("error");
        EXPECT_FALSE(error["path"].get<std::string>().empty());
        EXPECT_FALSE(error["message"].get<std::string>().empty());
        EXPECT_TRUE(after == before) << "the scene changed";
      }
    }
    // Undo all the way: the blank sheet again.
    for (int c = 0; c < creases; ++c) e.send({{"type", "undo"}, {"op", 200 + c}});
    EXPECT_EQ(e.session->sceneJson()["model"]["drawing"], blank["model"]["drawing"]);
  }
  std::printf("random creases: %d built, %d refused\n", built, refused);
  // Most plausible drawings build (a refusal is a layout the model has no valid strips for).
  EXPECT_GT(built, 4 * refused) << built << " built, " << refused << " refused";
}

}  // namespace
}  // namespace devsurf::server

namespace devsurf::server {
namespace {

/// What a mouse drag makes of a drawn sheet: two curved creases that do not cross (a valley and a
/// mountain, left edge to right edge), folded by the slider to 100 %, then a free corner pulled up
/// and out by a mouse drag. The corner's height before and after, and the last solved metrics.
struct DraggedDrawnSheet {
  double z0 = 0.0, z1 = 0.0;
  json metrics;
};

void dragAFoldedDrawnSheet(const proto::Scene& sheet, DraggedDrawnSheet& out) {
  // The daemon's own budgets: they count the solving thread's CPU time, so the machine's load
  // does not decide how far the drag gets (on wall time, a CI run's load once left the corner
  // 1.6 mm below where the fold had it, and once at 49.0 mm of a pull from 49.4 mm).
  ExampleEditor e(sheet);
  e.send(drawMessage(1, {{0.0, 45.0}, {50.0, 55.0}, {100.0, 60.0}, {150.0, 55.0}, {200.0, 45.0}}, true, "V"));
  e.send(drawMessage(2, {{0.0, 95.0}, {50.0, 105.0}, {100.0, 110.0}, {150.0, 105.0}, {200.0, 95.0}}, true, "M"));
  for (int k = 1; k <= 10; ++k) e.send({{"type", "fold"}, {"op", 10 + k}, {"amount", 0.1 * k}});
  e.send({{"type", "fold_end"}, {"op", 30}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  const json folded = e.session->sceneJson();
  // The free corner farthest from the fixed vertices: the top-left one (0, 150) of the drawing.
  int corner = -1;
  const json& dev = folded["model"]["development"]["vertices"];
  for (std::size_t v = 0; v < folded["model"]["vertices"].size() && v < dev.size(); ++v)
    if (std::abs(dev[v][0].get<double>()) < 1e-6 && std::abs(dev[v][1].get<double>() - kSheetHeight) < 1e-6) corner = static_cast<int>(v);
  ASSERT_GE(corner, 0);
  const json p0 = folded["model"]["vertices"][static_cast<std::size_t>(corner)];
  const double z0 = p0[2].get<double>();
  ASSERT_GT(std::abs(z0), 10.0);  // folded
  // Pulled 20 mm further up (z) and 10 mm out (−x), as a mouse sends it: 24 messages.
  json last;
  for (int k = 1; k <= 24; ++k) {
    const double s = k / 24.0;
    last = {p0[0].get<double>() - 10.0 * s, p0[1].get<double>(), z0 + (z0 > 0 ? 20.0 : -20.0) * s};
    e.send({{"type", "drag"}, {"op", 100 + k}, {"target", {{"vertex", corner}}}, {"position", last}});
  }
  e.send({{"type", "drag_end"}, {"op", 200}, {"target", {{"vertex", corner}}}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  const json after = e.session->sceneJson();
  const json p1 = after["model"]["vertices"][static_cast<std::size_t>(corner)];
  const json metrics = e.inbox.last("solved")["metrics"];
  std::printf("corner %d: (%.2f, %.2f, %.2f) → (%.2f, %.2f, %.2f), pulled to (%.2f, %.2f, %.2f); fold error %.3g°, development error %.3g\n",
              corner, p0[0].get<double>(), p0[1].get<double>(), z0, p1[0].get<double>(), p1[1].get<double>(), p1[2].get<double>(),
              last[0].get<double>(), last[1].get<double>(), last[2].get<double>(), metrics.value("fold_angle_error_max_deg", -1.0),
              metrics.value("development_length_error", -1.0));
  out = {z0, p1[2].get<double>(), metrics};
}

TEST(SessionDrawing, ADrawnSheetFoldedByTheSliderKeepsWhatADragMakesOfIt) {
  DraggedDrawnSheet d;
  dragAFoldedDrawnSheet(blankSheet(), d);
  if (::testing::Test::HasFatalFailure()) return;
  const json& metrics = d.metrics;
  // Still folded, and the corner kept part of the pull: not sprung back to the slider's fold, not
  // unfolded flat (before, the release's projections dropped the fold targets and walked the
  // sheet back to its flat drawing, 92° → 0°). The fold targets follow the drag: the corner
  // ends at 58.9 mm of a pull from 49.4 to 69.4 mm (57.4 mm with six busy loops on the two cores:
  // the budgets count the solving thread's CPU time). The sheet's lengths rest within 0.5 %:
  // measured 0.11–0.13 % (0.125 % idle, 0.109 % loaded this stop), with the developed sheet's drag
  // band of 1e-4 and two correction steps per drag step (SessionSettings); 0.42 % with the band
  // of 1e-3 and no corrections before (1.06 % under CI load) — docs/architecture.md "Drags of a
  // design folded by its targets". A sheet that unfolded or tore is far beyond this.
  EXPECT_GT(std::abs(d.z1), std::abs(d.z0) + 5.0);
  EXPECT_LT(metrics["development_length_error"].get<double>(), 5e-3);
  EXPECT_LT(metrics["fold_angle_error_max_deg"].get<double>(), 1.0);
  EXPECT_EQ(metrics["development_flipped_faces"].get<int>(), 0);
}

TEST(SessionDrawing, WithTheRulingCreaseRowsTheSameDragStillFollowsThePointer) {
  // `crease_normals: ruling` (a drawn sheet this size keeps the free rows under `auto`): its
  // developed drag runs at SessionSettings::developedDragHardBandRulingCreases (3e-4). At 1e-4 this
  // drag stalled (the corner stayed at 49.4 mm of a pull from 49.4 to 69.4 mm); at 3e-4 it
  // measured 53.2–53.7 mm and lengths within 0.20–0.23 % (53.5–53.7 mm and 0.22–0.23 % in
  // dragAFoldedDrawnSheet, idle and with six busy loops on the two cores).
  proto::Scene sheet = blankSheet();
  sheet.solver.creaseNormals = "ruling";
  DraggedDrawnSheet d;
  dragAFoldedDrawnSheet(sheet, d);
  if (::testing::Test::HasFatalFailure()) return;
  EXPECT_GT(std::abs(d.z1), std::abs(d.z0) + 1.5);  // not stalled: 3.8–4.3 mm measured, a stall 0
  EXPECT_LT(d.metrics["development_length_error"].get<double>(), 5e-3);
  EXPECT_LT(d.metrics["fold_angle_error_max_deg"].get<double>(), 1.0);
  EXPECT_EQ(d.metrics["development_flipped_faces"].get<int>(), 0);
}

}  // namespace
}  // namespace devsurf::server

namespace devsurf::server {
namespace {

// A drawn sheet still flat (the slider at 0 %) whose free corner is pulled up by a mouse: its fold
// targets held every crease at 0° while the point was pulled, so the corner stayed on the table
// (stop 50's "drags that do not move"). The targets now let go during the drag as they do at any
// amount, and the release moves the slider to what the drag folded: the sheet stays folded, with
// its lengths, and the slider then folds it on from there.
TEST(SessionDrawing, AFlatDrawnSheetFoldsUnderADragOfAFreeCornerAndTheSliderMovesWithIt) {
  for (const bool curved : {true, false}) {
    SCOPED_TRACE(curved ? "a curved valley" : "a straight valley");
    ExampleEditor e(blankSheet());
    if (curved)
      e.send(drawMessage(1, {{0.0, 60.0}, {70.0, 85.0}, {130.0, 65.0}, {200.0, 90.0}}, true, "V"));
    else
      e.send(drawMessage(1, {{0.0, 75.0}, {200.0, 75.0}}, false, "V"));
    ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
    const json flat = e.session->sceneJson();
    ASSERT_EQ(flat["model"].value("fold_amount", 1.0), 0.0);
    // A corner of the sheet away from the fixed face: the first whose drag lifts it (a corner beside
    // the fixed face rises only as far as the sheet bends there).
    const json& dev = flat["model"]["development"]["vertices"];
    int corner = -1;
    for (const auto& [x, y] : {std::pair{kSheetWidth, 0.0}, {kSheetWidth, kSheetHeight}, {0.0, 0.0}, {0.0, kSheetHeight}}) {
      for (std::size_t v = 0; v < dev.size() && corner < 0; ++v)
        if (std::abs(dev[v][0].get<double>() - x) < 1e-6 && std::abs(dev[v][1].get<double>() - y) < 1e-6) {
          bool fixed = false;
          for (const json& f : flat["model"].value("fixed", json::array())) fixed = fixed || f.value("vertex", -1) == static_cast<int>(v);
          if (!fixed) corner = static_cast<int>(v);
        }
      if (corner >= 0) {
        // The drag must be able to move it: try it, and take it if it left the table.
        const json p0 = flat["model"]["vertices"][static_cast<std::size_t>(corner)];
        for (int k = 1; k <= 40; ++k)
          e.send({{"type", "drag"}, {"op", 100 + k}, {"target", {{"vertex", corner}}},
                  {"position", {p0[0].get<double>(), p0[1].get<double>(), 80.0 * k / 40.0}}});
        e.send({{"type", "drag_end"}, {"op", 200}, {"target", {{"vertex", corner}}}});
        ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
        if (std::abs(e.session->sceneJson()["model"]["vertices"][static_cast<std::size_t>(corner)][2].get<double>()) > 20.0) break;
        e.send({{"type", "undo"}, {"op", 300}});
        corner = -1;
      }
    }
    ASSERT_GE(corner, 0) << "no corner of the flat sheet followed a drag up by more than 20 mm of 80";
    const json after = e.session->sceneJson();
    const json metrics = e.inbox.last("solved")["metrics"];
    // What a client holds (and saves to a file): the scene of the last `update` before the last
    // `solved` carries the targets and the amount the release took from the drag, as the session
    // has them. Before, no update followed the release: a saved file paired the amount of the
    // fold with the targets from before the drag (flat here: no amount at all).
    {
      json clientScene;
      for (const json& m : e.inbox.messages) {
        if (m.value("type", "") == "update" || m.value("type", "") == "state") clientScene = m["scene"];
      }
      ASSERT_TRUE(clientScene.is_object());
      EXPECT_EQ(clientScene["model"].value("fold_amount", 0.0), after["model"].value("fold_amount", 0.0));
      EXPECT_EQ(clientScene["model"]["fold_angles"], after["model"]["fold_angles"]);
      EXPECT_EQ(clientScene["model"]["vertices"], after["model"]["vertices"]);
    }
    const double z = after["model"]["vertices"][static_cast<std::size_t>(corner)][2].get<double>();
    const double amount = after["model"].value("fold_amount", 1.0);
    std::printf("%s: corner %d pulled 80 mm up → z %.1f mm; fold amount %.3f, largest fold %.1f°, fold error %.3g°, "
                "development error %.3g\n",
                curved ? "curved" : "straight", corner, z, amount, metrics["crease_fold_angle_max_deg"].get<double>(),
                metrics["fold_angle_error_max_deg"].get<double>(), metrics["development_length_error"].get<double>());
    EXPECT_GT(amount, 0.1);
    EXPECT_LE(amount, 1.0);
    EXPECT_GT(metrics["crease_fold_angle_max_deg"].get<double>(), 10.0);
    EXPECT_LT(metrics["fold_angle_error_max_deg"].get<double>(), 1.0);  // the slider holds what the drag folded
    EXPECT_LT(metrics["development_length_error"].get<double>(), 5e-3);
    EXPECT_TRUE(e.inbox.last("solved")["quality"]["met"].get<bool>()) << e.inbox.last("solved")["quality"].dump();
    // The slider takes it on to 100 % from there.
    for (int k = 1; k <= 5; ++k) e.send({{"type", "fold"}, {"op", 400 + k}, {"amount", amount + (1.0 - amount) * k / 5.0}});
    e.send({{"type", "fold_end"}, {"op", 410}});
    ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
    const json full = e.inbox.last("solved")["metrics"];
    EXPECT_DOUBLE_EQ(full["fold_amount"].get<double>(), 1.0);
    EXPECT_GT(full["crease_fold_angle_max_deg"].get<double>(), metrics["crease_fold_angle_max_deg"].get<double>());
  }
}


// The same pull on a sheet whose crease is a mountain folds it the other way (as a valley): the
// drag leaves the slider at 0 % and the release holds the targets, so the sheet goes back flat —
// before, it stayed folded at 0 %, its quality missed (fold-angle error 40° of a 1° limit), and
// the next solve snapped it flat (a reviewer's case).
TEST(SessionDrawing, AFlatSheetPulledAgainstItsCreasesLetterGoesBackFlatAtZeroPercent) {
  ExampleEditor e(blankSheet());
  e.send(drawMessage(1, {{0.0, 75.0}, {200.0, 75.0}}, false, "M"));
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  const json flat = e.session->sceneJson();
  const json& dev = flat["model"]["development"]["vertices"];
  int corner = -1;
  for (std::size_t v = 0; v < dev.size(); ++v)
    if (std::abs(dev[v][0].get<double>() - kSheetWidth) < 1e-6 && std::abs(dev[v][1].get<double>()) < 1e-6) corner = static_cast<int>(v);
  ASSERT_GE(corner, 0);
  const json p0 = flat["model"]["vertices"][static_cast<std::size_t>(corner)];
  double zMax = 0.0;
  for (int k = 1; k <= 40; ++k) {
    e.send({{"type", "drag"}, {"op", 100 + k}, {"target", {{"vertex", corner}}},
            {"position", {p0[0].get<double>(), p0[1].get<double>(), 80.0 * k / 40.0}}});
    zMax = std::max(zMax, e.session->sceneJson()["model"]["vertices"][static_cast<std::size_t>(corner)][2].get<double>());
  }
  e.send({{"type", "drag_end"}, {"op", 200}, {"target", {{"vertex", corner}}}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  const json after = e.session->sceneJson();
  const json solved = e.inbox.last("solved");
  const double z = after["model"]["vertices"][static_cast<std::size_t>(corner)][2].get<double>();
  std::printf("mountain pulled as a valley: corner up to %.1f mm during the drag, %.3g mm after the release; amount %g\n",
              zMax, z, after["model"].value("fold_amount", 1.0));
  EXPECT_EQ(after["model"].value("fold_amount", 1.0), 0.0);
  EXPECT_LT(std::abs(z), 1.0);
  EXPECT_TRUE(solved["quality"]["met"].get<bool>()) << solved["quality"].dump();
}
}  // namespace
}  // namespace devsurf::server
