// MappingRegularityTerm (004_… §2.3.3, E_map).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <stdexcept>

#include <Eigen/Geometry>

#include "devsurf/terms/MappingRegularityTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

TEST(MappingRegularityTerm, JacobianMatchesFiniteDifferences) {
  // The last quadruple has l = i: its coefficients are merged.
  std::vector<int> mesh, unfolding;
  for (int i = 0; i < 6; ++i) {
    mesh.push_back(6 * i);
    unfolding.push_back(6 * i + 3);
  }
  MappingRegularityTerm term("mapping", {{0, 1, 2, 4}, {3, 4, 5, 1}, {1, 2, 5, 1}}, mesh,
                             unfolding);
  EXPECT_EQ(term.numResiduals(), 3);
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(36, 1341));
}

TEST(MappingRegularityTerm, ComparesTangentialSecondDifferences) {
  // M: v_i = 0, v_j = (1,0,0), v_k = (2,1,0), v_l = (1,1,1): ⟨(0,1,0), (0,1,1)⟩ = 1.
  // M′: v′_i, v′_j, v′_k on a line equally spaced: 0.  Row: 1 − 0.
  Eigen::VectorXd x(24);
  x << 0, 0, 0, 1, 0, 0, 2, 1, 0, 1, 1, 1,  //
      0, 0, 0, 1, 0, 0, 2, 0, 0, 1, 1, 0;
  MappingRegularityTerm term("mapping", {{0, 1, 2, 3}}, {0, 3, 6, 9}, {12, 15, 18, 21});
  EXPECT_EQ(residuals(term, x)[0], 1.0);
  // A rigid motion of M as M′ gives 0.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 1, 1).normalized()).toRotationMatrix();
  for (int i = 0; i < 4; ++i) x.segment<3>(12 + 3 * i) = R * x.segment<3>(3 * i) + Eigen::Vector3d(1, 2, 3);
  EXPECT_NEAR(residuals(term, x)[0], 0.0, 1e-14);
}

TEST(MappingRegularityTerm, RejectsInvalidInput) {
  const std::vector<int> mesh = {0, 3, 6, 9}, unfolding = {12, 15, 18, 21};
  EXPECT_THROW(MappingRegularityTerm("m", {{0, 1, 2, 4}}, mesh, unfolding), std::invalid_argument);
  EXPECT_THROW(MappingRegularityTerm("m", {{0, 1, 0, 3}}, mesh, unfolding), std::invalid_argument);
  EXPECT_THROW(MappingRegularityTerm("m", {{0, 1, 2, 1}}, mesh, unfolding), std::invalid_argument);
  EXPECT_THROW(MappingRegularityTerm("m", {{0, 1, 2, 3}}, mesh, {12, 15, 18}),
               std::invalid_argument);
  EXPECT_THROW(MappingRegularityTerm("m", {{0, 1, 2, 3}}, mesh, {12, 15, 18, 10}),
               std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
