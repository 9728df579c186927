// `devsurf solve --fold-amount` on imported crease patterns, what the report's quality says of a
// fold that is missed or stretches the sheet, and the mountain/valley letters of a pattern folded
// flat (issue 16; a new user's tryout at stop 55).

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "server/CliTesting.h"
#include "support/TempDir.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
using testing::CliRun;
using testing::runCommand;

/// A scene imported from an SVG drawing written to `dir`.
json importedSvg(const devsurf::testing::TempDir& dir, const std::string& name, const std::string& svg) {
  const std::string path = (dir.path() / (name + ".svg")).string();
  std::ofstream(path) << svg;
  const CliRun imported = runCommand({"import", path});
  EXPECT_EQ(imported.code, 0) << imported.err;
  return imported.code == 0 ? json::parse(imported.out) : json();
}

/// The check of `metric` in a report's quality (null if there is none).
json qualityCheck(const json& report, const std::string& metric) {
  for (const json& c : report["quality"]["checks"])
    if (c["metric"] == metric) return c;
  return json();
}

// Two straight creases across a square at full opacity (Origami Simulator's 180°): red mountain at
// x = 20, blue valley at x = 40.
const char* kFlatFoldedPleat = R"(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
  <rect width="100" height="100" fill="none" stroke="#000000"/>
  <line x1="20" y1="0" x2="20" y2="100" stroke="#ff0000"/>
  <line x1="40" y1="0" x2="40" y2="100" stroke="#0000ff"/>
</svg>)";

TEST(SolveFoldAmount, APatternFoldedFlatKeepsItsMountainsAndValleysInItsFoldAndSvgExports) {
  // At 180° a measured fold angle is as readily +180° as −180°: the exports wrote the mountain as
  // a valley (and swapped both in a pleat) before they took the turn nearer the design.
  devsurf::testing::TempDir dir;
  const json scene = importedSvg(dir, "pleat", kFlatFoldedPleat);
  ASSERT_FALSE(scene.is_null());
  const std::string scenePath = (dir.path() / "pleat.json").string();
  std::ofstream(scenePath) << scene.dump();
  const std::string fold = (dir.path() / "pleat.fold").string(), svg = (dir.path() / "pleat-pattern.svg").string();
  const CliRun solved = runCommand({"solve", scenePath, "--fold-amount", "100%", "--iterations", "200", "--export",
                                    "fold:" + fold, "--export", "svg:" + svg});
  ASSERT_EQ(solved.code, 0) << solved.err;
  const json report = json::parse(solved.out);
  EXPECT_GT(report["metrics"]["crease_fold_angle_max_deg"].get<double>(), 179.0);  // folded flat indeed

  std::ifstream foldFile(fold);
  const json pattern = json::parse(foldFile);
  const json& coords = pattern["vertices_coords"];
  int mountains = 0, valleys = 0;
  for (std::size_t e = 0; e < pattern["edges_vertices"].size(); ++e) {
    const json& ev = pattern["edges_vertices"][e];
    const double x0 = coords[ev[0].get<std::size_t>()][0].get<double>(), x1 = coords[ev[1].get<std::size_t>()][0].get<double>();
    const std::string letter = pattern["edges_assignment"][e];
    const double angle = pattern["edges_foldAngle"][e];
    if (std::abs(x0 - 20.0) < 1e-6 && std::abs(x1 - 20.0) < 1e-6) {
      EXPECT_EQ(letter, "M") << "edge " << e;
      EXPECT_LT(angle, -179.0) << "edge " << e;
      ++mountains;
    } else if (std::abs(x0 - 40.0) < 1e-6 && std::abs(x1 - 40.0) < 1e-6) {
      EXPECT_EQ(letter, "V") << "edge " << e;
      EXPECT_GT(angle, 179.0) << "edge " << e;
      ++valleys;
    }
  }
  EXPECT_GE(mountains, 1);
  EXPECT_GE(valleys, 1);
  // The SVG fold pattern: the mountain line left of the valley line, as drawn (the legend's line
  // samples, without a fold angle, aside).
  std::ifstream svgFile(svg);
  std::stringstream text;
  text << svgFile.rdbuf();
  auto firstX = [&text](const std::string& assignment) {
    const std::string svgText = text.str();
    const std::size_t at = svgText.find("<polyline class=\"" + assignment + "\"");
    if (at == std::string::npos) return std::nan("");
    const std::size_t points = svgText.find("points=\"", at);
    return std::stod(svgText.substr(points + 8));
  };
  const double mountainX = firstX("mountain"), valleyX = firstX("valley");
  ASSERT_TRUE(std::isfinite(mountainX) && std::isfinite(valleyX)) << text.str();
  EXPECT_LT(mountainX, valleyX);
}

