// `devsurf fit` (issue 15, 000_… §4.2): a strip scene over a region of a user's shape, solved by
// `devsurf solve`; its distances checked against `--reference`, an independent computation over
// every point of the region's file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "server/CliTesting.h"
#include "support/TempDir.h"

namespace devsurf::server {
namespace {

using testing::CliRun;
using testing::runCommand;

/// A noisy cylinder patch (radius 1, 100° of arc, height 1.2) written as an XYZ cloud without
/// normals; σ = 0.1 % of its bounding-box diagonal.
std::string writeCylinderCloud(const devsurf::testing::TempDir& dir, double& sigma) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  sigma = 1e-3 * std::sqrt(1.2 * 1.2 + 1.532 * 1.532 + 0.357 * 0.357);
  std::normal_distribution<double> noise(0.0, sigma);
  const std::string path = (dir.path() / "cylinder.xyz").string();
  std::ofstream f(path);
  f.precision(17);
  for (int j = 0; j < 3000; ++j) {
    const double angle = (-50.0 + 100.0 * uniform(rng)) * M_PI / 180.0, r = 1.0 + noise(rng);
    f << r * std::cos(angle) << ' ' << r * std::sin(angle) << ' ' << 1.2 * uniform(rng) << '\n';
  }
  return path;
}

TEST(FitCommand, WritesAStripSceneThatSolvesOntoTheCloudWithinTheIssuesThresholds) {
  devsurf::testing::TempDir dir;
  double sigma = 0.0;
  const std::string cloud = writeCylinderCloud(dir, sigma);
  const std::string scene = (dir.path() / "fit.json").string(), report = (dir.path() / "report.json").string();
  const CliRun fit = runCommand({"fit", cloud, "--out", scene});
  ASSERT_EQ(fit.code, 0) << fit.err;
  const nlohmann::json document = nlohmann::json::parse(std::ifstream(scene));
  EXPECT_EQ(document["model"]["kind"], "strip");
  EXPECT_GT(document["model"]["approximation"]["points"].size(), 100u);
  EXPECT_EQ(document["model"]["approximation"]["points"].size(), document["model"]["approximation"]["normals"].size());
  const CliRun solve = runCommand({"solve", scene, "--reference", cloud, "--coverage-tolerance",
                                   std::to_string(3.0 * sigma), "--out", report});
  ASSERT_EQ(solve.code, 0) << solve.err;
  const nlohmann::json metrics = nlohmann::json::parse(std::ifstream(report))["metrics"];
  // Every one of the 3000 points, measured by --reference: RMS ≤ 2σ, coverage ≥ 95 %, warp ≤ 0.05°.
  EXPECT_EQ(metrics["reference_points"], 3000);
  EXPECT_LE(metrics["reference_distance_rms"].get<double>(), 2.0 * sigma);
  EXPECT_GE(metrics["reference_coverage"].get<double>(), 0.95);
  EXPECT_LE(metrics["warp_angle_max_deg"].get<double>(), 0.05);
  EXPECT_LE(metrics["approximation_distance_rms"].get<double>(), 2.0 * sigma);
}

/// CGAL's kitten point cloud (libcgal-demo's data) extracted into `dir`: its path, empty if not.
std::string extractedKitten(const devsurf::testing::TempDir& dir) {
  const std::string command = "tar -xzf /usr/share/doc/libcgal-dev/data.tar.gz -C '" + dir.str() +
                              "' data/points_3/kitten.xyz 2>/dev/null";
  if (std::system(command.c_str()) != 0) return {};
  return (dir.path() / "data/points_3/kitten.xyz").string();
}

TEST(FitCommand, ARegionOfCgalsKittenIsCoveredByAStripThatStaysOnIt) {
  devsurf::testing::TempDir dir;
  const std::string kitten = extractedKitten(dir);
  ASSERT_FALSE(kitten.empty()) << "libcgal-demo's data (scripts/setup.sh installs it)";
  const std::string scene = (dir.path() / "kitten-fit.json").string(), report = (dir.path() / "r.json").string();
  // A brush stroke on the kitten's flank (doubly curved: one strip cannot follow it exactly).
  const CliRun fit = runCommand({"fit", kitten, "--centre", "0.3,0,0", "--radius", "0.12", "--out", scene});
  ASSERT_EQ(fit.code, 0) << fit.err;
  for (const int iterations : {10, 60, 200}) {
    nlohmann::json document = nlohmann::json::parse(std::ifstream(scene));
    document["solver"]["iterations"] = iterations;
    std::ofstream(scene + ".run") << document.dump();
    const CliRun solve = runCommand({"solve", scene + ".run", "--out", report});
    ASSERT_EQ(solve.code, 0) << solve.err;
    const nlohmann::json metrics = nlohmann::json::parse(std::ifstream(report))["metrics"];
    SCOPED_TRACE(iterations);
    // Measured: RMS 1.4 % of the region's diagonal at 10, 60 and 200 iterations; it drifted to
    // 8 % before points beyond the boundary counted in eq. (11).
    EXPECT_LE(metrics["approximation_distance_rms_relative"].get<double>(), 0.02);
    EXPECT_LE(metrics["approximation_distance_max_relative"].get<double>(), 0.06);
    // The region is doubly curved: the strip keeps narrowing until its width guard holds it
    // (10 % of the start with a target), and against the guard its dense warp grows (measured
    // 0.0003° / 1.05° / 0.77° at 10 / 60 / 200 iterations): a known limit, listed in
    // docs/architecture.md; what is asserted here is that the strip stays on its region.
    if (iterations <= 10) EXPECT_LE(metrics["warp_angle_max_deg"].get<double>(), 0.05);
    std::printf("kitten flank, %d iterations: RMS %.4f, max %.4f of the diagonal, warp %.3g°\n", iterations,
                metrics["approximation_distance_rms_relative"].get<double>(),
                metrics["approximation_distance_max_relative"].get<double>(), metrics["warp_angle_max_deg"].get<double>());
  }
}

TEST(MergeCommand, TwoStripsFittedToHalvesOfACloudMergeIntoOneThatSolvesOverTheWhole) {
  devsurf::testing::TempDir dir;
  double sigma = 0.0;
  const std::string cloud = writeCylinderCloud(dir, sigma);
  // The halves as the user brushes them: balls around the middles of the two halves, wide enough
  // to hold their corners (they overlap in the middle).
  const double c = std::cos(25.0 * M_PI / 180.0), s = std::sin(25.0 * M_PI / 180.0);
  const std::string left = (dir.path() / "left.json").string(), right = (dir.path() / "right.json").string();
  ASSERT_EQ(runCommand({"fit", cloud, "--centre", std::to_string(c) + "," + std::to_string(-s) + ",0.6", "--radius", "0.75",
                        "--out", left}).code, 0);
  ASSERT_EQ(runCommand({"fit", cloud, "--centre", std::to_string(c) + "," + std::to_string(s) + ",0.6", "--radius", "0.75",
                        "--out", right}).code, 0);
  for (const std::string& half : {left, right}) ASSERT_EQ(runCommand({"solve", half, "--out", half}).code, 0);
  // The solved reports hold the solved scenes; merge those.
  for (const std::string& half : {left, right}) {
    const nlohmann::json report = nlohmann::json::parse(std::ifstream(half));
    std::ofstream(half) << report["scene"].dump();
  }
  const std::string merged = (dir.path() / "merged.json").string(), report = (dir.path() / "r.json").string();
  const CliRun merge = runCommand({"merge", left, right, "--out", merged});
  ASSERT_EQ(merge.code, 0) << merge.err;
  EXPECT_NE(merge.err.find("joined with a gap of"), std::string::npos);
  const CliRun solve = runCommand({"solve", merged, "--reference", cloud, "--coverage-tolerance",
                                   std::to_string(3.0 * sigma), "--out", report});
  ASSERT_EQ(solve.code, 0) << solve.err;
  const nlohmann::json metrics = nlohmann::json::parse(std::ifstream(report))["metrics"];
  EXPECT_LE(metrics["reference_distance_rms"].get<double>(), 2.0 * sigma) << metrics.dump(1);
  EXPECT_GE(metrics["reference_coverage"].get<double>(), 0.95);
  EXPECT_LE(metrics["warp_angle_max_deg"].get<double>(), 0.05);
  // Not strips: refused naming the kind.
  const CliRun composite = runCommand({"merge", merged, testing::examplePath("composite-curved-fold.json")});
  EXPECT_EQ(composite.code, 2);
  EXPECT_NE(composite.err.find("model.kind"), std::string::npos) << composite.err;
  EXPECT_EQ(runCommand({"merge", merged}).code, 2);
  // Strips that do not meet (the left one moved 30 units along x, its ends far from the right
  // one's): refused, and nothing written.
  nlohmann::json far = nlohmann::json::parse(std::ifstream(left));
  for (const char* curve : {"a", "b"})
    for (nlohmann::json& p : far["model"][curve]["points"]) p[0] = p[0].get<double>() + 30.0;
  const std::string farPath = (dir.path() / "far.json").string(), notWritten = (dir.path() / "none.json").string();
  std::ofstream(farPath) << far.dump();
  const CliRun apart = runCommand({"merge", farPath, right, "--out", notWritten});
  EXPECT_EQ(apart.code, 2) << apart.err;
  EXPECT_NE(apart.err.find("do not meet"), std::string::npos) << apart.err;
  EXPECT_FALSE(std::filesystem::exists(notWritten));
  // The right strip beside itself (moved across by a third of its width): side by side, not end
  // to end; refused, and nothing written.
  nlohmann::json beside = nlohmann::json::parse(std::ifstream(right));
  const nlohmann::json& a = beside["model"]["a"]["points"];
  const nlohmann::json& b = beside["model"]["b"]["points"];
  Eigen::Vector3d across = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 3; ++k) across[k] += (b[i][k].get<double>() - a[i][k].get<double>()) / static_cast<double>(a.size());
  for (const char* curve : {"a", "b"})
    for (nlohmann::json& p : beside["model"][curve]["points"])
      for (int k = 0; k < 3; ++k) p[k] = p[k].get<double>() + across[k] / 3.0;
  const std::string besidePath = (dir.path() / "beside.json").string();
  std::ofstream(besidePath) << beside.dump();
  const CliRun sideBySide = runCommand({"merge", right, besidePath, "--out", notWritten});
  EXPECT_EQ(sideBySide.code, 2) << sideBySide.err;
  EXPECT_NE(sideBySide.err.find("continue one another"), std::string::npos) << sideBySide.err;
  EXPECT_FALSE(std::filesystem::exists(notWritten));
}

