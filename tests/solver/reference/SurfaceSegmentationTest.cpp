// reference::segmentByNormals (issue 15): a starting segmentation for 004_… §5.
#include <gtest/gtest.h>

#include <random>
#include <set>

#include <Eigen/Geometry>

#include "devsurf/reference/SurfaceSegmentation.h"

namespace devsurf::reference {
namespace {

/// A sheet folded along x = 0 by `angle` (two planes), n × n quads per side as triangles, turned
/// by `turn`. sideOf[t] is 0 for x < 0 and 1 otherwise.
void foldedSheet(int n, double angle, const Eigen::Matrix3d& turn, Eigen::MatrixX3d& V, Eigen::MatrixX3i& T,
                 std::vector<int>& sideOf) {
  const int columns = 2 * n + 1;
  V.resize(columns * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i < columns; ++i) {
      const double x = (i - n) / static_cast<double>(n), y = j / static_cast<double>(n);
      const Eigen::Vector3d p = x <= 0 ? Eigen::Vector3d(x, y, 0) : Eigen::Vector3d(x * std::cos(angle), y, x * std::sin(angle));
      V.row(j * columns + i) = (turn * p).transpose();
    }
  T.resize(4 * n * n, 3);
  sideOf.clear();
  int t = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < 2 * n; ++i) {
      const int a = j * columns + i;
      T.row(t++) << a, a + 1, a + columns + 1;
      T.row(t++) << a, a + columns + 1, a + columns;
      sideOf.push_back(i < n ? 0 : 1);
      sideOf.push_back(i < n ? 0 : 1);
    }
}

TEST(SurfaceSegmentation, SplitsAFoldedSheetByNormalsExactlyAtItsFoldForHundredsOfPosesAndAngles) {
  std::mt19937 random(15);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const double angle = (25.0 + 130.0 * unit(random)) * M_PI / 180.0;
    const Eigen::Matrix3d turn =
        Eigen::AngleAxisd(2.0 * M_PI * unit(random), Eigen::Vector3d(unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5).normalized())
            .toRotationMatrix();
    Eigen::MatrixX3d V;
    Eigen::MatrixX3i T;
    std::vector<int> sideOf;
    foldedSheet(6, angle, turn, V, T, sideOf);
    NormalSegmentationOptions options;
    options.patches = 2;
    options.positionWeight = 0.0;  // the Gauss image alone: two points
    options.seed = static_cast<std::uint32_t>(trial);
    const std::vector<int> label = segmentByNormals(V, T, options);
    ASSERT_EQ(label.size(), sideOf.size());
    // Labels are numbered by first triangle: the first triangle's side is patch 0.
    for (std::size_t t = 0; t < label.size(); ++t)
      ASSERT_EQ(label[t], sideOf[t] == sideOf[0] ? 0 : 1) << "trial " << trial << ", fold " << angle * 180 / M_PI << "°, triangle " << t;
  }
}

TEST(SurfaceSegmentation, WithPositionWeightSeparatesTwoParallelPlatesThatNormalsAloneCannot) {
  // Two unit squares in z = 0 and z = 3 (same normal): by normal alone one cluster is as good as
  // another; with positions the plates are the patches.
  Eigen::MatrixX3d V(8, 3);
  V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 3, 1, 0, 3, 1, 1, 3, 0, 1, 3;
  Eigen::MatrixX3i T(4, 3);
  T << 0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7;
  NormalSegmentationOptions options;
  options.patches = 2;
  EXPECT_EQ(segmentByNormals(V, T, options), (std::vector<int>{0, 0, 1, 1}));
}

TEST(SurfaceSegmentation, IsDeterministicForASeedAndNeverReturnsMorePatchesThanAsked) {
  Eigen::MatrixX3d V;
  Eigen::MatrixX3i T;
  std::vector<int> sideOf;
  foldedSheet(8, 1.0, Eigen::Matrix3d::Identity(), V, T, sideOf);
  for (int k : {1, 3, 7, 40}) {
    NormalSegmentationOptions options;
    options.patches = k;
    const std::vector<int> a = segmentByNormals(V, T, options), b = segmentByNormals(V, T, options);
    EXPECT_EQ(a, b);
    const std::set<int> ids(a.begin(), a.end());
    EXPECT_LE(static_cast<int>(ids.size()), k);
    EXPECT_EQ(*ids.begin(), 0);
    EXPECT_EQ(*ids.rbegin(), static_cast<int>(ids.size()) - 1) << "ids are compact";
  }
}

