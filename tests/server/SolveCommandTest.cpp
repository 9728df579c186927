#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "devsurf/io/QuadMesh.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/server/Cli.h"
#include "server/CliTesting.h"

namespace devsurf::server {
namespace {

using testing::CliRun;
using testing::examplePath;
using testing::runCommand;

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("devsurf_cli_" + std::to_string(::getpid()) + "_" + name)).string();
}

TEST(SolveCommand, WritesAValidReportForTheTwistedStripExample) {
  const CliRun r = runCommand({"solve", examplePath("strip-twisted.json")});
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  const auto errors = proto::schemaRegistry().validate(report, "report.schema.json");
  EXPECT_TRUE(errors.empty()) << errors[0].toString();
  EXPECT_LT(report["metrics"]["warp_angle_max_deg"].get<double>(), 0.05);
  EXPECT_LE(report["iterations"].get<int>(), 20);
  EXPECT_EQ(report["history"].size(), report["iterations"].get<std::size_t>() + 1);
  // The solved scene is valid input again, with the same structure.
  const proto::Scene again = proto::sceneFromJson(report["scene"]);
  EXPECT_EQ(std::get<models::strip::StripDesign>(again.model).b.points.rows(), 7);
}

TEST(SolveCommand, HonoursIterationsOutAndExport) {
  const std::string reportPath = tempPath("report.json");
  const std::string objPath = tempPath("surface.mesh");  // any name: the format says OBJ
  const CliRun r = runCommand({"solve", examplePath("strip-lifted-corner.json"), "--iterations", "3", "--out",
                     reportPath, "--export", "obj:" + objPath});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  std::ifstream file(reportPath);
  const nlohmann::json report = nlohmann::json::parse(file);
  EXPECT_EQ(report["iterations"], 3);
  std::filesystem::copy_file(objPath, objPath + ".obj", std::filesystem::copy_options::overwrite_existing);
  const io::QuadMesh mesh = io::readQuadMesh(objPath + ".obj");
  EXPECT_EQ(mesh.vertices.rows(), 200 * 8);
  EXPECT_EQ(mesh.quads.rows(), 199 * 7);
  for (const std::string& p : {reportPath, objPath, objPath + ".obj"}) std::remove(p.c_str());
}

