// `devsurf reference` and `devsurf solve --reference` (issue 15): what a shape holds, thinning
// written and read back, and distances to a solved surface checked against an independent
// offset of its own OBJ export.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "devsurf/proto/Scene.h"
#include "devsurf/server/Cli.h"
#include "server/CliTesting.h"
#include "support/ExportChecks.h"
#include "support/TempDir.h"

namespace devsurf::server {
namespace {

using testing::CliRun;
using testing::examplePath;
using testing::runCommand;

TEST(ReferenceCommand, DescribesAShapeAndWritesItsThinnedCloudWithNormals) {
  devsurf::testing::TempDir dir;
  const std::string cloud = (dir.path() / "plane.xyz").string();
  {
    std::ofstream f(cloud);
    for (int i = 0; i <= 40; ++i)
      for (int j = 0; j <= 40; ++j) f << i * 0.05 << ' ' << j * 0.05 << ' ' << 0.5 * i * 0.05 << '\n';
  }
  const std::string thinned = (dir.path() / "thin.xyz").string();
  const CliRun r = runCommand({"reference", cloud, "--thin", "0.3", "--seed", "5", "--out", thinned});
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  EXPECT_EQ(report["points"], 41 * 41);
  EXPECT_EQ(report["triangles"], 0);
  EXPECT_EQ(report["format"], "xyz");
  EXPECT_NEAR(report["diagonal"].get<double>(), std::sqrt(4.0 + 4.0 + 1.0), 1e-12);
  const long kept = report["thinned"]["points"].get<long>();
  EXPECT_GT(kept, 10);
  EXPECT_EQ(report["thinned"]["normals_fitted"], kept);
  // The written cloud read back line by line: the plane's normal ±(−0.5, 0, 1)/|…| everywhere.
  std::ifstream back(thinned);
  long lines = 0;
  double x, y, z, nx, ny, nz;
  while (back >> x >> y >> z >> nx >> ny >> nz) {
    ++lines;
    EXPECT_NEAR(z, 0.5 * x, 1e-12);
    EXPECT_NEAR(std::abs(-0.5 * nx + nz) / std::sqrt(1.25), 1.0, 1e-9);
  }
  EXPECT_EQ(lines, kept);
}

TEST(ReferenceCommand, BadArgumentsAndFilesAreRefusedNamingThem) {
  EXPECT_EQ(runCommand({"reference"}).code, 2);
  const CliRun radius = runCommand({"reference", examplePath("strip-twisted.json"), "--thin", "-1"});
  EXPECT_EQ(radius.code, 2);
  EXPECT_NE(radius.err.find("--thin: expected a positive length"), std::string::npos) << radius.err;
  const CliRun extension = runCommand({"reference", examplePath("strip-twisted.json")});
  EXPECT_EQ(extension.code, 2);
  EXPECT_NE(extension.err.find("unknown extension \".json\""), std::string::npos) << extension.err;
  const CliRun out = runCommand({"reference", "x.xyz", "--out", "y.xyz"});
  EXPECT_EQ(out.code, 2);
  EXPECT_NE(out.err.find("give --thin"), std::string::npos) << out.err;
  const CliRun solve = runCommand({"solve", examplePath("strip-twisted.json"), "--reference", "/nonexistent/scan.xyz"});
  EXPECT_EQ(solve.code, 2);
  EXPECT_NE(solve.err.find("--reference: /nonexistent/scan.xyz: cannot open"), std::string::npos) << solve.err;
  const CliRun tolerance = runCommand({"solve", examplePath("strip-twisted.json"), "--coverage-tolerance", "0.1"});
  EXPECT_EQ(tolerance.code, 2);
  EXPECT_NE(tolerance.err.find("needs --reference"), std::string::npos) << tolerance.err;
}

/// Every example kind: reference points = the solved OBJ export's vertices moved along their
/// (area-weighted) normals by d; solve --reference must report distances of at most d and, for
/// most points, close to d; the unmoved vertices are at distance 0 and fully covered.
TEST(ReferenceCommand, SolveReportsDistancesToTheSolvedSurfaceOfEveryKind) {
  devsurf::testing::TempDir dir;
  // One example of every kind, discovered (the first by name).
  std::map<std::string, std::string> exampleOfKind;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(DEVSURF_SOURCE_DIR) + "/examples")) {
    if (entry.path().extension() != ".json") continue;
    std::ifstream f(entry.path());
    const std::string kind = nlohmann::json::parse(f)["model"]["kind"].get<std::string>();
    const std::string name = entry.path().filename().string();
    if (!exampleOfKind.count(kind) || name < exampleOfKind[kind]) exampleOfKind[kind] = name;
  }
  EXPECT_GE(exampleOfKind.size(), 5u);
  for (const auto& [kind, name] : exampleOfKind) {
    const std::string obj = (dir.path() / "surface.obj").string();
    const CliRun solved = runCommand({"solve", examplePath(name), "--export", "obj:" + obj});
    ASSERT_EQ(solved.code, 0) << name << ": " << solved.err;
    std::ifstream in(obj);
    std::stringstream text;
    text << in.rdbuf();
    const devsurf::testing::ObjMesh mesh = devsurf::testing::parseObj(text.str());
    ASSERT_GT(mesh.vertices.size(), 10u) << name;
    std::vector<Eigen::Vector3d> normals(mesh.vertices.size(), Eigen::Vector3d::Zero());
    for (const auto& f : mesh.faces)
      for (std::size_t k = 0; k < f.size(); ++k) {
        const Eigen::Vector3d& a = mesh.vertices[f[k]];
        const Eigen::Vector3d& b = mesh.vertices[f[(k + 1) % f.size()]];
        const Eigen::Vector3d& c = mesh.vertices[f[(k + f.size() - 1) % f.size()]];
        normals[f[k]] += (b - a).cross(c - a);
      }
    Eigen::Vector3d lo = mesh.vertices[0], hi = mesh.vertices[0];
    for (const auto& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    const double size = (hi - lo).norm(), d = 1e-3 * size;
    const std::string exact = (dir.path() / "exact.xyz").string(), offset = (dir.path() / "offset.xyz").string();
    {
      std::ofstream e(exact), o(offset);
      e.precision(17);
      o.precision(17);
      for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
        const Eigen::Vector3d& v = mesh.vertices[i];
        e << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
        if (normals[i].norm() == 0) continue;
        const Eigen::Vector3d w = v + d * normals[i].normalized();
        o << w.x() << ' ' << w.y() << ' ' << w.z() << '\n';
      }
    }
    const CliRun atZero = runCommand({"solve", examplePath(name), "--reference", exact});
    ASSERT_EQ(atZero.code, 0) << name << ": " << atZero.err;
    const nlohmann::json m0 = nlohmann::json::parse(atZero.out)["metrics"];
    EXPECT_LT(m0["reference_distance_max"].get<double>(), 1e-7 * size) << name << " (the OBJ has 9 digits)";
    EXPECT_EQ(m0["reference_coverage"].get<double>(), 1.0) << name;
    EXPECT_EQ(m0["reference_points"].get<double>(), static_cast<double>(mesh.vertices.size())) << name;
    const CliRun moved = runCommand({"solve", examplePath(name), "--reference", offset, "--coverage-tolerance", std::to_string(d / 2)});
    ASSERT_EQ(moved.code, 0) << name << ": " << moved.err;
    const nlohmann::json m = nlohmann::json::parse(moved.out)["metrics"];
    EXPECT_LE(m["reference_distance_max"].get<double>(), d + 1e-7 * size) << name;
    EXPECT_GT(m["reference_distance_rms"].get<double>(), 0.5 * d) << name;
    EXPECT_LT(m["reference_coverage"].get<double>(), 0.5) << name << ": most points are d from the surface";
  }
}

}  // namespace
}  // namespace devsurf::server
