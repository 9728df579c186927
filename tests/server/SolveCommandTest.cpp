#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "devsurf/io/QuadMesh.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/server/Cli.h"
#include "server/CliTesting.h"
#include "support/ExportChecks.h"

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

// The report carries the quality verdict a session's `solved` message carries. A sheet pulled to
// fold angles it cannot reach without stretching (two opposite arcs at ±90°, folded to 100 % in
// one solve) ends stretched: the report says so, a warning names the failed checks, and with
// --require-quality the exit status is 3. A shipped example meets its thresholds: exit 0.
TEST(SolveCommand, AResultThatMissesItsQualityThresholdsIsReportedAndRequireQualityExitsThree) {
  const CliRun good = runCommand({"solve", examplePath("composite-curved-fold.json"), "--require-quality"});
  ASSERT_EQ(good.code, 0) << good.err;
  const nlohmann::json goodReport = nlohmann::json::parse(good.out);
  EXPECT_TRUE(goodReport["quality"]["met"].get<bool>()) << goodReport["quality"].dump();
  EXPECT_EQ(good.err.find("warning"), std::string::npos) << good.err;

  const std::string svg = tempPath("arcs.svg"), scene = tempPath("arcs.json"), folded = tempPath("arcs-100.json");
  std::ofstream(svg) << R"(<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="100mm" viewBox="0 0 200 100">
    <rect x="0" y="0" width="200" height="100" fill="none" stroke="#000000"/>
    <path d="M 60 0 C 80 30, 80 70, 60 100" fill="none" stroke="#ff0000" stroke-opacity="0.5"/>
    <path d="M 140 0 C 120 30, 120 70, 140 100" fill="none" stroke="#0000ff" stroke-opacity="0.5"/></svg>)";
  ASSERT_EQ(runCommand({"import", svg, "--out", scene}).code, 0);
  nlohmann::json doc = nlohmann::json::parse(std::ifstream(scene));
  doc["model"]["fold_amount"] = 1.0;
  std::ofstream(folded) << doc.dump();
  const CliRun bad = runCommand({"solve", folded, "--iterations", "20"});
  ASSERT_EQ(bad.code, 0) << bad.err;
  const nlohmann::json report = nlohmann::json::parse(bad.out);
  const auto errors = proto::schemaRegistry().validate(report, "report.schema.json");
  EXPECT_TRUE(errors.empty()) << errors[0].toString();
  ASSERT_FALSE(report["quality"]["met"].get<bool>()) << report["metrics"].dump(1);
  for (const nlohmann::json& check : report["quality"]["checks"])
    if (!check["ok"].get<bool>())
      EXPECT_NE(bad.err.find(check["metric"].get<std::string>()), std::string::npos) << bad.err;
  EXPECT_NE(bad.err.find("warning: the result misses its quality thresholds"), std::string::npos) << bad.err;
  const CliRun strict = runCommand({"solve", folded, "--iterations", "20", "--require-quality"});
  EXPECT_EQ(strict.code, 3) << strict.err;
  EXPECT_FALSE(strict.out.empty()) << "the report is still written";
  for (const std::string& p : {svg, scene, folded}) std::remove(p.c_str());
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
  // development_edge_strain_max, recomputed from the file: each edge's length in the folded frame
  // against the crease pattern's.
  double strain = 0.0;
  const nlohmann::json& flat = doc["vertices_coords"];
  const nlohmann::json& folded = doc["file_frames"][0]["vertices_coords"];
  for (const nlohmann::json& e : doc["edges_vertices"]) {
    const int i = e[0], j = e[1];
    double l2 = 0.0, l3 = 0.0;
    for (int c = 0; c < 2; ++c) l2 += std::pow(flat[i][c].get<double>() - flat[j][c].get<double>(), 2);
    for (int c = 0; c < 3; ++c) l3 += std::pow(folded[i][c].get<double>() - folded[j][c].get<double>(), 2);
    strain = std::max(strain, std::abs(std::sqrt(l3) - std::sqrt(l2)) / std::sqrt(l2));
  }
  EXPECT_NEAR(report["metrics"]["development_edge_strain_max"].get<double>(), strain, 1e-9 + 1e-6 * strain);
  EXPECT_GT(strain, 0.0);
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

