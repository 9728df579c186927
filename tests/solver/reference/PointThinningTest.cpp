// Poisson-like thinning with fitted normals (000_… §4.2): the sampling's two properties checked by
// brute force over hundreds of seeded random clouds, normals against planes and a sphere.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "devsurf/reference/PointThinning.h"

namespace devsurf::reference {
namespace {

TEST(PointThinning, KeptPointsAreRApartAndEveryPointIsWithinROfOne) {
  std::mt19937 random(2026);
  for (int trial = 0; trial < 300; ++trial) {
    const int n = 1 + static_cast<int>(random() % 400);
    const double spread = std::uniform_real_distribution<double>(0.1, 10.0)(random);
    Eigen::MatrixX3d points(n, 3);
    std::uniform_real_distribution<double> coordinate(-spread, spread);
    for (int i = 0; i < n; ++i) points.row(i) << coordinate(random), coordinate(random), 0.2 * coordinate(random);
    if (trial % 7 == 0 && n > 3) points.row(1) = points.row(0);  // duplicate points happen in scans
    ThinningOptions options;
    options.radius = spread * std::uniform_real_distribution<double>(0.02, 1.5)(random);
    options.seed = static_cast<std::uint32_t>(trial);
    const ThinnedCloud thin = thinPointCloud(points, Eigen::MatrixX3d(0, 3), options);
    ASSERT_GE(thin.kept.size(), 1u);
    const double r = options.radius;
    for (std::size_t a = 0; a < thin.kept.size(); ++a)
      for (std::size_t b = a + 1; b < thin.kept.size(); ++b)
        ASSERT_GT((points.row(thin.kept[a]) - points.row(thin.kept[b])).norm(), r * (1 - 1e-12))
            << "trial " << trial << ": kept points " << thin.kept[a] << " and " << thin.kept[b] << " closer than r";
    for (int i = 0; i < n; ++i) {
      double nearest = INFINITY;
      for (const int k : thin.kept) nearest = std::min(nearest, (points.row(i) - points.row(k)).norm());
      ASSERT_LE(nearest, r * (1 + 1e-12)) << "trial " << trial << ": point " << i << " is covered by no kept point";
    }
    for (std::size_t k = 0; k < thin.kept.size(); ++k)
      ASSERT_EQ(thin.points.row(static_cast<Eigen::Index>(k)), points.row(thin.kept[k]));
    // The same seed gives the same result.
    EXPECT_EQ(thinPointCloud(points, Eigen::MatrixX3d(0, 3), options).kept, thin.kept);
  }
}

TEST(PointThinning, NormalsOfAPlaneAreItsNormalOrientedLikeTheGivenOnes) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d normal = Eigen::Vector3d(-0.3, -0.2, 1.0).normalized();
  Eigen::MatrixX3d points(2000, 3), given(2000, 3);
  for (int i = 0; i < 2000; ++i) {
    const double x = u(random), y = u(random);
    points.row(i) << x, y, 0.3 * x + 0.2 * y + 1.0;
    given.row(i) = -normal.transpose() + 0.3 * Eigen::RowVector3d(u(random), u(random), 0);  // rough, one side
  }
  ThinningOptions options;
  options.radius = 0.15;
  const ThinnedCloud thin = thinPointCloud(points, given, options);
  EXPECT_GT(thin.kept.size(), 40u);
  for (Eigen::Index k = 0; k < thin.normals.rows(); ++k) {
    EXPECT_NEAR(thin.normals.row(k).dot(-normal.transpose()), 1.0, 1e-10) << "fitted and turned to the given side";
    EXPECT_LT(thin.flatness(k), 1e-14) << "a plane: the ball's covariance has rank 2";
  }
}

TEST(PointThinning, NormalsOfASphereArePointRadialWithinTheBallsCurvature) {
  std::mt19937 random(11);
  std::normal_distribution<double> g;
  const int n = 20000;
  Eigen::MatrixX3d points(n, 3);
  for (int i = 0; i < n; ++i) {
    Eigen::RowVector3d p(g(random), g(random), g(random));
    points.row(i) = 2.0 * p.normalized();
  }
  ThinningOptions options;
  options.radius = 0.2;
  const ThinnedCloud thin = thinPointCloud(points, Eigen::MatrixX3d(0, 3), options);
  double worst = 0.0;
  for (Eigen::Index k = 0; k < thin.points.rows(); ++k) {
    const double c = std::abs(thin.normals.row(k).dot(thin.points.row(k).normalized()));
    worst = std::max(worst, std::acos(std::min(1.0, c)));
  }
  // A ball of radius 0.2 on a sphere of radius 2: its points sample a cap whose centroid
  // direction is radial; random sampling tilts the fit by a few degrees at most.
  EXPECT_LT(worst * 180.0 / M_PI, 5.0);
  // Bounds from the two properties: kept points r apart ⇒ disjoint caps of chord radius r/2, at
  // most area/(π (r/2)²); every point within r of one ⇒ caps of chord radius r (area π r² on a
  // sphere) cover the sampled sphere, at least area/(π r²) (less 10% for the sampling's gaps).
  const double area = 4 * M_PI * 4.0;
  EXPECT_GE(static_cast<double>(thin.kept.size()), 0.9 * area / (M_PI * 0.04));
  EXPECT_LE(static_cast<double>(thin.kept.size()), area / (M_PI * 0.01) * 1.1);
}

TEST(PointThinning, BadRadiiAndSizesAreRefusedNamingTheField) {
  const Eigen::MatrixX3d points = Eigen::MatrixX3d::Random(10, 3);
  for (const double r : {0.0, -1.0, std::nan(""), static_cast<double>(INFINITY)}) {
    ThinningOptions options;
    options.radius = r;
    try {
      thinPointCloud(points, Eigen::MatrixX3d(0, 3), options);
      ADD_FAILURE() << "radius " << r << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind("radius:", 0), 0u) << e.what();
    }
  }
  ThinningOptions options;
  options.radius = 0.5;
  EXPECT_THROW(thinPointCloud(points, Eigen::MatrixX3d::Zero(3, 3), options), std::invalid_argument);
  Eigen::MatrixX3d bad = points;
  bad(4, 2) = std::nan("");
  EXPECT_THROW(thinPointCloud(bad, Eigen::MatrixX3d(0, 3), options), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::reference
