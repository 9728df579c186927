// spatial::SegmentSetProximity: closest points on a set of segments (CGAL's AABB tree), checked
// against a brute-force scan.
#include <gtest/gtest.h>

#include <random>

#include "devsurf/spatial/SegmentSetProximity.h"

namespace devsurf::spatial {
namespace {

Eigen::Vector3d closestOnSegment(const Eigen::Vector3d& q, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double t = std::clamp((q - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
  return a + t * (b - a);
}

TEST(SegmentSetProximity, FindsTheClosestPointOfHundredsOfRandomSegmentSetsAsABruteForceScanDoes) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 1 + trial % 40;
    Eigen::MatrixX3d A(n, 3), B(n, 3);
    for (int k = 0; k < n; ++k) {
      A.row(k) << unit(random), unit(random), trial % 2 ? 0.0 : unit(random);
      B.row(k) = A.row(k) + Eigen::RowVector3d(unit(random), unit(random), trial % 2 ? 0.0 : unit(random)) * 0.3;
    }
    const SegmentSetProximity set(A, B);
    for (int query = 0; query < 20; ++query) {
      const Eigen::Vector3d q(2 * unit(random), 2 * unit(random), 2 * unit(random));
      double best = 1e300;
      for (int k = 0; k < n; ++k) best = std::min(best, (closestOnSegment(q, A.row(k), B.row(k)) - q).norm());
      const ClosestSegmentPoint found = set.closest(q);
      EXPECT_NEAR((found.point - q).norm(), best, 1e-12);
      ASSERT_GE(found.segment, 0);
      ASSERT_LT(found.segment, n);
      EXPECT_LT((closestOnSegment(q, A.row(found.segment), B.row(found.segment)) - found.point).norm(), 1e-12);
    }
  }
}

TEST(SegmentSetProximity, RefusesEmptyMismatchedDegenerateOrNonFiniteInput) {
  EXPECT_THROW(SegmentSetProximity(Eigen::MatrixX3d(0, 3), Eigen::MatrixX3d(0, 3)), std::invalid_argument);
  EXPECT_THROW(SegmentSetProximity(Eigen::MatrixX3d::Zero(2, 3), Eigen::MatrixX3d::Ones(1, 3)), std::invalid_argument);
  EXPECT_THROW(SegmentSetProximity(Eigen::MatrixX3d::Zero(1, 3), Eigen::MatrixX3d::Zero(1, 3)), std::invalid_argument);
  Eigen::MatrixX3d nan = Eigen::MatrixX3d::Zero(1, 3);
  nan(0, 1) = std::nan("");
  EXPECT_THROW(SegmentSetProximity(nan, Eigen::MatrixX3d::Ones(1, 3)), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::spatial
