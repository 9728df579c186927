#include "devsurf/terms/StripWidthTerm.h"

#include <gtest/gtest.h>

#include "support/TermTesting.h"

namespace devsurf::terms {
namespace {

/// A strip sampled at two parameters: a_k at x[0..5], b_k at x[6..11], a′_k at x[12..17], b′_k at
/// x[18..23] (free vectors, as identity point sets).
StripWidthTerm fourSets(std::vector<double> minWidth) {
  return StripWidthTerm("strip_width", {{LinearPoints::identity(2, 0), -1.0}, {LinearPoints::identity(2, 6), 1.0}},
                        {{LinearPoints::identity(2, 12), 1.0}, {LinearPoints::identity(2, 18), 1.0}}, std::move(minWidth));
}

Eigen::VectorXd flatStrip() {
  Eigen::VectorXd x(24);
  // a = (0,0,0), (1,0,0); b = (0,1,0), (1,1,0); a′ = b′ = (1,0,0): N = (0,1,0) × (2,0,0), |N| = 2.
  x << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0;
  return x;
}

TEST(StripWidthTerm, IsZeroWhileTheStripKeepsItsWidth) {
  StripWidthTerm term = fourSets({1.0, 1.0});
  EXPECT_EQ(testing::residuals(term, flatStrip()).norm(), 0.0);
  EXPECT_DOUBLE_EQ(term.widthRatioMin(flatStrip(), 0.5), 1.0);  // |N| = 2 = its reference (1 / 0.5)
}

TEST(StripWidthTerm, ARulingTurnedIntoTheCurvesDirectionIsPenalizedThoughItKeepsItsLength) {
  StripWidthTerm term = fourSets({1.0, 1.0});
  Eigen::VectorXd x = flatStrip();
  x.segment<3>(6) << 1, 0, 0;  // b_0 = (1,0,0): the ruling a_0 b_0 has length 1 but lies along a′
  const Eigen::VectorXd r = testing::residuals(term, x);
  EXPECT_DOUBLE_EQ(r[0], hingeResidual(1.0));  // |N| = 0
  EXPECT_EQ(r[1], 0.0);
}

TEST(StripWidthTerm, JacobianMatchesFiniteDifferencesWithSharedControlPoints) {
  for (unsigned seed = 1; seed <= 8; ++seed) {
    StripWidthTerm separate = fourSets({0.3, 5.0});  // mostly inactive / always active
    testing::expectJacobianMatches(separate, testing::randomVector(24, seed));
    testing::expectNoDuplicateEntries(separate);
    // r and t from the same 4 control points (a curve and its derivative share variables).
    spline::EvaluationMatrix R(2, 4), T(2, 4);
    R.insert(0, 0) = -1; R.insert(0, 2) = 1; R.insert(1, 1) = -1; R.insert(1, 3) = 1;
    T.insert(0, 0) = -3; T.insert(0, 1) = 3; T.insert(1, 2) = -3; T.insert(1, 3) = 3;
    R.makeCompressed();
    T.makeCompressed();
    StripWidthTerm shared("strip_width", {{LinearPoints{R, 0}, 1.0}}, {{LinearPoints{T, 0}, 1.0}}, {0.3, 5.0});
    testing::expectJacobianMatches(shared, testing::randomVector(12, seed));
    testing::expectNoDuplicateEntries(shared);
  }
}

}  // namespace
}  // namespace devsurf::terms