TEST(MergeCommand, KittenFitsThatDoNotMakeOneDevelopableStripAreRefusedAndOnesThatDoAreMerged) {
  devsurf::testing::TempDir dir;
  const std::string kitten = extractedKitten(dir);
  ASSERT_FALSE(kitten.empty()) << "libcgal-demo's data (scripts/setup.sh installs it)";
  // Two brush strokes as a user makes them: a fit, then the next ball 0.2 further along the way
  // the first strip runs; each solved, and the solved scenes merged.
  const auto fitAndSolve = [&dir, &kitten](const std::string& centre, const std::string& stem) {
    const std::string path = (dir.path() / (stem + ".json")).string();
    EXPECT_EQ(runCommand({"fit", kitten, "--centre", centre, "--radius", "0.12", "--out", path}).code, 0);
    EXPECT_EQ(runCommand({"solve", path, "--out", path}).code, 0);
    const nlohmann::json report = nlohmann::json::parse(std::ifstream(path));
    std::ofstream(path) << report["scene"].dump();
    return path;
  };
  const auto solvedWarp = [&dir](const std::string& scene) {
    const std::string report = (dir.path() / "warp.json").string();
    EXPECT_EQ(runCommand({"solve", scene, "--out", report}).code, 0);
    return nlohmann::json::parse(std::ifstream(report))["metrics"]["warp_angle_max_deg"].get<double>();
  };
  // On the back: the strips continue one another; merged, the strip solves within a strip's
  // warp limit (measured 0.01°).
  const std::string backFirst = fitAndSolve("0.1049,0.0531,0.2720", "back1");
  const std::string backSecond = fitAndSolve("0.1906,0.2336,0.2815", "back2");
  const std::string merged = (dir.path() / "merged.json").string();
  const CliRun merge = runCommand({"merge", backFirst, backSecond, "--out", merged});
  ASSERT_EQ(merge.code, 0) << merge.err;
  EXPECT_LE(solvedWarp(merged), 0.05);
  // Round the flank: the layout checks pass, but no one developable strip follows both (as stop
  // 51's overlapping fits, whose merge solved to a warp of 65°). Refused naming why, nothing
  // written; --unchecked writes it, and `solve` confirms it misses the limit by far.
  const std::string flankFirst = fitAndSolve("0.2141,-0.0210,-0.0634", "flank1");
  const std::string flankSecond = fitAndSolve("0.0793,-0.1229,-0.1704", "flank2");
  const std::string notWritten = (dir.path() / "none.json").string();
  const CliRun refused = runCommand({"merge", flankFirst, flankSecond, "--out", notWritten});
  EXPECT_EQ(refused.code, 2) << refused.err;
  EXPECT_NE(refused.err.find("do not make one developable strip"), std::string::npos) << refused.err;
  EXPECT_FALSE(std::filesystem::exists(notWritten));
  const CliRun unchecked = runCommand({"merge", flankFirst, flankSecond, "--unchecked", "--out", merged});
  ASSERT_EQ(unchecked.code, 0) << unchecked.err;
  const double warp = solvedWarp(merged);
  std::printf("kitten flank merged anyway: warp %.3g°\n", warp);
  EXPECT_GT(warp, 0.5);
}