TEST(SolveFoldAmount, TheAmountFoldsAnImportedPatternAsTheSliderWouldAndIsCheckedByName) {
  devsurf::testing::TempDir dir;
  const json scene = importedSvg(dir, "valley", R"(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
    <rect width="100" height="100" fill="none" stroke="#000"/>
    <line x1="50" y1="0" x2="50" y2="100" stroke="#0000ff" stroke-opacity="0.5"/></svg>)");
  ASSERT_FALSE(scene.is_null());
  EXPECT_EQ(scene["model"]["fold_amount"], 0.0);  // an import starts flat
  for (const auto& [amount, expected] : {std::pair<std::string, double>{"0.5", 45.0}, {"100%", 90.0}}) {
    SCOPED_TRACE(amount);
    const CliRun solved = runCommand({"solve", "-", "--fold-amount", amount, "--iterations", "60"}, scene.dump());
    ASSERT_EQ(solved.code, 0) << solved.err;
    const json report = json::parse(solved.out);
    EXPECT_NEAR(report["metrics"]["crease_fold_angle_max_deg"].get<double>(), expected, 0.5);
    EXPECT_TRUE(report["quality"]["met"].get<bool>()) << report["quality"].dump();
  }
  for (const std::string bad : {"1.5", "-0.1", "150%", "half", "", "nan"}) {
    const CliRun refused = runCommand({"solve", "-", "--fold-amount", bad}, scene.dump());
    EXPECT_EQ(refused.code, 2) << bad;
    EXPECT_NE(refused.err.find("--fold-amount"), std::string::npos) << refused.err;
  }
  // A design without fold angles, and another kind, say why.
  const CliRun strip = runCommand({"solve", testing::examplePath("strip-lifted-corner.json"), "--fold-amount", "1"});
  EXPECT_EQ(strip.code, 2);
  EXPECT_NE(strip.err.find("only a composite"), std::string::npos) << strip.err;
  const CliRun preset = runCommand({"solve", testing::examplePath("composite-two-creases.json"), "--fold-amount", "1"});
  EXPECT_EQ(preset.code, 2);
  EXPECT_NE(preset.err.find("model.fold_angles"), std::string::npos) << preset.err;
}

TEST(SolveFoldAmount, AFoldThatIsMissedOrTearsTheSheetDoesNotMeetItsQuality) {
  // Two S-shaped creases at ±90° (a new user's Inkscape drawing): the sheet stays nearly flat and
  // its short edges stretch several times over. The report said "quality met".
  devsurf::testing::TempDir dir;
  const json scene = importedSvg(dir, "s-curves", R"(<svg width="200mm" height="100mm" viewBox="0 0 200 100" xmlns="http://www.w3.org/2000/svg">
    <path d="m 0,0 h 200 v 100 h -200 z" style="fill:none;stroke:#000000"/>
    <path d="m 60,0 c 10,20 -10,30 0,50 s 10,30 0,50" style="fill:none;stroke:#0000ff;stroke-opacity:0.5"/>
    <path d="m 140,0 q 20,25 0,50 t 0,50" style="fill:none;stroke:#ff0000;stroke-opacity:0.5"/></svg>)");
  ASSERT_FALSE(scene.is_null());
  const CliRun solved = runCommand({"solve", "-", "--fold-amount", "1", "--iterations", "200", "--require-quality"},
                                   scene.dump());
  EXPECT_EQ(solved.code, 3) << solved.err;
  const json report = json::parse(solved.out);
  EXPECT_FALSE(report["quality"]["met"].get<bool>());
  const json fold = qualityCheck(report, "fold_angle_error_max_deg");
  const json strain = qualityCheck(report, "development_edge_strain_max");
  ASSERT_FALSE(fold.is_null()) << report["quality"].dump();
  ASSERT_FALSE(strain.is_null()) << report["quality"].dump();
  // Both are missed by far, not at the margin: the largest target is 90°, so the limit is 14.5°.
  EXPECT_DOUBLE_EQ(fold["limit"].get<double>(), 1.0 + 0.15 * 90.0);
  EXPECT_GT(fold["value"].get<double>(), 45.0);
  EXPECT_GT(strain["value"].get<double>(), 0.5);
  EXPECT_NE(solved.err.find("fold_angle_error_max_deg"), std::string::npos) << solved.err;
}

TEST(SolveFoldAmount, WithoutIterationsAFoldRunsAsLongAsASessionsReleaseAndReachesItsAngles) {
  // A preset exported as FOLD and imported: its scene asks for 20 iterations, which left a 53°
  // crease at 21° under `--fold-amount 1` (a new user's tryout).
  devsurf::testing::TempDir dir;
  const std::string fold = (dir.path() / "two-creases.fold").string();
  const CliRun exported = runCommand({"solve", std::string(DEVSURF_SOURCE_DIR) + "/examples/composite-two-creases.json",
                                      "--export", "fold:" + fold});
  ASSERT_EQ(exported.code, 0) << exported.err;
  const CliRun imported = runCommand({"import", fold});
  ASSERT_EQ(imported.code, 0) << imported.err;
  ASSERT_EQ(json::parse(imported.out)["solver"]["iterations"], 20);
  const CliRun solved = runCommand({"solve", "-", "--fold-amount", "1"}, imported.out);
  ASSERT_EQ(solved.code, 0) << solved.err;
  const json report = json::parse(solved.out);
  EXPECT_GT(report["iterations"].get<int>(), 20);
  const json check = qualityCheck(report, "fold_angle_error_max_deg");
  ASSERT_FALSE(check.is_null());
  EXPECT_TRUE(check["ok"].get<bool>()) << check.dump();
}

}  // namespace
}  // namespace devsurf::server
