// MappingEndPointTerm (001_… §5.4, end-point fixing).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <memory>

#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/KnotVector.h"
#include "devsurf/terms/ExtendedCurve.h"
#include "devsurf/terms/MappingEndPointTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

std::shared_ptr<const ExtendedCurve> endPointArc() {
  spline::BSplineCurve c;
  c.knots = spline::KnotVector::clampedUniform(2, 4);
  c.points.resize(4, 3);
  c.points << 0, 0, 0, 1, 1, 0, 2, 1, 0.5, 3, 0, 1;
  return std::make_shared<const ExtendedCurve>(c);
}

TEST(MappingEndPointTerm, JacobianMatchesFiniteDifferences) {
  MappingEndPointTerm term("end point", 1, {{0, 1.0}, {1, 1.0}, {2, 1.0}, {3, 1.0}}, endPointArc(),
                           Eigen::Vector3d(3, 0, 1));
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(5, 3));
}

TEST(MappingEndPointTerm, MeasuresTheDistanceOfTheMappedEndFromItsTarget) {
  // σ(1) = Σ ε² = 1 puts the end on C2(1) = (3, 0, 1).
  MappingEndPointTerm term("end point", 0, {{0, 1.0}, {1, 1.0}}, endPointArc(), Eigen::Vector3d(3, 0, 1));
  Eigen::VectorXd x(2);
  x << std::sqrt(0.5), std::sqrt(0.5);
  EXPECT_LT(residuals(term, x).norm(), 1e-14);
  x << 0.0, 0.0;  // σ = 0: C2(0) = origin
  EXPECT_NEAR(residuals(term, x).norm(), std::sqrt(10.0), 1e-15);
}

}  // namespace
}  // namespace devsurf::terms
