// TangentDistanceTerm (000_… §5 "Isometric mapping", 003_… §5.2.5 TDM).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "devsurf/engine/JacobianCheck.h"
#include "devsurf/terms/TangentDistanceTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::randomVector;
using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::residuals;

/// Regular counter-clockwise N-gon of circumradius R about the origin.
std::vector<Eigen::Vector2d> regularPolygon(int N, double R) {
  std::vector<Eigen::Vector2d> p;
  for (int i = 0; i < N; ++i) {
    const double t = 2.0 * M_PI * i / N;
    p.emplace_back(R * std::cos(t), R * std::sin(t));
  }
  return p;
}

TEST(TangentDistanceTerm, JacobianMatchesFiniteDifferencesWithFootPointsHeldFixed) {
  // checkJacobian calls linearizeAt(x) once: foot points and normals stay the constants of that
  // iteration while it differences, as in the solver.
  TangentDistanceTerm closed("tdm", {0, 2, 6, 8}, regularPolygon(7, 0.8), true);
  EXPECT_EQ(closed.numResiduals(), 4);
  expectNoDuplicateEntries(closed);
  expectJacobianMatches(closed, randomVector(10, 61));
  TangentDistanceTerm open("tdm", {1, 3, 5}, {{-1, 0}, {0, 0.5}, {0.5, 0.4}, {1, -1}}, false);
  expectJacobianMatches(open, randomVector(7, 62));
}

TEST(TangentDistanceTerm, MeasuresSignedDistanceFromTheTangentOfARegularPolygon) {
  const int N = 8;
  const double R = 1.0, eps = 0.05;
  const auto poly = regularPolygon(N, R);
  TangentDistanceTerm term("tdm", {0, 2, 4, 6}, poly, true);
  const Eigen::Vector2d mid = 0.5 * (poly[2] + poly[3]);
  const Eigen::Vector2d outward = mid.normalized();  // the segment's normal for a regular polygon
  Eigen::VectorXd x(8);
  x.segment<2>(0) = poly[5];                        // on a corner
  x.segment<2>(2) = mid;                            // inside a segment
  x.segment<2>(4) = (1.0 + eps) * poly[1];          // pushed out radially from a corner
  x.segment<2>(6) = mid - eps * outward;            // pushed inward from a segment
  const Eigen::VectorXd r = residuals(term, x);
  EXPECT_NEAR(r[0], 0.0, 1e-15);
  EXPECT_NEAR(r[1], 0.0, 1e-15);
  EXPECT_NEAR(r[2], eps * R, 1e-15);  // corner normal: bisector = radial direction
  EXPECT_NEAR(r[3], -eps, 1e-15);
  EXPECT_LT((term.normal(2) - poly[1].normalized()).norm(), 1e-15);
  EXPECT_LT((term.footPoint(3) - mid).norm(), 1e-15);
}

TEST(TangentDistanceTerm, FootPointsAreRenewedOnlyByLinearizeAt) {
  TangentDistanceTerm term("tdm", {0}, {{0, 0}, {1, 0}, {1, 1}, {0, 1}}, true);
  Eigen::VectorXd x(2);
  x << 0.5, -0.1;
  double r = 0;
  term.linearizeAt(x);
  term.evaluate(x, &r, nullptr);
  EXPECT_NEAR(r, 0.1, 1e-15);  // bottom side, outward normal (0, −1)
  x << 1.2, 0.5;
  term.evaluate(x, &r, nullptr);
  EXPECT_NEAR(r, -0.5, 1e-15);  // still the old tangent line y = 0
  term.linearizeAt(x);
  term.evaluate(x, &r, nullptr);
  EXPECT_NEAR(r, 0.2, 1e-15);  // right side now
  EXPECT_EQ(term.footPoint(0), Eigen::Vector2d(1.0, 0.5));
  EXPECT_EQ(term.normal(0), Eigen::Vector2d(1.0, 0.0));
}

TEST(TangentDistanceTerm, OpenEndsExtendAlongTheEndTangent) {
  TangentDistanceTerm term("tdm", {0, 2}, {{0, 0}, {1, 0}, {2, 1}}, false);
  Eigen::VectorXd x(4);
  x << -0.5, 0.0, -0.5, 0.3;
  const Eigen::VectorXd r = residuals(term, x);
  EXPECT_NEAR(r[0], 0.0, 1e-15);
  EXPECT_NEAR(r[1], -0.3, 1e-15);
  // An interior kink takes the normalized sum of the two segment normals.
  Eigen::Vector2d foot, normal;
  term.project(Eigen::Vector2d(1.0, 0.0), foot, normal);
  const Eigen::Vector2d expected =
      (Eigen::Vector2d(0, -1) + Eigen::Vector2d(1, -1).normalized()).normalized();
  EXPECT_LT((normal - expected).norm(), 1e-15);
}

TEST(TangentDistanceTerm, RejectsDegeneratePolylines) {
  EXPECT_THROW(TangentDistanceTerm("t", {0}, {{0, 0}}, false), std::invalid_argument);
  EXPECT_THROW(TangentDistanceTerm("t", {0}, {{0, 0}, {1, 0}}, true), std::invalid_argument);
  EXPECT_THROW(TangentDistanceTerm("t", {0}, {{0, 0}, {0, 0}, {1, 0}}, false),
               std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
