// CheckerboardIsometryTerm (004_… eq. 1).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

#include "devsurf/terms/CheckerboardIsometryTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

/// Two quads and a triangle on 6 vertices: [0,1,2,3], [1,4,2], [2,4,5,3].
const std::vector<std::array<int, 4>> kIsometryFaces = {{0, 1, 2, 3}, {1, 4, 2, -1}, {2, 4, 5, 3}};

TEST(CheckerboardIsometryTerm, JacobianMatchesFiniteDifferencesOnQuadsAndATriangle) {
  // M and M′ interleaved: vertex i of M at 6i, its image at 6i + 3.
  std::vector<int> mesh, unfolding;
  for (int i = 0; i < 6; ++i) {
    mesh.push_back(6 * i);
    unfolding.push_back(6 * i + 3);
  }
  CheckerboardIsometryTerm term("isometry", kIsometryFaces, mesh, unfolding);
  EXPECT_EQ(term.numResiduals(), 9);
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(36, 1301));
  // Blocks: M first, then M′ (the model's layout).
  std::vector<int> mesh2, unfolding2;
  for (int i = 0; i < 6; ++i) {
    mesh2.push_back(3 * i);
    unfolding2.push_back(18 + 3 * i);
  }
  CheckerboardIsometryTerm blocks("isometry", kIsometryFaces, mesh2, unfolding2);
  expectJacobianMatches(blocks, randomVector(36, 1302));
}

TEST(CheckerboardIsometryTerm, ComparesDiagonalsOfASquareWithThoseOfARectangle) {
  // M: unit square in z = 0; M′: the 2 × 1 rectangle. d0 = v0 − v2, d1 = v1 − v3.
  // M: ‖d0‖² = 2, ‖d1‖² = 2, ⟨d0, d1⟩ = 0;  M′: 5, 5, −3.  Triangle [0, 1, 2]: edges 1, 1, 2
  // against 4, 1, 5.
  Eigen::VectorXd x(24);
  x << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,  //
      0, 0, 0, 2, 0, 0, 2, 1, 0, 0, 1, 0;
  const std::vector<int> mesh = {0, 3, 6, 9}, unfolding = {12, 15, 18, 21};
  CheckerboardIsometryTerm term("isometry", {{0, 1, 2, 3}, {0, 1, 2, -1}}, mesh, unfolding);
  Eigen::VectorXd expected(6);
  expected << -3, -3, 3, -3, 0, -3;
  EXPECT_EQ(residuals(term, x), expected);
}

TEST(CheckerboardIsometryTerm, VanishesForARigidMotionOfANonPlanarMesh) {
  Eigen::VectorXd x = randomVector(36, 1303);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d shift(0.3, -1.2, 2.0);
  for (int i = 0; i < 6; ++i) x.segment<3>(18 + 3 * i) = R * x.segment<3>(3 * i) + shift;
  std::vector<int> mesh, unfolding;
  for (int i = 0; i < 6; ++i) {
    mesh.push_back(3 * i);
    unfolding.push_back(18 + 3 * i);
  }
  CheckerboardIsometryTerm term("isometry", kIsometryFaces, mesh, unfolding);
  EXPECT_LT(residuals(term, x).cwiseAbs().maxCoeff(), 1e-14);
  x[18] += 0.1;  // moving one image vertex breaks it
  EXPECT_GT(residuals(term, x).cwiseAbs().maxCoeff(), 1e-3);
}

TEST(CheckerboardIsometryTerm, RejectsInvalidInput) {
  const std::vector<int> mesh = {0, 3, 6, 9}, unfolding = {12, 15, 18, 21};
  using F = std::vector<std::array<int, 4>>;
  EXPECT_THROW(CheckerboardIsometryTerm("i", F{{0, 1, 2, 3}}, mesh, {12, 15, 18}),
               std::invalid_argument);                                                // count
  EXPECT_THROW(CheckerboardIsometryTerm("i", F{{0, 1, 2, 4}}, mesh, unfolding),
               std::invalid_argument);                                                // range
  EXPECT_THROW(CheckerboardIsometryTerm("i", F{{0, 1, 2, -2}}, mesh, unfolding),
               std::invalid_argument);
  EXPECT_THROW(CheckerboardIsometryTerm("i", F{{0, 1, 1, 3}}, mesh, unfolding),
               std::invalid_argument);                                                // repeat
  EXPECT_THROW(CheckerboardIsometryTerm("i", F{{0, 1, 2, 3}}, mesh, {12, 15, 18, 8}),
               std::invalid_argument);                                                // overlap
  EXPECT_THROW(CheckerboardIsometryTerm("i", F{{0, 1, 2, 3}}, {0, 3, 5, 9}, unfolding),
               std::invalid_argument);
  EXPECT_THROW(CheckerboardIsometryTerm("i", F{{0, 1, 2, 3}}, {-3, 3, 6, 9}, unfolding),
               std::invalid_argument);                                                // negative
  try {
    CheckerboardIsometryTerm("i", F{{0, 1, 2, 3}, {0, 1, 7, -1}}, mesh, unfolding);
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("face 1"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace devsurf::terms
