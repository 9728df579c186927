// VertexCoincidenceTerm (004_… §2.3.1, gluing part of E_pos).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <stdexcept>

#include "devsurf/terms/VertexCoincidenceTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

TEST(VertexCoincidenceTerm, JacobianMatchesFiniteDifferences) {
  VertexCoincidenceTerm term("glue", {{0, 3}, {1, 2}, {2, 0}}, {9, 0, 4, 14});
  EXPECT_EQ(term.numResiduals(), 9);
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(17, 1331));
}

TEST(VertexCoincidenceTerm, MeasuresTheGapOfEachPair) {
  VertexCoincidenceTerm term("glue", {{1, 0}, {0, 2}}, {0, 3, 6});
  Eigen::VectorXd x(9);
  x << 1, 2, 3, 1.5, 2, 1, 1, 2, 3;
  Eigen::VectorXd expected(6);
  expected << 0.5, 0, -2, 0, 0, 0;
  EXPECT_EQ(residuals(term, x), expected);
}

TEST(VertexCoincidenceTerm, RejectsInvalidInput) {
  EXPECT_THROW(VertexCoincidenceTerm("g", {{0, 3}}, {0, 3, 6}), std::invalid_argument);
  EXPECT_THROW(VertexCoincidenceTerm("g", {{-1, 0}}, {0, 3, 6}), std::invalid_argument);
  EXPECT_THROW(VertexCoincidenceTerm("g", {{1, 1}}, {0, 3, 6}), std::invalid_argument);
  EXPECT_THROW(VertexCoincidenceTerm("g", {{0, 1}}, {0, 2, 6}), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
