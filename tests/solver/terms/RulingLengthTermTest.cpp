#include "devsurf/terms/RulingLengthTerm.h"

#include <gtest/gtest.h>

#include "support/TermTesting.h"

namespace devsurf::terms {
namespace {

/// Two rulings between points a_k (x[0..5]) and b_k (x[6..11]) as rows of identity maps.
RulingLengthTerm twoRulings(double m0, double m1) {
  return RulingLengthTerm("ruling_length", LinearPoints::identity(2, 0), LinearPoints::identity(2, 6), {m0, m1});
}

TEST(RulingLengthTerm, IsZeroWhileEveryRulingIsLongEnough) {
  RulingLengthTerm term = twoRulings(0.5, 0.5);
  Eigen::VectorXd x(12);
  x << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0;  // both rulings have length 1
  EXPECT_EQ(testing::residuals(term, x).norm(), 0.0);
}

TEST(RulingLengthTerm, GrowsAsARulingShrinksBelowItsMinimum) {
  RulingLengthTerm term = twoRulings(0.5, 0.5);
  Eigen::VectorXd x(12);
  x << 0, 0, 0, 1, 0, 0, 0, 0.25, 0, 1, 1, 0;  // the first ruling has length 0.25 = half its minimum
  const Eigen::VectorXd r = testing::residuals(term, x);
  EXPECT_DOUBLE_EQ(r[0], hingeResidual(0.75));  // g = 1 − 0.25²/0.5²
  EXPECT_EQ(r[1], 0.0);
}

TEST(RulingLengthTerm, JacobianMatchesFiniteDifferencesActiveAndInactive) {
  for (unsigned seed = 1; seed <= 8; ++seed) {
    // Minimum lengths 0.2 (mostly inactive at random points) and 3 (always active).
    RulingLengthTerm term = twoRulings(0.2, 3.0);
    testing::expectJacobianMatches(term, testing::randomVector(12, seed));
    testing::expectNoDuplicateEntries(term);
  }
}

TEST(RulingLengthTerm, DegenerateRulingsByDesignHaveNoRow) {
  RulingLengthTerm term = twoRulings(0.0, 0.5);
  EXPECT_EQ(term.numResiduals(), 1);
  Eigen::VectorXd x(12);
  x << 0, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0.2, 0;
  EXPECT_NEAR(term.lengthRatioMin(x, 0.5), 0.2 / 1.0, 1e-15);  // 0.2 against its reference 1 (= 0.5 / 0.5)
}

}  // namespace
}  // namespace devsurf::terms

namespace devsurf::terms {
namespace {

TEST(Hinge, IsZeroBelowTheBoundThenRampsSmoothlyIntoAStraightLine) {
  EXPECT_EQ(hingeResidual(-1.0), 0.0);
  EXPECT_EQ(hingeResidual(0.0), 0.0);
  EXPECT_EQ(hingeSlope(0.0), 0.0);
  EXPECT_NEAR(hingeResidual(kHingeRamp), 0.5 * kHingeRamp, 1e-15);  // the two pieces meet …
  EXPECT_NEAR(hingeSlope(kHingeRamp), 1.0, 1e-15);                  // … with one slope
  for (double g : {0.01, 0.03, 0.2, 2.0})
    EXPECT_NEAR(hingeSlope(g), (hingeResidual(g + 1e-7) - hingeResidual(g - 1e-7)) / 2e-7, 1e-6) << g;
}

}  // namespace
}  // namespace devsurf::terms
