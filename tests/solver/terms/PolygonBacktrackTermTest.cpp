#include "devsurf/terms/PolygonBacktrackTerm.h"

#include <gtest/gtest.h>

#include "support/TermTesting.h"

namespace devsurf::terms {
namespace {

/// A straight reference polygon (0,0,0) (1,0,0) (2,0,0) (3,0,0), its points scattered in x as an S
/// edge's are: 9, 0, 3, 6.
Eigen::VectorXd straightReference() {
  Eigen::VectorXd x(12);
  x << 1, 0, 0, 2, 0, 0, 3, 0, 0, 0, 0, 0;
  return x;
}

TEST(PolygonBacktrackTerm, IsZeroOnAPolygonThatTurnsLessThanARightAngle) {
  PolygonBacktrackTerm term("crease_backtrack", {9, 0, 3, 6}, straightReference());
  Eigen::VectorXd x(12);
  x << 1, 0, 0, 2, 0.5, 0, 3, 1.5, 0, 0, 0, 0;  // (0,0,0) (1,0,0) (2,.5,0) (3,1.5,0)
  EXPECT_EQ(testing::residuals(term, x).norm(), 0.0);
  EXPECT_EQ(term.backtrackMax(x), 0.0);
}

TEST(PolygonBacktrackTerm, ACreaseWhoseFirstPointLiesBehindItsVertexIsPenalized) {
  PolygonBacktrackTerm term("crease_backtrack", {9, 0, 3, 6}, straightReference());
  Eigen::VectorXd x(12);
  x << -0.5, 0, 0, 1, 0, 0, 2, 0, 0, 0, 0, 0;  // (0,0,0) (−.5,0,0) (1,0,0) (2,0,0): back, then forward
  const Eigen::VectorXd r = testing::residuals(term, x);
  EXPECT_DOUBLE_EQ(r[0], hingeResidual(0.75));  // g = −⟨(−.5,0,0), (1.5,0,0)⟩ / (1·1)
  EXPECT_EQ(r[1], 0.0);
  EXPECT_DOUBLE_EQ(term.backtrackMax(x), 1.0);  // a full reversal
}

TEST(PolygonBacktrackTerm, JacobianMatchesFiniteDifferencesActiveAndInactive) {
  for (unsigned seed = 1; seed <= 8; ++seed) {
    Eigen::VectorXd reference = Eigen::VectorXd::Zero(15);
    for (int k = 0; k < 5; ++k) reference[(std::vector<int>{9, 0, 3, 6, 12})[k]] = k * (1.0 + 0.1 * k);
    PolygonBacktrackTerm term("crease_backtrack", {9, 0, 3, 6, 12}, reference);
    EXPECT_EQ(term.numResiduals(), 3);
    testing::expectJacobianMatches(term, testing::randomVector(15, seed));
    testing::expectNoDuplicateEntries(term);
  }
}

TEST(PolygonBacktrackTerm, AWindowOfThreeLegsCatchesTheCuspTwoRightTurnsMake) {
  // (0,0,0) (1,0,0) (1,1,0) (0,1,0): consecutive legs turn by 90° each, the first and the third
  // point opposite ways — a cubic's derivative on that span vanishes. Only the window sees it.
  Eigen::VectorXd x(12);
  x << 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 0;
  PolygonBacktrackTerm consecutive("b", {9, 0, 3, 6}, straightReference(), 2);
  PolygonBacktrackTerm window("b", {9, 0, 3, 6}, straightReference(), 3);
  EXPECT_EQ(consecutive.numResiduals(), 2);
  EXPECT_EQ(window.numResiduals(), 3);
  EXPECT_EQ(testing::residuals(consecutive, x).norm(), 0.0);
  EXPECT_DOUBLE_EQ(testing::residuals(window, x)[1], hingeResidual(1.0));  // legs 0 and 2: −⟨(1,0,0), (−1,0,0)⟩
  for (unsigned seed = 1; seed <= 8; ++seed) {
    testing::expectJacobianMatches(window, testing::randomVector(12, seed));
    testing::expectNoDuplicateEntries(window);
  }
}

TEST(PolygonBacktrackTerm, ATurnTheReferenceMakesByDesignIsNotGuarded) {
  Eigen::VectorXd reference = straightReference();
  reference[3] = 0.5;  // (0,0,0) (1,0,0) (0.5,0,0) (3,0,0): the reference turns back at point 1
  PolygonBacktrackTerm term("crease_backtrack", {9, 0, 3, 6}, reference);
  EXPECT_EQ(term.numResiduals(), 0);
  EXPECT_DOUBLE_EQ(term.backtrackMax(reference), 1.0);  // the metric still reports it
}

TEST(PolygonBacktrackTerm, RejectsAPolygonTooShortOrARepeatedPoint) {
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(9, 0, 8);
  EXPECT_THROW(PolygonBacktrackTerm("b", {0, 3}, x), std::invalid_argument);
  EXPECT_THROW(PolygonBacktrackTerm("b", {0, 3, 0}, x), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