TEST(SurfaceSegmentation, RefusesWhatItCannotSegment) {
  Eigen::MatrixX3d V(3, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  Eigen::MatrixX3i T(1, 3);
  T << 0, 1, 2;
  NormalSegmentationOptions bad;
  bad.patches = 0;
  EXPECT_THROW(segmentByNormals(V, T, bad), std::invalid_argument);
  EXPECT_THROW(segmentByNormals(V, Eigen::MatrixX3i(0, 3)), std::invalid_argument);
  Eigen::MatrixX3i out(1, 3);
  out << 0, 1, 3;
  EXPECT_THROW(segmentByNormals(V, out), std::invalid_argument);
}

TEST(SurfaceSegmentation, SplitsPointsOnABoxsSixSidesOneLabelPerSideInHundredsOfPoses) {
  std::mt19937 random(1506);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::Matrix3d turn =
        Eigen::AngleAxisd(2.0 * M_PI * unit(random), Eigen::Vector3d(unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5).normalized())
            .toRotationMatrix();
    const Eigen::Vector3d size(0.5 + unit(random), 0.5 + unit(random), 0.5 + unit(random));
    const int perSide = 40;
    Eigen::MatrixX3d points(6 * perSide, 3), normals(6 * perSide, 3);
    std::vector<int> sideOf;
    for (int side = 0; side < 6; ++side) {
      const int axis = side / 2;
      const double sign = side % 2 ? 1.0 : -1.0;
      for (int k = 0; k < perSide; ++k) {
        Eigen::Vector3d p(size.x() * (unit(random) - 0.5), size.y() * (unit(random) - 0.5), size.z() * (unit(random) - 0.5));
        p[axis] = sign * 0.5 * size[axis];
        const int row = side * perSide + k;
        points.row(row) = (turn * p).transpose();
        normals.row(row) = (turn * (sign * Eigen::Vector3d::Unit(axis))).transpose();
        sideOf.push_back(side);
      }
    }
    NormalSegmentationOptions options;
    options.patches = 6;
    options.positionWeight = 0.0;  // the Gauss image alone: six points
    options.seed = static_cast<std::uint32_t>(trial);
    const std::vector<int> label = segmentPointsByNormals(points, normals, options);
    ASSERT_EQ(label.size(), sideOf.size());
    // One label per side, a different one for each side.
    std::set<std::pair<int, int>> pairs;
    for (std::size_t j = 0; j < label.size(); ++j) pairs.insert({sideOf[j], label[j]});
    EXPECT_EQ(pairs.size(), 6u) << "trial " << trial;
    std::set<int> labels;
    for (const auto& [side, l] : pairs) labels.insert(l);
    EXPECT_EQ(labels.size(), 6u) << "trial " << trial;
  }
}

TEST(SurfaceSegmentation, PointsWithOneNormalAreSplitByPositionWhenItIsWeighed) {
  // Two parallel plates facing one way, far apart: the normals cannot tell them apart.
  Eigen::MatrixX3d points(200, 3), normals(200, 3);
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int j = 0; j < 200; ++j) {
    points.row(j) << unit(random) + (j < 100 ? 0.0 : 5.0), unit(random), 0.0;
    normals.row(j) << 0.0, 0.0, 1.0;
  }
  NormalSegmentationOptions options;
  options.patches = 2;
  options.positionWeight = 1.0;
  const std::vector<int> label = segmentPointsByNormals(points, normals, options);
  for (int j = 0; j < 200; ++j) EXPECT_EQ(label[static_cast<std::size_t>(j)], j < 100 ? 0 : 1) << j;
  EXPECT_THROW(segmentPointsByNormals(points, Eigen::MatrixX3d(3, 3), options), std::invalid_argument);
  EXPECT_THROW(segmentPointsByNormals(Eigen::MatrixX3d(0, 3), Eigen::MatrixX3d(0, 3), options), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::reference