TEST(SolveCommand, ExportsTheFoldPatternOfACompositeWithADevelopment) {
  const std::string fold = tempPath("pattern.fold"), svg = tempPath("pattern.svg");
  const CliRun r = runCommand({"solve", examplePath("composite-curved-fold.json"), "--export", "fold:" + fold,
                        "--export", "svg:" + svg});
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  EXPECT_LT(report["metrics"]["development_length_error"].get<double>(), 1e-3);
  EXPECT_LT(report["metrics"]["warp_angle_max_deg"].get<double>(), 0.05);
  const nlohmann::json doc = nlohmann::json::parse(std::ifstream(fold));
  EXPECT_EQ(doc["file_spec"], 1.2);
  int creases = 0;
  for (std::size_t e = 0; e < doc["edges_assignment"].size(); ++e) {
    const std::string a = doc["edges_assignment"][e];
    if (a == "M" || a == "V") {
      ++creases;
      const double angle = doc["edges_foldAngle"][e];
      EXPECT_EQ(a == "V", angle > 0) << "FOLD: valley folds have positive angles";
    }
  }
  EXPECT_GT(creases, 0);
  std::ifstream svgFile(svg);
  const std::string text((std::istreambuf_iterator<char>(svgFile)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("<svg"), std::string::npos);
  EXPECT_NE(text.find("curve-"), std::string::npos);
  // Without a development there is no fold pattern.
  nlohmann::json plain;
  std::ifstream(examplePath("composite-two-creases.json")) >> plain;
  plain["model"].erase("development");
  const std::string plainPath = svg + ".scene.json";
  std::ofstream(plainPath) << plain.dump();
  const CliRun no = runCommand({"solve", plainPath, "--export", "svg:" + svg});
  std::remove(plainPath.c_str());
  EXPECT_EQ(no.code, 2);
  EXPECT_NE(no.err.find("development"), std::string::npos);
  for (const std::string& p : {fold, svg}) std::remove(p.c_str());
}

TEST(SolveCommand, AnExportTheSolvedStateCannotProduceExitsWithTwoNamingTheOptionAndTheReason) {
  // The development pinned to the mirror image of the sheet's corners: its faces turn clockwise,
  // which no crease pattern accepts.
  nlohmann::json doc = nlohmann::json::parse(std::ifstream(examplePath("composite-curved-fold.json")));
  nlohmann::json corners = nlohmann::json::array();
  for (int v : {0, 2, 3, 5}) {
    const nlohmann::json& p = doc["model"]["vertices"][static_cast<std::size_t>(v)];
    corners.push_back({{"vertex", v}, {"at", {-p[0].get<double>(), p[1].get<double>()}}});
  }
  doc["model"]["development"] = {{"samples", 4}, {"domain", {{"corners", corners}}}};
  const std::string svg = tempPath("mirrored.svg");
  const CliRun r = runCommand({"solve", "-", "--iterations", "2", "--export", "svg:" + svg}, doc.dump());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.rfind("devsurf solve: --export svg: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("not a valid crease pattern"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("counter-clockwise"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(svg));
}

TEST(SolveCommand, TheScenesUnitsSetTheFoldFrameUnitAndTheSvgsTrueSize) {
  nlohmann::json doc = nlohmann::json::parse(std::ifstream(examplePath("composite-curved-fold.json")));
  auto exportIn = [&doc](const std::string& units) {
    nlohmann::json scene = doc;
    if (!units.empty()) scene["units"] = units;
    const std::string fold = tempPath(units + "units.fold"), svg = tempPath(units + "units.svg");
    const CliRun r = runCommand({"solve", "-", "--iterations", "3", "--export", "fold:" + fold, "--export", "svg:" + svg},
                         scene.dump());
    EXPECT_EQ(r.code, 0) << r.err;
    std::pair<nlohmann::json, std::string> out{nlohmann::json::parse(std::ifstream(fold)), ""};
    std::ifstream in(svg);
    out.second.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    std::remove(fold.c_str());
    std::remove(svg.c_str());
    return out;
  };
  // Width of the boundary (every polyline of its group) in the SVG's user units, millimetres.
  auto boundaryWidth = [](const std::string& svg) {
    const std::size_t group = svg.find("<g id=\"boundary\"");
    const std::size_t end = svg.find("</g>", group);
    double lo = 1e300, hi = -1e300;
    for (std::size_t at = svg.find("points=\"", group); at < end; at = svg.find("points=\"", at)) {
      at += 8;
      std::istringstream points(svg.substr(at, svg.find('"', at) - at));
      double x, y;
      char comma;
      while (points >> x >> comma >> y) lo = std::min(lo, x), hi = std::max(hi, x);
    }
    return hi - lo;
  };
  const auto [mm, mmSvg] = exportIn("");
  const auto [cm, cmSvg] = exportIn("cm");
  const auto [in, inSvg] = exportIn("in");
  EXPECT_EQ(mm["frame_unit"], "mm");  // design units are millimetres by default
  EXPECT_EQ(cm["frame_unit"], "cm");
  EXPECT_EQ(in["frame_unit"], "in");
  EXPECT_EQ(cm["file_frames"][0]["frame_unit"], "cm");
  EXPECT_EQ(cm["devsurf:unitToMm"], 10.0);
  EXPECT_EQ(in["devsurf:unitToMm"], 25.4);
  // FOLD keeps the design's numbers and names their unit.
  EXPECT_EQ(cm["vertices_coords"], mm["vertices_coords"]);
  EXPECT_EQ(in["file_frames"][0]["vertices_coords"], mm["file_frames"][0]["vertices_coords"]);
  // The SVG draws at true size: the same sheet is 10× (25.4×) as wide in cm (in) as in mm.
  const double w = boundaryWidth(mmSvg);
  EXPECT_GT(w, 1.0);
  EXPECT_NEAR(boundaryWidth(cmSvg), 10.0 * w, 1e-2);  // 4 decimals
  EXPECT_NEAR(boundaryWidth(inSvg), 25.4 * w, 1e-2);
}

TEST(SolveCommand, ReadsTheSceneFromStandardInput) {
  std::ifstream file(examplePath("strip-cylinder.json"));
  std::stringstream text;
  text << file.rdbuf();
  const CliRun r = runCommand({"solve", "-"}, text.str());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_LT(nlohmann::json::parse(r.out)["metrics"]["displacement_max_b"].get<double>(), 1e-9);
}

TEST(SolveCommand, BadInputExitsWithTwoAndNamesTheField) {
  const CliRun notJson = runCommand({"solve", "-"}, "{ this is not json");
  EXPECT_EQ(notJson.code, 2);
  EXPECT_NE(notJson.err.find("not valid JSON"), std::string::npos) << notJson.err;

  nlohmann::json doc = nlohmann::json::parse(std::ifstream(examplePath("strip-twisted.json")));
  doc["model"]["a"]["points"][3] = {1, 2};
  const CliRun badPoint = runCommand({"solve", "-"}, doc.dump());
  EXPECT_EQ(badPoint.code, 2);
  EXPECT_NE(badPoint.err.find("model.a.points[3]: expected 3 numbers"), std::string::npos) << badPoint.err;

  EXPECT_EQ(runCommand({"solve"}).code, 2);
  EXPECT_EQ(runCommand({"solve", "/nonexistent.json"}).code, 2);
  EXPECT_EQ(runCommand({"solve", examplePath("strip-twisted.json"), "--iterations", "many"}).code, 2);
  EXPECT_EQ(runCommand({"solve", examplePath("strip-twisted.json"), "--export", "dwg:x.dwg"}).code, 2);
  EXPECT_EQ(runCommand({"frobnicate"}).code, 2);
  EXPECT_EQ(runCommand({"help"}).code, 0);
}

TEST(Cli, EveryCommandInTheUsageAnswersHelpWithTheUsageAndStartsNothing) {
  const std::string usage = runCommand({"help"}).out;
  std::istringstream lines(usage.substr(usage.find("commands:")));
  std::vector<std::string> commands;
  for (std::string line; std::getline(lines, line);)
    if (line.size() > 2 && line.rfind("  ", 0) == 0 && line[2] != ' ')  // "  solve SCENE …", not its text
      commands.push_back(line.substr(2, line.find(' ', 2) - 2));
  EXPECT_GE(commands.size(), 8u) << usage;
  for (const std::string& command : commands)
    for (const std::string flag : {"--help", "-h"}) {
      const auto result = runCommand({command, flag});
      EXPECT_EQ(result.code, 0) << command << " " << flag << ": " << result.err;
      EXPECT_EQ(result.out, usage) << command << " " << flag;
      EXPECT_EQ(result.err, "") << command << " " << flag;
    }
  const auto late = runCommand({"solve", examplePath("strip-twisted.json"), "--iterations", "3", "--help"});
  EXPECT_EQ(late.code, 0);
  EXPECT_EQ(late.out, usage) << "help anywhere among the arguments, nothing solved";
}

}  // namespace
}  // namespace devsurf::server