TEST(SolveCommand, EveryExportIsCheckedBeforeTheSolveAndOneThatFailsAfterItLeavesTheReportWritten) {
  const std::string report = tempPath("checked.json"), obj = tempPath("checked.obj");
  std::filesystem::remove(report);
  std::filesystem::remove(obj);
  // A format that does not apply to the kind, one that does not exist, a folder that does not:
  // refused before anything is solved or written.
  struct Refused {
    std::string spec, says;
  };
  for (const Refused& refused : {Refused{"fold:" + tempPath("x.fold"), "this scene is a strip"},
                                 Refused{"unfolding_obj:" + tempPath("x.obj"), "quad_mesh"},
                                 Refused{"bogus:" + tempPath("x.bogus"), "expected obj"},
                                 Refused{"json:" + tempPath("x.json"), "--out"},
                                 Refused{"obj:" + tempPath("no-such-folder") + "/x.obj", "does not exist"}}) {
    SCOPED_TRACE(refused.spec);
    const CliRun r = runCommand({"solve", examplePath("strip-twisted.json"), "--out", report, "--export", "obj:" + obj,
                                 "--export", refused.spec});
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(r.err.rfind("devsurf solve: --export ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(refused.says), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(report));
    EXPECT_FALSE(std::filesystem::exists(obj));
  }
  const CliRun noFolder = runCommand({"solve", examplePath("strip-twisted.json"), "--out",
                                      tempPath("no-such-folder") + "/r.json", "--export", "obj:" + obj});
  EXPECT_EQ(noFolder.code, 2);
  EXPECT_EQ(noFolder.err.rfind("devsurf solve: --out ", 0), 0u) << noFolder.err;
  EXPECT_FALSE(std::filesystem::exists(obj));
  // An export that fails once solved (its path is a folder): the report is written before it.
  const std::string folder = tempPath("a-folder");
  std::filesystem::create_directories(folder);
  const CliRun r = runCommand({"solve", examplePath("strip-twisted.json"), "--iterations", "3", "--out", report,
                               "--export", "obj:" + obj, "--export", "stl:" + folder});
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("the report is written"), std::string::npos) << r.err;
  const nlohmann::json written = nlohmann::json::parse(std::ifstream(report));
  EXPECT_TRUE(written.contains("metrics"));
  EXPECT_TRUE(std::filesystem::exists(obj));
  std::filesystem::remove(report);
  std::filesystem::remove(obj);
  std::filesystem::remove_all(folder);
}

/// From an OBJ file alone (read by the tests' own parser): the largest angle between the normals
/// of two faces sharing an edge (the polygon's vector area by the shoelace sum of its corners),
/// degrees, and how many exceed 30°.
std::pair<double, int> objFaceNormalAngles(const std::string& path) {
  std::ifstream in(path);
  const devsurf::testing::ObjMesh mesh =
      devsurf::testing::parseObj(std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()));
  std::vector<Eigen::Vector3d> normal(mesh.faces.size(), Eigen::Vector3d::Zero());
  std::map<std::pair<int, int>, std::vector<std::size_t>> shared;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const std::vector<int>& c = mesh.faces[f];
    for (std::size_t k = 0; k < c.size(); ++k) {
      const int a = c[k], b = c[(k + 1) % c.size()];
      normal[f] += mesh.vertices[static_cast<std::size_t>(a)].cross(mesh.vertices[static_cast<std::size_t>(b)]);
      shared[{std::min(a, b), std::max(a, b)}].push_back(f);
    }
  }
  double largest = 0.0;
  int sharp = 0;
  for (const auto& [edge, fs] : shared) {
    if (fs.size() != 2) continue;
    const Eigen::Vector3d &n0 = normal[fs[0]], &n1 = normal[fs[1]];
    const double degrees = std::acos(std::clamp(n0.dot(n1) / (n0.norm() * n1.norm()), -1.0, 1.0)) * 180.0 / M_PI;
    largest = std::max(largest, degrees);
    if (degrees > 30.0) ++sharp;
  }
  return {largest, sharp};
}

