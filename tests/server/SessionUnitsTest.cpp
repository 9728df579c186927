// The units setting (issue 16, item 4): "set_units" says what one coordinate of the design is; the
// numbers stay, the exports follow (read back from the exported files), undo and the journal keep it.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "devsurf/io/SvgImport.h"
#include "server/SessionTesting.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
using testing::ExampleEditor;

/// The width in millimetres of the sheet an exported fold-pattern SVG draws, read back by the SVG
/// crease-pattern reader (its black outline; the legend's lines dangle and are left out).
double sheetWidthMm(const std::string& svg) {
  const io::SvgImport drawing = io::importSvgText(svg);
  return drawing.pattern.vertices2d.col(0).maxCoeff() - drawing.pattern.vertices2d.col(0).minCoeff();
}

TEST(SessionUnits, SetUnitsRelabelsTheDesignAndTheExportsFollow) {
  ExampleEditor e("composite-two-creases");
  const json before = e.session->sceneJson();
  ASSERT_EQ(before.value("units", "mm"), "mm");
  const double widthMm = sheetWidthMm(e.session->exportAs("svg").content);
  e.send({{"type", "set_units"}, {"op", 1}, {"units", "cm"}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.ofType("error")[0].dump();
  const json after = e.session->sceneJson();
  EXPECT_EQ(after["units"], "cm");
  EXPECT_EQ(after["model"]["vertices"], before["model"]["vertices"]);  // the numbers stay

  // FOLD says so (frame_unit); the SVG is drawn at true size.
  const json fold = json::parse(e.session->exportAs("fold").content);
  EXPECT_EQ(fold["frame_unit"], "cm");
  // Drawn at true size: the sheet is ten times as wide as before.
  EXPECT_NEAR(sheetWidthMm(e.session->exportAs("svg").content), 10.0 * widthMm, 1e-3 * widthMm);
  EXPECT_GT(widthMm, 2.9);  // 3 units (the development of a folded sheet: a little over)

  // Undo brings millimetres back; the journal replays the change.
  e.send({{"type", "undo"}, {"op", 2}});
  EXPECT_EQ(e.session->sceneJson().value("units", "mm"), "mm");
  e.send({{"type", "redo"}, {"op", 3}});
  EXPECT_EQ(e.session->sceneJson()["units"], "cm");
}

TEST(SessionUnits, UnknownUnitsAreRefusedNamingTheFieldAndNothingChanges) {
  ExampleEditor e("strip-lifted-corner");
  e.send({{"type", "set_units"}, {"op", 1}, {"units", "furlong"}});
  const auto errors = e.inbox.ofType("error");
  ASSERT_FALSE(errors.empty());
  EXPECT_EQ(errors.back()["path"], "units") << errors.back().dump();
  EXPECT_EQ(e.session->sceneJson().value("units", "mm"), "mm");
}

}  // namespace
}  // namespace devsurf::server
