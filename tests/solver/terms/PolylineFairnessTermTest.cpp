// PolylineFairnessTerm (004_… §2.3.3, E_fair).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <stdexcept>

#include "devsurf/terms/PolylineFairnessTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

TEST(PolylineFairnessTerm, JacobianMatchesFiniteDifferencesWithScatteredPoints) {
  PolylineFairnessTerm term("fairness", {{0, 1, 2}, {1, 2, 3}, {4, 1, 0}}, {12, 0, 7, 3, 16});
  EXPECT_EQ(term.numResiduals(), 9);
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(20, 1321));
}

TEST(PolylineFairnessTerm, MeasuresTheSecondDifference) {
  // (0,0,0), (1,0,0), (3,1,0): v_i − 2v_j + v_k = (1, 1, 0); equally spaced on a line: 0.
  PolylineFairnessTerm term("fairness", {{2, 0, 1}, {2, 0, 3}}, {3, 6, 0, 9});
  Eigen::VectorXd x(12);
  x << 0, 0, 0, 1, 0, 0, 3, 1, 0, 2, 0, 0;
  Eigen::VectorXd expected(6);
  expected << 1, 1, 0, 0, 0, 0;
  EXPECT_EQ(residuals(term, x), expected);
}

TEST(PolylineFairnessTerm, RejectsInvalidInput) {
  EXPECT_THROW(PolylineFairnessTerm("f", {{0, 1, 3}}, {0, 3, 6}), std::invalid_argument);
  EXPECT_THROW(PolylineFairnessTerm("f", {{0, 1, -1}}, {0, 3, 6}), std::invalid_argument);
  EXPECT_THROW(PolylineFairnessTerm("f", {{0, 1, 0}}, {0, 3, 6}), std::invalid_argument);
  EXPECT_THROW(PolylineFairnessTerm("f", {{0, 1, 2}}, {0, 3, 4}), std::invalid_argument);
  EXPECT_THROW(PolylineFairnessTerm("f", {{0, 1, 2}}, {0, 3, -6}), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