TEST(SolveCommand, AQuadMeshReportMeasuresTheCreasesItsExportedMeshShows) {
  // The exact cylinder: neighbouring quads 7.5° apart, none sharp.
  const std::string cylinder = tempPath("cylinder.obj");
  const CliRun exact = runCommand({"solve", examplePath("quad-cylinder-exact.json"), "--export", "obj:" + cylinder});
  ASSERT_EQ(exact.code, 0) << exact.err;
  const nlohmann::json metrics = nlohmann::json::parse(exact.out)["metrics"];
  EXPECT_NEAR(metrics["face_normal_angle_max_deg"].get<double>(), 7.5, 1e-6);
  EXPECT_EQ(metrics["sharp_edges"].get<int>(), 0);
  EXPECT_NEAR(objFaceNormalAngles(cylinder).first, 7.5, 1e-5);
  // A saddle made developable creases (Jiang et al. Fig. 8b); the report says as much as the file.
  const std::string saddle = tempPath("saddle.obj");
  const CliRun creased = runCommand({"solve", examplePath("quad-developable-approx.json"), "--export", "obj:" + saddle});
  ASSERT_EQ(creased.code, 0) << creased.err;
  const nlohmann::json m = nlohmann::json::parse(creased.out)["metrics"];
  const auto [largest, sharp] = objFaceNormalAngles(saddle);
  EXPECT_NEAR(m["face_normal_angle_max_deg"].get<double>(), largest, 1e-3);
  EXPECT_EQ(m["sharp_edges"].get<int>(), sharp);
  EXPECT_GT(sharp, 0);
  EXPECT_LT(m["face_normal_angle_max_deg_initial"].get<double>(), 5.0);  // the saddle as designed is smooth
  std::filesystem::remove(cylinder);
  std::filesystem::remove(saddle);
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
  const CliRun few = runCommand({"solve", examplePath("strip-twisted.json"), "--max-control-points", "3"});
  EXPECT_EQ(few.code, 2);
  EXPECT_NE(few.err.find("control points"), std::string::npos) << few.err;
  EXPECT_EQ(runCommand({"frobnicate"}).code, 2);
  EXPECT_EQ(runCommand({"help"}).code, 0);
}

TEST(Cli, EveryCommandInTheUsageAnswersHelpWithItsOwnPartOfTheUsageAndStartsNothing) {
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
      EXPECT_EQ(result.err, "") << command << " " << flag;
      if (command == "help") {  // its part is all of it
        EXPECT_EQ(result.out, usage);
        continue;
      }
      // Its own entries of the usage, each line as the full usage has it, and no other command's.
      EXPECT_EQ(result.out.rfind("usage: devsurf " + command, 0), 0u) << command << " " << flag << ": " << result.out;
      std::istringstream own(result.out);
      for (std::string line; std::getline(own, line);) {
        const std::string asListed = line.rfind("usage: devsurf ", 0) == 0 ? "  " + line.substr(15) : line;
        EXPECT_NE(usage.find(asListed + "\n"), std::string::npos) << command << ": " << line;
        if (line.rfind("usage: devsurf ", 0) == 0) EXPECT_EQ(line.rfind("usage: devsurf " + command, 0), 0u) << line;
      }
      EXPECT_LT(result.out.size(), usage.size() / 2) << command;
    }
  const auto late = runCommand({"solve", examplePath("strip-twisted.json"), "--iterations", "3", "--help"});
  EXPECT_EQ(late.code, 0);
  EXPECT_EQ(late.out.rfind("usage: devsurf solve SCENE", 0), 0u) << "help anywhere among the arguments, nothing solved";
  EXPECT_NE(late.out.find("--require-quality"), std::string::npos);
  EXPECT_EQ(late.out.find("serve [--port"), std::string::npos);
}

}  // namespace
}  // namespace devsurf::server
