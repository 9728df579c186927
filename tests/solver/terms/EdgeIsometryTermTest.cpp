// EdgeIsometryTerm (000_… eq. 12, 003_… §5.2.5) and gridEdgeAndDiagonalPairs.

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "devsurf/engine/JacobianCheck.h"
#include "devsurf/spline/Basis.h"
#include "devsurf/terms/EdgeIsometryTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::randomVector;
using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::residuals;

TEST(EdgeIsometryTerm, JacobianMatchesFiniteDifferencesOnASampledStrip) {
  // Curves a, b (6 control points each), sampled at U parameters; development after them.
  const spline::KnotVector k = spline::KnotVector::clampedUniform(3, 6);
  const std::vector<double> params = k.uniformSamples(5);
  const int U = static_cast<int>(params.size());
  LinearPoints a{spline::evaluationMatrix(k, params, 0), 0};
  LinearPoints b{spline::evaluationMatrix(k, params, 0), 18};
  std::vector<int> developed;
  for (int i = 0; i < 2 * U; ++i) developed.push_back(36 + 2 * i);
  EdgeIsometryTerm term("isometry", {a, b}, developed, gridEdgeAndDiagonalPairs(U, 2));
  EXPECT_EQ(term.numResiduals(), 2 * (U - 1) + U + 2 * (U - 1));  // a/b edges, rulings, diagonals
  expectNoDuplicateEntries(term);  // neighbouring samples share control points
  expectJacobianMatches(term, randomVector(36 + 4 * U, 51));
}

TEST(EdgeIsometryTerm, JacobianMatchesFiniteDifferencesWithInterleavedFreePoints) {
  // Development interleaved with the 3D points: point i at 5i, its image at 5i + 3.
  // One point set per vertex, since the 3D points are not 3-strided in x.
  const int n = 6;
  std::vector<int> developed;
  for (int i = 0; i < n; ++i) developed.push_back(5 * i + 3);
  std::vector<LinearPoints> points;
  for (int i = 0; i < n; ++i) points.push_back(LinearPoints::identity(1, 5 * i));
  EdgeIsometryTerm term("isometry", points, developed, gridEdgeAndDiagonalPairs(3, 2));
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(5 * n, 52));
}

TEST(EdgeIsometryTerm, VanishesOnACylinderAndItsUnrolledStrip) {
  // Quads between two rulings of a cylinder are planar rectangles (chord × height): the strip
  // unrolled quad by quad is an exact development for all edges and diagonals.
  const int U = 6;
  const double R = 1.3, h = 0.7;
  Eigen::VectorXd x(3 * 2 * U + 2 * 2 * U);
  std::vector<int> developed;
  double arc = 0.0;
  for (int i = 0; i < U; ++i) {
    const double t = 0.3 * i + 0.05 * i * i;
    if (i > 0) {
      const double tp = 0.3 * (i - 1) + 0.05 * (i - 1) * (i - 1);
      arc += 2.0 * R * std::sin(0.5 * (t - tp));  // chord length
    }
    for (int j = 0; j < 2; ++j) {
      const int v = j * U + i;
      x.segment<3>(3 * v) = Eigen::Vector3d(R * std::cos(t), R * std::sin(t), j * h);
      x.segment<2>(6 * U + 2 * v) = Eigen::Vector2d(arc, j * h);
    }
  }
  for (int v = 0; v < 2 * U; ++v) developed.push_back(6 * U + 2 * v);
  const auto pairs = gridEdgeAndDiagonalPairs(U, 2);
  EdgeIsometryTerm term("isometry", LinearPoints::identity(2 * U, 0), developed, pairs);
  EXPECT_LT(residuals(term, x).cwiseAbs().maxCoeff(), 1e-14);

  // A development scaled by 2 has residuals (1 − 4)·‖v_i − v_j‖².
  Eigen::VectorXd y = x;
  y.tail(4 * U) *= 2.0;
  const Eigen::VectorXd r = residuals(term, y);
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    const double d2 =
        (x.segment<3>(3 * pairs[p].first) - x.segment<3>(3 * pairs[p].second)).squaredNorm();
    EXPECT_NEAR(r[p], -3.0 * d2, 1e-13);
  }
  EXPECT_GT(r.cwiseAbs().minCoeff(), 1e-3);
}

TEST(EdgeIsometryTerm, GridPairsAreEdgesAndBothDiagonals) {
  const auto pairs = gridEdgeAndDiagonalPairs(4, 3);
  EXPECT_EQ(pairs.size(), 9u + 8u + 12u);
  std::vector<std::pair<int, int>> sorted;
  for (auto [i, j] : pairs) sorted.emplace_back(std::min(i, j), std::max(i, j));
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end());
  for (auto p : {std::pair{0, 1}, std::pair{0, 4}, std::pair{0, 5}, std::pair{1, 4},
                 std::pair{6, 11}, std::pair{7, 10}, std::pair{10, 11}})
    EXPECT_NE(std::find(sorted.begin(), sorted.end(), p), sorted.end())
        << p.first << "," << p.second;
  EXPECT_EQ(std::find(sorted.begin(), sorted.end(), std::pair{0, 2}), sorted.end());
  EXPECT_EQ(gridEdgeAndDiagonalPairs(1, 1).size(), 0u);
  EXPECT_THROW(gridEdgeAndDiagonalPairs(0, 2), std::invalid_argument);
}

TEST(EdgeIsometryTerm, RejectsInvalidInput) {
  const LinearPoints p = LinearPoints::identity(3, 0);
  EXPECT_THROW(EdgeIsometryTerm("i", p, {9, 11}, {{0, 1}}), std::invalid_argument);  // count
  EXPECT_THROW(EdgeIsometryTerm("i", p, {9, 11, 13}, {{0, 3}}), std::invalid_argument);
  EXPECT_THROW(EdgeIsometryTerm("i", p, {9, 11, 13}, {{1, 1}}), std::invalid_argument);
  EXPECT_THROW(EdgeIsometryTerm("i", p, {2, 11, 13}, {{0, 1}}), std::invalid_argument);  // overlap
}

}  // namespace
}  // namespace devsurf::terms
