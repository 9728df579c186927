// PlanarPolygonTerm (000_… §3.1: planar R…R faces).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include <Eigen/Geometry>

#include "devsurf/engine/JacobianCheck.h"
#include "devsurf/terms/PlanarPolygonTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::randomVector;
using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::residuals;

TEST(PlanarPolygonTerm, JacobianMatchesFiniteDifferences) {
  PlanarPolygonTerm quad("planar", 0, {3, 6, 9, 12});
  EXPECT_EQ(quad.numResiduals(), 4);
  expectNoDuplicateEntries(quad);
  expectJacobianMatches(quad, randomVector(15, 31));
  // Normal after the vertices, vertices out of order in x.
  PlanarPolygonTerm pentagon("planar", 18, {9, 0, 12, 3, 15});
  expectNoDuplicateEntries(pentagon);
  expectJacobianMatches(pentagon, randomVector(21, 32));
}

TEST(PlanarPolygonTerm, VanishesOnAPlanarPolygonInATiltedPlane) {
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d center(0.3, -1.0, 2.0);
  Eigen::VectorXd x(3 + 3 * 5);
  x.head<3>() = R.col(2);
  for (int i = 0; i < 5; ++i) {
    const double t = 2.0 * M_PI * i / 5.0;
    x.segment<3>(3 + 3 * i) = center + 1.5 * std::cos(t) * R.col(0) + 0.8 * std::sin(t) * R.col(1);
  }
  PlanarPolygonTerm term("planar", 0, {3, 6, 9, 12, 15});
  EXPECT_LT(residuals(term, x).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(PlanarPolygonTerm, LiftedVertexGivesPlusAndMinusItsHeight) {
  // Unit square in z = 0 with vertex 2 lifted by h; n = e_z. Edge residuals: 0, h, −h, 0.
  const double h = 0.25;
  Eigen::VectorXd x(15);
  x << 0, 0, 1,  0, 0, 0,  1, 0, 0,  1, 1, h,  0, 1, 0;
  PlanarPolygonTerm term("planar", 0, {3, 6, 9, 12});
  const Eigen::VectorXd r = residuals(term, x);
  EXPECT_DOUBLE_EQ(r[0], 0.0);
  EXPECT_DOUBLE_EQ(r[1], h);
  EXPECT_DOUBLE_EQ(r[2], -h);
  EXPECT_DOUBLE_EQ(r[3], 0.0);
}

TEST(PlanarPolygonTerm, RejectsDegenerateInput) {
  EXPECT_THROW(PlanarPolygonTerm("p", 0, {3, 6}), std::invalid_argument);
  EXPECT_THROW(PlanarPolygonTerm("p", 0, {3, 6, 7}), std::invalid_argument);   // overlap
  EXPECT_THROW(PlanarPolygonTerm("p", 4, {3, 9, 12}), std::invalid_argument);  // normal overlaps
}

}  // namespace
}  // namespace devsurf::terms