TEST(FitCommand, TheLampshadeScanSceneSolvesOntoItsPoints) {
  // tests/data/fit/strip-fit-lampshade.json: made by `devsurf fit` from a synthetic 6 000-point
  // scan of a conical lampshade (σ = 0.157 mm on 157 mm), served by the browser test as a demo.
  const std::string scene = std::string(DEVSURF_SOURCE_DIR) + "/tests/data/fit/strip-fit-lampshade.json";
  devsurf::testing::TempDir dir;
  const std::string report = (dir.path() / "r.json").string();
  const CliRun solve = runCommand({"solve", scene, "--out", report});
  ASSERT_EQ(solve.code, 0) << solve.err;
  const nlohmann::json metrics = nlohmann::json::parse(std::ifstream(report))["metrics"];
  // Measured: RMS 0.105 % of the points' diagonal, warp 6e-5°.
  EXPECT_LE(metrics["approximation_distance_rms_relative"].get<double>(), 0.002);
  EXPECT_GE(metrics["approximation_coverage"].get<double>(), 0.99);
  EXPECT_LE(metrics["warp_angle_max_deg"].get<double>(), 0.05);
  EXPECT_GE(metrics["ruling_length_min_ratio"].get<double>(), 0.25);
}

TEST(FitCommand, BadArgumentsAreRefusedNamingThem) {
  devsurf::testing::TempDir dir;
  double sigma = 0.0;
  const std::string cloud = writeCylinderCloud(dir, sigma);
  const CliRun lonely = runCommand({"fit", cloud, "--radius", "0.2"});
  EXPECT_EQ(lonely.code, 2);
  EXPECT_NE(lonely.err.find("--centre and --radius go together"), std::string::npos) << lonely.err;
  const CliRun centre = runCommand({"fit", cloud, "--centre", "1,nan,0", "--radius", "0.2"});
  EXPECT_EQ(centre.code, 2);
  EXPECT_NE(centre.err.find("--centre"), std::string::npos) << centre.err;
  const CliRun empty = runCommand({"fit", cloud, "--centre", "50,50,50", "--radius", "0.2"});
  EXPECT_EQ(empty.code, 2);
  EXPECT_NE(empty.err.find("the region holds 0 points"), std::string::npos) << empty.err;
  const CliRun rulings = runCommand({"fit", cloud, "--rulings", "diagonal"});
  EXPECT_EQ(rulings.code, 2);
  EXPECT_NE(rulings.err.find("--rulings"), std::string::npos) << rulings.err;
  EXPECT_EQ(runCommand({"fit", (dir.path() / "missing.xyz").string()}).code, 2);
}

TEST(FitCommand, AnApproximationWithMismatchedNormalsIsRefusedNamingTheField) {
  devsurf::testing::TempDir dir;
  double sigma = 0.0;
  const std::string scene = (dir.path() / "fit.json").string();
  ASSERT_EQ(runCommand({"fit", writeCylinderCloud(dir, sigma), "--out", scene}).code, 0);
  nlohmann::json document = nlohmann::json::parse(std::ifstream(scene));
  document["model"]["approximation"]["normals"].erase(0);
  const CliRun shortNormals = runCommand({"solve", "-"}, document.dump());
  EXPECT_EQ(shortNormals.code, 2);
  EXPECT_NE(shortNormals.err.find("model.approximation.normals"), std::string::npos) << shortNormals.err;
  document = nlohmann::json::parse(std::ifstream(scene));
  document["model"]["approximation"]["normals"][3] = {0, 0, 0};
  const CliRun zero = runCommand({"solve", "-"}, document.dump());
  EXPECT_EQ(zero.code, 2);
  EXPECT_NE(zero.err.find("approximation.normals"), std::string::npos) << zero.err;
}

}  // namespace
}  // namespace devsurf::server
