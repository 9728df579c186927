// ReferencePointDistanceTerm and ReferencePlaneDistanceTerm (004_… §2.3.2, E_prox,1 and E_prox,2).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

#include "devsurf/spatial/TriangleMeshProximity.h"
#include "devsurf/terms/ReferenceFootPoints.h"
#include "devsurf/terms/ReferencePlaneDistanceTerm.h"
#include "devsurf/terms/ReferencePointDistanceTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

/// The unit square [0, 1]² in z = 0 as two counter-clockwise triangles (normal +z).
std::shared_ptr<const spatial::TriangleMeshProximity> unitSquare() {
  Eigen::MatrixX3d V(4, 3);
  V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  Eigen::MatrixX3i T(2, 3);
  T << 0, 1, 2, 0, 2, 3;
  return std::make_shared<const spatial::TriangleMeshProximity>(V, T);
}

/// A curved 6×6 grid over [−1, 1]² (z = 0.3 (x² − y²)).
std::shared_ptr<const spatial::TriangleMeshProximity> saddle() {
  const int n = 6;
  Eigen::MatrixX3d V(n * n, 3);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double u = -1.0 + 2.0 * i / (n - 1), v = -1.0 + 2.0 * j / (n - 1);
      V.row(j * n + i) << u, v, 0.3 * (u * u - v * v);
    }
  Eigen::MatrixX3i T(2 * (n - 1) * (n - 1), 3);
  int t = 0;
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i;
      T.row(t++) << a, a + 1, a + n + 1;
      T.row(t++) << a, a + n + 1, a + n;
    }
  return std::make_shared<const spatial::TriangleMeshProximity>(V, T);
}

TEST(ReferencePointDistanceTerm, JacobianMatchesFiniteDifferencesWithFootPointsHeldFixed) {
  ReferencePointDistanceTerm term("proximity point", {3, 9, 0, 13}, saddle());
  EXPECT_EQ(term.numResiduals(), 12);
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(16, 1351));
}

TEST(ReferencePlaneDistanceTerm, JacobianMatchesFiniteDifferencesWithPlanesHeldFixed) {
  ReferencePlaneDistanceTerm term("proximity plane", {3, 9, 0, 13}, saddle());
  EXPECT_EQ(term.numResiduals(), 4);
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(16, 1352));
}

TEST(ReferencePointDistanceTerm, PointsFromTheFootPointsOnAUnitSquare) {
  ReferencePointDistanceTerm term("proximity point", {0, 3}, unitSquare());
  Eigen::VectorXd x(6);
  x << 0.3, 0.2, 0.5, 1.5, 0.5, 0.25;
  Eigen::VectorXd expected(6);
  expected << 0, 0, 0.5, 0.5, 0, 0.25;
  EXPECT_EQ(residuals(term, x), expected);
  EXPECT_EQ(term.footPoint(1), Eigen::Vector3d(1.0, 0.5, 0.0));
}

