// `devsurf cover` (issue 15, 000_… Fig. 10d–e): the back of CGAL's bunny covered by strips side by
// side, made one composite and solved. Distances are measured twice: by `solve --reference` and,
// independently, from the region's points to the exported STL read back through OpenMesh.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "devsurf/reference/ReferenceShape.h"
#include "devsurf/reference/SurfaceDistance.h"
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
}

}  // namespace
}  // namespace devsurf::server
