// DevelopmentPeriodTerm (000_… §6 Fig. 14: developments periodic across a seam).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <cmath>
#include <stdexcept>

#include "devsurf/terms/DevelopmentPeriodTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

TEST(DevelopmentPeriodTerm, JacobianMatchesFiniteDifferences) {
  DevelopmentPeriodTerm term("period", {{0, 4}, {2, 6}}, 8);
  EXPECT_EQ(term.numResiduals(), 4);
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(10, 5));
}

TEST(DevelopmentPeriodTerm, VanishesExactlyForTranslatedCopies) {
  // Two seam vertices and their copies shifted by T = (2π, 0): a cylinder of radius 1 unrolled.
  Eigen::VectorXd x(10);
  x << 0.0, 0.0, 0.0, 1.0, 2 * M_PI, 0.0, 2 * M_PI, 1.0, 2 * M_PI, 0.0;
  DevelopmentPeriodTerm term("period", {{0, 4}, {2, 6}}, 8);
  EXPECT_EQ(residuals(term, x).cwiseAbs().maxCoeff(), 0.0);
  x[7] += 0.25;  // the second copy drifts in y
  const Eigen::VectorXd r = residuals(term, x);
  EXPECT_DOUBLE_EQ(r[3], 0.25);
  EXPECT_EQ(r.head<3>().cwiseAbs().maxCoeff(), 0.0);
}

TEST(DevelopmentPeriodTerm, RejectsOverlappingVariables) {
  EXPECT_THROW(DevelopmentPeriodTerm("period", {{0, 1}}, 4), std::invalid_argument);
  EXPECT_THROW(DevelopmentPeriodTerm("period", {{0, 2}}, 3), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
