#include "devsurf/engine/JacobianCheck.h"

#include <gtest/gtest.h>

#include "solver/engine/TestTerms.h"

namespace devsurf::engine {
namespace {

TEST(JacobianCheck, AcceptsACorrectJacobian) {
  testing::ProductTerm term("p", 0, 1, 2.0);
  const JacobianCheckResult r = checkJacobian(term, Eigen::Vector2d(0.3, -1.7));
  EXPECT_LT(r.maxRelativeError, 1e-8);
  EXPECT_TRUE(r.structureComplete);
}

TEST(JacobianCheck, CatchesAWrongValueAndAMissingStructuralEntry) {
  testing::WrongProductTerm term("wrong");
  const JacobianCheckResult r = checkJacobian(term, Eigen::Vector2d(0.3, -1.7));
  EXPECT_GT(r.maxRelativeError, 0.5);
  EXPECT_FALSE(r.structureComplete);
  EXPECT_NEAR(r.maxOutsideStructure, 0.3, 1e-8);
}

}  // namespace
}  // namespace devsurf::engine
