// `devsurf cover` (issue 15, 000_… Fig. 10d–e): the back of CGAL's bunny covered by strips side by
// side, made one composite and solved. Distances are measured twice: by `solve --reference` and,
// independently, from the region's points to the exported STL read back through OpenMesh.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "devsurf/reference/ReferenceShape.h"
#include "devsurf/reference/SurfaceDistance.h"
#include "devsurf/server/ShapeFitting.h"
#include "devsurf/spline/BSplineCurve.h"
#include "server/CliTesting.h"
#include "support/TempDir.h"

namespace devsurf::server {
namespace {

using testing::CliRun;
using testing::runCommand;

std::string cgalData(const devsurf::testing::TempDir& dir, const std::string& member) {
  const std::string command = "tar -xzf /usr/share/doc/libcgal-dev/data.tar.gz -C '" + dir.str() + "' '" + member +
                              "' 2>/dev/null";
  EXPECT_EQ(std::system(command.c_str()), 0) << "libcgal-demo's data (scripts/setup.sh installs it): " << member;
  return (dir.path() / member).string();
}

TEST(CoverCommand, CoversTheBunnysBackWithEightStripsThatSolveAsOneComposite) {
  devsurf::testing::TempDir dir;
  const std::string bunny = cgalData(dir, "data/meshes/bunny00.off");
  const std::string scene = (dir.path() / "cover.json").string(), region = (dir.path() / "region.xyz").string(),
                    report = (dir.path() / "report.json").string(), stl = (dir.path() / "cover.stl").string();
  // The bunny's back (a ball of radius 0.35 on a bunny 1 wide), eight strips: docs/cover-bunny.png.
  const CliRun cover = runCommand({"cover", bunny, "--centre", "0.187,0.119,0.014", "--radius", "0.35", "--strips",
                                   "8", "--region-out", region, "--out", scene});
  ASSERT_EQ(cover.code, 0) << cover.err;
  EXPECT_EQ(cover.err.find("warning"), std::string::npos) << cover.err;
  const nlohmann::json summary = nlohmann::json::parse(cover.out);
  ASSERT_EQ(summary["pairings"].size(), 7u);
  const nlohmann::json document = nlohmann::json::parse(std::ifstream(scene));
  EXPECT_EQ(document["model"]["kind"], "composite");
  EXPECT_EQ(document["model"]["faces"].size(), 8u);

  const CliRun solve = runCommand({"solve", scene, "--reference", region, "--out", report, "--export", "stl:" + stl});
  ASSERT_EQ(solve.code, 0) << solve.err;
  const nlohmann::json metrics = nlohmann::json::parse(std::ifstream(report))["metrics"];
  const reference::ReferenceShape points = reference::readReferenceShape(region);
  const double diagonal = points.diagonal();
  std::printf("bunny back, 8 strips: warp %.3g°, flatness %.3g, RMS %.3g %% max %.3g %% of the region's diagonal, "
              "coverage %.3f within 1 %%\n",
              metrics["warp_angle_max_deg"].get<double>(), metrics["face_flatness_max"].get<double>(),
              100 * metrics["reference_distance_rms_relative"].get<double>(),
              100 * metrics["reference_distance_max_relative"].get<double>(), metrics["reference_coverage"].get<double>());
  EXPECT_LE(metrics["warp_angle_max_deg"].get<double>(), 0.05);
  EXPECT_LE(metrics["reference_distance_rms_relative"].get<double>(), 0.01);
  EXPECT_GE(metrics["reference_coverage"].get<double>(), 0.85);
  // Independently: the exported triangles read back, distances from the region's points.
  const reference::ReferenceShape surface = reference::readReferenceShape(stl);
  ASSERT_GT(surface.triangles.rows(), 0);
  const reference::SurfaceDistance d =
      reference::surfaceDistance(points.points, surface.points, surface.triangles, 0.01 * diagonal);
  EXPECT_NEAR(d.rmsDistance, metrics["reference_distance_rms"].get<double>(), 0.1 * d.rmsDistance);
  EXPECT_LE(d.rmsDistance, 0.01 * diagonal);
}

/// An S edge of a composite scene's JSON as a B-spline, read here (not through proto/): the scene
/// lists its interior control points, its ends are the edge's vertices, knots uniform unless given.
spline::BSplineCurve sceneEdgeCurve(const nlohmann::json& model, const nlohmann::json& edge) {
  std::vector<nlohmann::json> points{model["vertices"][edge["v"][0].get<std::size_t>()]};
  for (const auto& p : edge["points"]) points.push_back(p);
  points.push_back(model["vertices"][edge["v"][1].get<std::size_t>()]);
  spline::BSplineCurve curve;
  curve.points.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t k = 0; k < points.size(); ++k)
    for (int c = 0; c < 3; ++c) curve.points(static_cast<Eigen::Index>(k), c) = points[k][c].get<double>();
  const int degree = edge["degree"].get<int>(), n = static_cast<int>(points.size());
  curve.knots = edge.contains("knots") ? spline::KnotVector::clamped(degree, edge["knots"].get<std::vector<double>>(), n)
                                       : spline::KnotVector::clampedUniform(degree, n);
  return curve;
}

/// The shipped cover of the bunny's back exports its flat pieces: read back from the SVG (lines
/// parsed here), each seam's two glue chains have the length of the 3D curve they were cut from
/// (evaluated here from the scene's B-spline), and FOLD, a crease pattern, is refused.
TEST(CoverCommand, TheCoversPiecesExportAsACuttingPatternWhoseSeamsMatchTheirCurves) {
  devsurf::testing::TempDir dir;
  const std::string preset = std::string(DEVSURF_SOURCE_DIR) + "/examples/composite-cover-bunny.json";
  const std::string svg = (dir.path() / "pieces.svg").string(), report = (dir.path() / "r.json").string();
  nlohmann::json scene = nlohmann::json::parse(std::ifstream(preset));
  scene["solver"]["iterations"] = 0;  // the shipped state, as drawn
  const std::string sceneFile = (dir.path() / "cover.json").string();
  std::ofstream(sceneFile) << scene.dump();
  const CliRun run = runCommand({"solve", sceneFile, "--out", report, "--export", "svg:" + svg});
  ASSERT_EQ(run.code, 0) << run.err;
  std::ifstream in(svg);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // <line class="glue" data-v0="a" data-v1="b" data-seam="k" x1 y1 x2 y2/> → per seam, its edges.
  std::map<int, std::vector<std::pair<std::array<int, 2>, double>>> seams;
  std::size_t at = 0;
  while ((at = text.find("<line class=\"glue\"", at)) != std::string::npos) {
    const std::size_t end = text.find("/>", at);
    const std::string line = text.substr(at, end - at);
    auto attr = [&line](const std::string& name) {
      const std::size_t p = line.find(" " + name + "=\"") + name.size() + 3;
      return std::stod(line.substr(p, line.find('"', p) - p));
    };
    const double length = std::hypot(attr("x2") - attr("x1"), attr("y2") - attr("y1"));
    seams[static_cast<int>(attr("data-seam"))].push_back({{{static_cast<int>(attr("data-v0")), static_cast<int>(attr("data-v1"))}}, length});
    at = end;
  }
  ASSERT_EQ(seams.size(), 7u) << "eight strips side by side: seven seams";
  // The 3D lengths of the shared curves (scene units m → mm), densely evaluated here.
  const nlohmann::json& model = scene["model"];
  std::vector<double> curveLengths;
  std::vector<int> uses(model["edges"].size(), 0);
  for (const auto& face : model["faces"])
    for (const auto& e : face) ++uses[e.get<std::size_t>()];
  for (std::size_t e = 0; e < model["edges"].size(); ++e) {
    const nlohmann::json& edge = model["edges"][e];
    if (uses[e] != 2 || edge.value("type", "") != "S") continue;
    const spline::BSplineCurve curve = sceneEdgeCurve(model, edge);
    const Eigen::MatrixXd dense = curve.evaluate(curve.knots.uniformSamples(4001), 0);
    double length = 0.0;
    for (Eigen::Index k = 1; k < dense.rows(); ++k) length += (dense.row(k) - dense.row(k - 1)).norm();
    curveLengths.push_back(1000.0 * length);
  }
  ASSERT_EQ(curveLengths.size(), 7u);
  for (const auto& [seam, edges] : seams) {
    // The seam's edges form two chains, one on each piece: split them by connectivity.
    std::map<int, int> component;
    std::function<int(int)> root = [&component, &root](int v) {
      if (!component.count(v)) component[v] = v;
      return component[v] == v ? v : component[v] = root(component[v]);
    };
    for (const auto& [ends, length] : edges) component[root(ends[0])] = root(ends[1]);
    std::map<int, double> chainLength;
    for (const auto& [ends, length] : edges) chainLength[root(ends[0])] += length;
    ASSERT_EQ(chainLength.size(), 2u) << "seam " << seam << " runs along two pieces";
    const double a = chainLength.begin()->second, b = chainLength.rbegin()->second;
    EXPECT_NEAR(a, b, 1e-6 * a) << "seam " << seam << ": the two sides to glue have one length";
    // The polyline of 10 samples a span is a little shorter than the curve.
    const double nearest = *std::min_element(curveLengths.begin(), curveLengths.end(),
                                             [a](double x, double y) { return std::abs(x - a) < std::abs(y - a); });
    EXPECT_NEAR(a, nearest, 2e-3 * nearest) << "seam " << seam << " has the length of a shared curve";
  }

  // The same pieces as FOLD: one crease pattern of several parts whose seams are joins ("J"), one
  // per glue line of the SVG, and the folded frame where the two copies of every seam point meet
  // and the flat pieces' edges have their folded lengths — all read from the file.
  std::size_t glueLines = 0;
  for (const auto& [seam, edges] : seams) glueLines += edges.size();
  const std::string foldPath = (dir.path() / "pieces.fold").string();
  const CliRun fold = runCommand({"solve", sceneFile, "--out", report, "--export", "fold:" + foldPath});
  ASSERT_EQ(fold.code, 0) << fold.err;
  const nlohmann::json doc = nlohmann::json::parse(std::ifstream(foldPath));
  EXPECT_EQ(doc["frame_unit"], "m") << "the scene's units";
  const nlohmann::json& flat = doc["vertices_coords"];
  const nlohmann::json& folded = doc["file_frames"][0]["vertices_coords"];
  ASSERT_EQ(flat.size(), folded.size());
  std::size_t joins = 0;
  std::set<int> seamNumbers;
  double stretch = 0.0;
  for (std::size_t e = 0; e < doc["edges_vertices"].size(); ++e) {
    const std::size_t a = doc["edges_vertices"][e][0], b = doc["edges_vertices"][e][1];
    if (doc["edges_assignment"][e] == "J") {
      ++joins;
      seamNumbers.insert(doc["edges_devsurf:seam"][e].get<int>());
    }
    const double l2 = std::hypot(flat[a][0].get<double>() - flat[b][0].get<double>(),
                                 flat[a][1].get<double>() - flat[b][1].get<double>());
    const double l3 = std::hypot(folded[a][0].get<double>() - folded[b][0].get<double>(),
                                 folded[a][1].get<double>() - folded[b][1].get<double>(),
                                 folded[a][2].get<double>() - folded[b][2].get<double>());
    stretch = std::max(stretch, std::abs(l2 - l3) / l3);
  }
  EXPECT_EQ(joins, glueLines) << "every glue line of the SVG is a join";
  EXPECT_EQ(seamNumbers.size(), 7u);
  EXPECT_LT(stretch, 1e-4) << "the flat pieces keep the folded edge lengths";
  double gap = 0.0;
  for (const auto& pair : doc["devsurf:gluePairs"]) {
    const nlohmann::json &p = folded[pair[0].get<std::size_t>()], &q = folded[pair[1].get<std::size_t>()];
    gap = std::max(gap, std::hypot(p[0].get<double>() - q[0].get<double>(), p[1].get<double>() - q[1].get<double>(),
                                   p[2].get<double>() - q[2].get<double>()));
  }
  EXPECT_FALSE(doc["devsurf:gluePairs"].empty());
  EXPECT_LT(gap, 1e-12) << "the copies of a seam point are one point of the surface";
}

TEST(CoverCommand, BadArgumentsAreRefusedNamingTheOption) {
  devsurf::testing::TempDir dir;
  const std::string bunny = cgalData(dir, "data/meshes/bunny00.off");
  const CliRun strips = runCommand({"cover", bunny, "--strips", "0"});
  EXPECT_EQ(strips.code, 2);
  EXPECT_NE(strips.err.find("--strips"), std::string::npos) << strips.err;
  const CliRun crease = runCommand({"cover", bunny, "--crease", "valley"});
  EXPECT_EQ(crease.code, 2);
  EXPECT_NE(crease.err.find("--crease"), std::string::npos) << crease.err;
  const CliRun ball = runCommand({"cover", bunny, "--centre", "5,5,5", "--radius", "0.1"});
  EXPECT_EQ(ball.code, 2);
  EXPECT_NE(ball.err.find("--radius"), std::string::npos) << ball.err;
  const CliRun missing = runCommand({"cover", (dir.path() / "nothing.off").string()});
  EXPECT_NE(missing.code, 0);
  for (const std::vector<std::string>& flags : {std::vector<std::string>{"--regions", "0"},
                                                std::vector<std::string>{"--regions", "33"},
                                                std::vector<std::string>{"--regions", "32", "--strips", "8"},
                                                std::vector<std::string>{"--overhang", "-1"}}) {
    std::vector<std::string> args{"cover", bunny};
    args.insert(args.end(), flags.begin(), flags.end());
    const CliRun bad = runCommand(args);
    EXPECT_EQ(bad.code, 2) << flags[0] << " " << flags[1];
    EXPECT_NE(bad.err.find(flags[0]), std::string::npos) << bad.err;
  }
}

/// 000_… Fig. 10e, "the bunny is approximated by 6 composite surfaces": the whole closed bunny cut
/// into regions, each covered by strips, one composite of the parts. Distances from all of the
/// bunny's vertices are measured twice: by `solve --reference` and from the exported STL read
/// back through OpenMesh.
TEST(CoverCommand, CoversTheWholeClosedBunnyRegionByRegionAsOneCompositeOfDevelopableParts) {
  devsurf::testing::TempDir dir;
  const std::string bunny = cgalData(dir, "data/meshes/bunny00.off");
  const std::string scene = (dir.path() / "whole.json").string(), report = (dir.path() / "report.json").string(),
                    stl = (dir.path() / "whole.stl").string();
  const CliRun cover = runCommand({"cover", bunny, "--regions", "32", "--strips", "4", "--out", scene});
  ASSERT_EQ(cover.code, 0) << cover.err;
  const nlohmann::json summary = nlohmann::json::parse(cover.out);
  const int covered = summary["covered_regions"].get<int>();
  int skipped = 0;
  for (const auto& region : summary["regions"]) {
    if (region["covered"].get<bool>()) continue;
    ++skipped;
    EXPECT_FALSE(region["skipped"].get<std::string>().empty());
    EXPECT_NE(cover.err.find("is not covered"), std::string::npos);
  }
  EXPECT_EQ(covered + skipped, static_cast<int>(summary["regions"].size()));
  EXPECT_GE(covered, 25);
  EXPECT_LE(summary["warp_angle_max_deg"].get<double>(), 0.05);
  const nlohmann::json document = nlohmann::json::parse(std::ifstream(scene));
  EXPECT_EQ(document["model"]["kind"], "composite");
  EXPECT_EQ(document["model"]["faces"].size(), 4u * static_cast<std::size_t>(covered));

  // Solved again as a user would: it stays developable.
  const CliRun solve = runCommand({"solve", scene, "--reference", bunny, "--out", report, "--export", "stl:" + stl});
  ASSERT_EQ(solve.code, 0) << solve.err;
  const nlohmann::json metrics = nlohmann::json::parse(std::ifstream(report))["metrics"];
  const reference::ReferenceShape shape = reference::readReferenceShape(bunny);
  const double diagonal = shape.diagonal();
  const reference::ReferenceShape surface = reference::readReferenceShape(stl);
  ASSERT_GT(surface.triangles.rows(), 0);
  const reference::SurfaceDistance d = reference::surfaceDistance(shape.points, surface.points, surface.triangles,
                                                                   0.01 * diagonal);
  std::printf("whole bunny, %d of %zu regions: warp %.3g°, flatness %.3g, RMS %.3g %% max %.3g %% of the diagonal, "
              "%.1f %% of %ld vertices within 1 %%\n",
              covered, summary["regions"].size(), metrics["warp_angle_max_deg"].get<double>(),
              metrics["face_flatness_max"].get<double>(), 100 * d.rmsDistance / diagonal, 100 * d.maxDistance / diagonal,
              100 * d.coverage, static_cast<long>(shape.points.rows()));
  EXPECT_LE(metrics["warp_angle_max_deg"].get<double>(), 0.05);
  EXPECT_LE(metrics["face_flatness_max"].get<double>(), 1e-3);
  // No piece overlaps itself: no curve of the solved scene turns back, each evaluated here from
  // its B-spline at 2 001 parameters (its control polygon may zig-zag: crease_backtrack_max).
  const nlohmann::json solved = nlohmann::json::parse(std::ifstream(report))["scene"]["model"];
  double reversal = 0.0;
  int curves = 0;
  for (const auto& edge : solved["edges"]) {
    if (edge.value("type", "") != "S") continue;
    const spline::BSplineCurve curve = sceneEdgeCurve(solved, edge);
    const Eigen::MatrixXd dense = curve.evaluate(curve.knots.uniformSamples(2001), 0);
    for (Eigen::Index k = 2; k < dense.rows(); ++k) {
      const Eigen::RowVectorXd a = dense.row(k - 1) - dense.row(k - 2), b = dense.row(k) - dense.row(k - 1);
      if (a.norm() > 1e-12 && b.norm() > 1e-12) reversal = std::max(reversal, -a.normalized().dot(b.normalized()));
    }
    ++curves;
  }
  EXPECT_GT(curves, 2 * covered);
  EXPECT_LE(reversal, 0.05) << "a curve doubles back";
  EXPECT_NEAR(d.coverage, metrics["reference_coverage"].get<double>(), 0.01);
  EXPECT_GE(d.coverage, 0.75);
  EXPECT_LE(d.rmsDistance, 0.02 * diagonal);
}

/// Without the overhang rows a strip grows where no point holds it (000_… Fig. 11: "so as to
/// cover as much of the reference shape as possible"); on a doubly curved region that is a flap.
/// With them it stays over its region: the farthest point of the exported surface from the
/// region's points, computed here by brute force, is nearer. The fit without the rows does not
/// settle (its steps are halved again and again), so where it ends moves with the last bits of
/// its sums: one region gave ratios of 0.33 to 0.63 for centres 1 mm apart, and 0.37 or 0.60 for
/// the same centre with the assembly's sums in another order. Hence four centres, each nearer
/// with the rows, and less than 0.6 of the distance over all four (measured 0.50, and 0.49 with
/// the sums row by row).
TEST(CoverCommand, TheOverhangWeightKeepsAFittedStripOverItsRegion) {
  devsurf::testing::TempDir dir;
  const std::string bunny = cgalData(dir, "data/meshes/bunny00.off");
  double total[2] = {0.0, 0.0};
  int run = 0;
  for (const std::string centre : {"0.187,0.119,0.014", "0.188,0.119,0.014", "0.187,0.12,0.014", "0.186,0.118,0.015"}) {
    SCOPED_TRACE(centre);
    double farthest[2] = {0.0, 0.0};
    for (int withOverhang = 0; withOverhang < 2; ++withOverhang) {
      const std::string scene = (dir.path() / ("fit" + std::to_string(run) + ".json")).string();
      const std::string stl = (dir.path() / ("fit" + std::to_string(run) + ".stl")).string();
      ++run;
      std::vector<std::string> args{"fit", bunny, "--centre", centre, "--radius", "0.3", "--out", scene};
      if (withOverhang) args.insert(args.end(), {"--overhang", "0.001"});
      const CliRun fit = runCommand(args);
      ASSERT_EQ(fit.code, 0) << fit.err;
      const CliRun solve = runCommand({"solve", scene, "--export", "stl:" + stl});
      ASSERT_EQ(solve.code, 0) << solve.err;
      const nlohmann::json document = nlohmann::json::parse(std::ifstream(scene));
      const nlohmann::json& points = document["model"]["approximation"]["points"];
      EXPECT_EQ(document["model"]["approximation"]["weights"].value("overhang", 0.0), withOverhang ? 0.001 : 0.0);
      const reference::ReferenceShape surface = reference::readReferenceShape(stl);
      for (Eigen::Index v = 0; v < surface.points.rows(); v += 3) {
        double nearest = std::numeric_limits<double>::infinity();
        for (const auto& q : points)
          nearest = std::min(nearest, std::hypot(surface.points(v, 0) - q[0].get<double>(),
                                                 surface.points(v, 1) - q[1].get<double>(),
                                                 surface.points(v, 2) - q[2].get<double>()));
        farthest[withOverhang] = std::max(farthest[withOverhang], nearest);
      }
      total[withOverhang] += farthest[withOverhang];
    }
    std::printf("fitted strip on the bunny's back at %s: farthest surface point from the region %.3g without, %.3g with overhang rows\n",
                centre.c_str(), farthest[0], farthest[1]);
    EXPECT_LT(farthest[1], farthest[0]);
  }
  EXPECT_LT(total[1], 0.6 * total[0]);
}

/// The REST route runs a cover in its request's thread with a time limit: work that does not fit
/// is refused naming the parameter (413 "limit"), not left running.
TEST(CoverCommand, ACoverThatOutrunsItsTimeLimitIsRefusedNamingTheParameter) {
  devsurf::testing::TempDir dir;
  const reference::ReferenceShape bunny = reference::readReferenceShape(cgalData(dir, "data/meshes/bunny00.off"));
  for (const int regions : {1, 8}) {
    RegionFitRequest request;
    request.regions = regions;
    request.timeLimitMs = 1.0;
    try {
      (void)coverShapeWithStrips(bunny, "bunny00.off", request);
      ADD_FAILURE() << "a 1 ms cover of " << regions << " regions finished";
    } catch (const ApproximationInputError& e) {
      EXPECT_EQ(e.field(), regions > 1 ? "regions" : "rounds") << e.what();
      EXPECT_TRUE(e.tooLarge()) << e.what();
      EXPECT_NE(std::string(e.what()).find("time limit"), std::string::npos) << e.what();
    }
  }
}

/// With no ball, too few points for the regions asked names `regions`, not a radius nobody sent.
TEST(CoverCommand, AShapeTooSmallForItsRegionsNamesRegions) {
  reference::ReferenceShape plate;
  plate.points = Eigen::MatrixX3d::Random(40, 3);
  plate.points.col(2).setZero();
  RegionFitRequest request;
  request.regions = 4;
  try {
    (void)coverShapeWithStrips(plate, "plate.xyz", request);
    ADD_FAILURE() << "40 points covered by 4 regions of 4 strips";
  } catch (const ApproximationInputError& e) {
    EXPECT_EQ(e.field(), "regions") << e.what();
  }
}

}  // namespace
}  // namespace devsurf::server
