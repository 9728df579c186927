// spatial::parameterizeDisk (issue 15, 004_… §5): CGAL's conformal and ARAP maps of a disk.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "devsurf/spatial/DiskParameterization.h"
#include "support/TriangulatedGrid.h"

namespace devsurf::spatial {
namespace {

/// max over triangle edges of | |e′| / |e| − 1 | (an independent check of the map's distortion).
double edgeStretchMax(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& T, const Eigen::MatrixX2d& uv) {
  double worst = 0.0;
  for (Eigen::Index t = 0; t < T.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = T(t, k), b = T(t, (k + 1) % 3);
      worst = std::max(worst, std::abs((uv.row(a) - uv.row(b)).norm() / (V.row(a) - V.row(b)).norm() - 1.0));
    }
  return worst;
}

double signedAreaMin(const Eigen::MatrixX3i& T, const Eigen::MatrixX2d& uv) {
  double least = 1e300;
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    const Eigen::Vector2d a = uv.row(T(t, 0)), b = uv.row(T(t, 1)), c = uv.row(T(t, 2));
    least = std::min(least, 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x()));
  }
  return least;
}

TEST(DiskParameterization, AFlatSheetInSpaceMapsToItselfUpToARigidMotionWithBothMethods) {
  const Eigen::Matrix3d turn = (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  Eigen::MatrixX3d V;
  Eigen::MatrixX3i T;
  devsurf::testing::triangulatedGrid(12, 8, 3.0, 2.0, [&turn](double x, double y) { return Eigen::Vector3d(turn * Eigen::Vector3d(x, y, 0) + Eigen::Vector3d(5, -1, 2)); }, V, T);
  for (ParameterizationMethod method : {ParameterizationMethod::Conformal, ParameterizationMethod::NearIsometric}) {
    const Eigen::MatrixX2d uv = parameterizeDisk(V, T, method);
    // LSCM solves one linear system (exact); ARAP iterates to CGAL's own tolerance.
    EXPECT_LT(edgeStretchMax(V, T, uv), method == ParameterizationMethod::Conformal ? 1e-9 : 1e-4);
    EXPECT_GT(signedAreaMin(T, uv), 0.0) << "orientation kept, no triangle flipped";
    EXPECT_LT(uv.colwise().mean().norm(), 1e-9) << "centred";
  }
}

TEST(DiskParameterization, ACylinderPatchUnrollsNearlyIsometricallyAndKeepsItsArea) {
  // 120° of a unit cylinder, height 1.5: developable, so the near-isometric map is its unrolling.
  Eigen::MatrixX3d V;
  Eigen::MatrixX3i T;
  devsurf::testing::triangulatedGrid(40, 15, 2.0 * M_PI / 3.0, 1.5, [](double s, double z) { return Eigen::Vector3d(std::cos(s), std::sin(s), z); }, V, T);
  const Eigen::MatrixX2d uv = parameterizeDisk(V, T, ParameterizationMethod::NearIsometric);
  EXPECT_LT(edgeStretchMax(V, T, uv), 1e-3);
  EXPECT_GT(signedAreaMin(T, uv), 0.0);
  double area3d = 0.0, area2d = 0.0;
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    area3d += 0.5 * (V.row(T(t, 1)) - V.row(T(t, 0))).cross(V.row(T(t, 2)) - V.row(T(t, 0))).norm();
    const Eigen::Vector2d a = uv.row(T(t, 0)), b = uv.row(T(t, 1)), c = uv.row(T(t, 2));
    area2d += 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
  }
  EXPECT_NEAR(area2d, area3d, 1e-9 * area3d);
}

TEST(DiskParameterization, AMeshThatIsNotADiskIsRefusedSayingWhy) {
  // A closed tetrahedron.
  Eigen::MatrixX3d V(4, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  Eigen::MatrixX3i T(4, 3);
  T << 0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2;
  try {
    parameterizeDisk(V, T);
    FAIL() << "a closed mesh was mapped";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("closed"), std::string::npos) << e.what();
  }
  // An annulus: a sheet with one quad's two triangles taken out of its middle.
  Eigen::MatrixX3d G;
  Eigen::MatrixX3i S;
  devsurf::testing::triangulatedGrid(5, 5, 1.0, 1.0, [](double x, double y) { return Eigen::Vector3d(x, y, 0); }, G, S);
  Eigen::MatrixX3i holed(S.rows() - 2, 3);
  for (Eigen::Index t = 0, k = 0; t < S.rows(); ++t)
    if (t != 24 && t != 25) holed.row(k++) = S.row(t);
  try {
    parameterizeDisk(G, holed);
    FAIL() << "an annulus was mapped";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("2 boundary loops"), std::string::npos) << e.what();
  }
  // Two separate triangles.
  Eigen::MatrixX3d W(6, 3);
  W << 0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 0, 0, 6, 0, 0, 5, 1, 0;
  Eigen::MatrixX3i two(2, 3);
  two << 0, 1, 2, 3, 4, 5;
  EXPECT_THROW(parameterizeDisk(W, two), std::invalid_argument);
  // A degenerate triangle, an index out of range, a non-finite coordinate.
  Eigen::MatrixX3d D = W.topRows(3);
  D.row(2) = D.row(1) * 2.0;
  Eigen::MatrixX3i one(1, 3);
  one << 0, 1, 2;
  EXPECT_THROW(parameterizeDisk(D, one), std::invalid_argument);
  one << 0, 1, 7;
  EXPECT_THROW(parameterizeDisk(W, one), std::invalid_argument);
  Eigen::MatrixX3d N = W;
  N(0, 0) = std::nan("");
  one << 0, 1, 2;
  EXPECT_THROW(parameterizeDisk(N, one), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::spatial
