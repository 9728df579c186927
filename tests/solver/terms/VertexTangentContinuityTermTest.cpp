// VertexTangentContinuityTerm: two curves pass smoothly through a shared vertex.

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <stdexcept>

#include "devsurf/terms/VertexTangentContinuityTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

TEST(VertexTangentContinuityTerm, JacobianMatchesFiniteDifferences) {
  VertexTangentContinuityTerm term("tangent", 3, 0, 6);
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(9, 17));
}

TEST(VertexTangentContinuityTerm, VanishesExactlyWhenTheLegsAreCollinear) {
  Eigen::VectorXd x(9);
  x << -1.0, 2.0, 0.5, 0.0, 0.0, 0.0, 2.0, -4.0, -1.0;  // a = −v-side leg, b = 2 × the opposite
  VertexTangentContinuityTerm term("tangent", 3, 0, 6);
  EXPECT_EQ(residuals(term, x).cwiseAbs().maxCoeff(), 0.0);
  x[8] += 0.1;  // b leaves the line
  EXPECT_GT(residuals(term, x).cwiseAbs().maxCoeff(), 0.05);
}

TEST(VertexTangentContinuityTerm, RejectsSharedVariables) {
  EXPECT_THROW(VertexTangentContinuityTerm("t", 0, 1, 6), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
