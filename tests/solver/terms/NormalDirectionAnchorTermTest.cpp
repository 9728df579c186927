// NormalDirectionAnchorTerm (the Gauss image's guard, models::quad_mesh::solveGaussImage).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <stdexcept>

#include "devsurf/terms/NormalDirectionAnchorTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

TEST(NormalDirectionAnchorTerm, JacobianMatchesFiniteDifferences) {
  Eigen::MatrixX3d u(2, 3);
  u << 0.6, 0.0, 0.8, 0.0, 1.0, 0.0;
  NormalDirectionAnchorTerm term("anchor", u, {5, 0});
  EXPECT_EQ(term.numResiduals(), 6);
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(8, 77));
}

TEST(NormalDirectionAnchorTerm, MeasuresOnlyTheSidewaysPartOfEachVector) {
  Eigen::MatrixX3d u(1, 3);
  u << 0.0, 0.0, 1.0;
  NormalDirectionAnchorTerm term("anchor", u, {0});
  Eigen::VectorXd x(3);
  x << 0.0, 0.0, 7.0;  // longer along its direction: no residual
  EXPECT_EQ(residuals(term, x), Eigen::Vector3d::Zero());
  x << 0.5, -1.0, 2.0;
  EXPECT_EQ(residuals(term, x), Eigen::Vector3d(0.5, -1.0, 0.0));
}

TEST(NormalDirectionAnchorTerm, RejectsInvalidInput) {
  EXPECT_THROW(NormalDirectionAnchorTerm("a", Eigen::MatrixX3d::Zero(2, 3), {0}), std::invalid_argument);
  EXPECT_THROW(NormalDirectionAnchorTerm("a", Eigen::MatrixX3d::Zero(1, 3), {-3}), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
