// ReferencePointDistanceTerm and ReferencePlaneDistanceTerm (004_… §2.3.2, E_prox,1 and E_prox,2).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <cmath>
#include <memory>
#include <stdexcept>

#include "devsurf/spatial/TriangleMeshProximity.h"
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

TEST(ReferenceDistanceTerms, RejectInvalidInput) {
  EXPECT_THROW(ReferencePointDistanceTerm("p", {0}, nullptr), std::invalid_argument);
  EXPECT_THROW(ReferencePlaneDistanceTerm("p", {0}, nullptr), std::invalid_argument);
  EXPECT_THROW(ReferencePointDistanceTerm("p", {0, 2}, unitSquare()), std::invalid_argument);
  EXPECT_THROW(ReferencePlaneDistanceTerm("p", {-3}, unitSquare()), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