TEST(ReferencePlaneDistanceTerm, MeasuresSignedDistanceFromTheFootTrianglesPlane) {
  ReferencePlaneDistanceTerm term("proximity plane", {0, 3, 6}, unitSquare());
  Eigen::VectorXd x(9);
  x << 0.3, 0.2, 0.5, 1.5, 0.5, 0.25, 0.7, 0.9, -0.125;
  Eigen::VectorXd expected(3);
  expected << 0.5, 0.25, -0.125;  // beside the square only the normal offset counts
  EXPECT_EQ(residuals(term, x), expected);
  EXPECT_EQ(term.normal(2), Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(term.footPoint(2), Eigen::Vector3d(0.7, 0.9, 0.0));
}

TEST(ReferencePlaneDistanceTerm, PlanesAreRenewedOnlyByLinearizeAt) {
  ReferencePlaneDistanceTerm term("proximity plane", {0}, saddle());
  Eigen::VectorXd x(3);
  x << -0.9, 0.05, 1.0;
  term.linearizeAt(x);
  const Eigen::Vector3d n0 = term.normal(0);
  double r = 0;
  x << 0.9, -0.05, 1.0;
  term.evaluate(x, &r, nullptr);
  EXPECT_NEAR(r, n0.dot(x - term.footPoint(0)), 1e-15);  // the old plane still
  term.linearizeAt(x);
  EXPECT_GT((term.normal(0) - n0).norm(), 0.1);  // the saddle tilts the other way there
  term.evaluate(x, &r, nullptr);
  EXPECT_NEAR(r, term.normal(0).dot(x - term.footPoint(0)), 1e-15);
  EXPECT_GT(r, 0.0);
}

TEST(ReferenceFootPoints, TwoTermsOnOneSetQueryOncePerPositionAndLinearizeAsTermsOfTheirOwn) {
  const auto reference = saddle();
  const std::vector<int> offsets{3, 9, 0, 13};
  auto feet = std::make_shared<ReferenceFootPoints>(reference, offsets);
  ReferencePointDistanceTerm sharedPoint("proximity point", feet);
  ReferencePlaneDistanceTerm sharedPlane("proximity plane", feet);
  ReferencePointDistanceTerm ownPoint("proximity point", offsets, reference);
  ReferencePlaneDistanceTerm ownPlane("proximity plane", offsets, reference);
  for (int round = 0; round < 3; ++round) {
    const Eigen::VectorXd x = randomVector(16, 1360 + round);
    for (engine::Term* term : std::vector<engine::Term*>{&sharedPoint, &sharedPlane, &ownPoint, &ownPlane})
      term->linearizeAt(x);
    EXPECT_EQ(feet->queryCount(), 4 * (round + 1)) << "one query per point and position";
    for (int i = 0; i < 4; ++i) {
      const spatial::ClosestPoint direct = reference->closest(x.segment<3>(offsets[i]));
      EXPECT_EQ(sharedPoint.footPoint(i), direct.point);
      EXPECT_EQ(sharedPlane.footPoint(i), direct.point);
      EXPECT_EQ(sharedPlane.normal(i), direct.normal);
      EXPECT_EQ(ownPoint.footPoint(i), direct.point);
      EXPECT_EQ(ownPlane.normal(i), direct.normal);
    }
    EXPECT_EQ(residuals(sharedPoint, x), residuals(ownPoint, x));
    EXPECT_EQ(residuals(sharedPlane, x), residuals(ownPlane, x));
  }
}

TEST(ReferenceFootPoints, APointMovedByOneUlpIsQueriedAgainAndOtherUnknownsAreIgnored) {
  auto feet = std::make_shared<ReferenceFootPoints>(saddle(), std::vector<int>{0, 4});
  Eigen::VectorXd x(7);
  x << -0.9, 0.05, 1.0, 42.0, 0.9, -0.05, 1.0;
  const std::vector<spatial::ClosestPoint> first = feet->at(x);
  EXPECT_EQ(feet->queryCount(), 2);
  x[3] = -7.0;  // not a point of the set
  feet->at(x);
  EXPECT_EQ(feet->queryCount(), 2);
  x[5] = std::nextafter(x[5], 1.0);
  feet->at(x);
  EXPECT_EQ(feet->queryCount(), 4);
  x << 0.9, -0.05, 1.0, 0.0, -0.9, 0.05, 1.0;  // the two points swapped
  const std::vector<spatial::ClosestPoint>& swapped = feet->at(x);
  EXPECT_EQ(feet->queryCount(), 6);
  EXPECT_EQ(swapped[0].point, first[1].point);
  EXPECT_EQ(swapped[1].point, first[0].point);
}

TEST(ReferenceDistanceTerms, RejectInvalidInput) {
  EXPECT_THROW(ReferencePointDistanceTerm("p", {0}, nullptr), std::invalid_argument);
  EXPECT_THROW(ReferencePlaneDistanceTerm("p", {0}, nullptr), std::invalid_argument);
  EXPECT_THROW(ReferencePointDistanceTerm("p", {0, 2}, unitSquare()), std::invalid_argument);
  EXPECT_THROW(ReferencePlaneDistanceTerm("p", {-3}, unitSquare()), std::invalid_argument);
  EXPECT_THROW(ReferencePointDistanceTerm("p", std::shared_ptr<ReferenceFootPoints>()), std::invalid_argument);
  EXPECT_THROW(ReferencePlaneDistanceTerm("p", std::make_shared<ReferenceFootPoints>(unitSquare(), std::vector<int>{0, 1})),
               std::invalid_argument);
  EXPECT_THROW(ReferenceFootPoints(nullptr, {0}), std::invalid_argument);
  EXPECT_THROW(ReferenceFootPoints(unitSquare(), {0, -1}), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
