// The strip's overhang beyond its reference points (not in 000_…: its eq. 9–11 measure from the
// points to the strip only): rows, values and Jacobian.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "devsurf/spline/KnotVector.h"
#include "devsurf/terms/StripOverhangTerm.h"
#include "support/TermTesting.h"

namespace devsurf::terms {
namespace {

constexpr int kOverhangPoints = 5;  // per curve; a at x[0..14], b at x[15..29]

/// The flat strip over [0, 2] × [0, 1] at z = 0: a along y = 0, b along y = 1.
Eigen::VectorXd stripOverTwoUnits() {
  Eigen::VectorXd x(30);
  for (int i = 0; i < kOverhangPoints; ++i) {
    x.segment<3>(3 * i) << 2.0 * i / (kOverhangPoints - 1), 0.0, 0.0;
    x.segment<3>(15 + 3 * i) << 2.0 * i / (kOverhangPoints - 1), 1.0, 0.0;
  }
  return x;
}

/// Points every 0.05 over [0, 1] × [0, 1] at z = 0: the left half of the flat strip.
Eigen::MatrixX3d leftHalf() {
  Eigen::MatrixX3d q(21 * 21, 3);
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) q.row(21 * i + j) << 0.05 * i, 0.05 * j, 0.0;
  return q;
}

StripOverhangTerm overhangTerm(Eigen::MatrixX3d q, double reach, int samplesU = 9, int samplesV = 5) {
  return StripOverhangTerm("approximation_overhang", spline::KnotVector::clampedUniform(1, kOverhangPoints), {}, 0, 15,
                           std::move(q), reach, samplesU, samplesV);
}

TEST(StripOverhangTerm, RestsOverItsPointsAndPullsTheRestBackByItsDistanceBeyondTheReach) {
  // Samples at u = 0, 0.25, … 2 along, v = 0 … 1 across; points on the left half. A sample at
  // x > 1 lies x − 1 from the nearest point (1, v, 0); its rows have length x − 1 − ρ, pointing +x.
  const double reach = 0.1;
  StripOverhangTerm term = overhangTerm(leftHalf(), reach);
  const Eigen::VectorXd x = stripOverTwoUnits();
  const Eigen::VectorXd r = testing::residuals(term, x);
  ASSERT_EQ(r.size(), 3 * 9 * 5);
  for (int k = 0; k < term.samples(); ++k) {
    const Eigen::Vector3d s = term.samplePoint(x, k);
    const Eigen::Vector3d rows = r.segment<3>(3 * k);
    const double beyond = std::max(0.0, s.x() - 1.0 - reach);
    EXPECT_NEAR(rows.norm(), beyond, 1e-12) << "sample at " << s.transpose();
    if (beyond > 0.0) EXPECT_GT(rows.normalized().x(), 1.0 - 1e-12);
    EXPECT_NEAR(term.nearest(k).x(), std::min(s.x(), 1.0), 1e-12);
  }
}

TEST(StripOverhangTerm, JacobianMatchesFiniteDifferencesWithTheNearestPointsHeldFixed) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (unsigned seed = 1; seed <= 20; ++seed) {
    // A wavy strip over scattered points, a small reach: most samples overhang, a few rest.
    Eigen::VectorXd x = 0.1 * testing::randomVector(30, seed);
    for (int i = 0; i < kOverhangPoints; ++i) {
      x.segment<3>(3 * i) += Eigen::Vector3d(i * 0.5 - 1.0, 0.0, 0.3 * std::sin(i));
      x.segment<3>(15 + 3 * i) += Eigen::Vector3d(i * 0.5 - 1.0, 1.0, 0.3 * std::sin(i));
    }
    Eigen::MatrixX3d q(40, 3);
    for (Eigen::Index j = 0; j < q.rows(); ++j) q.row(j) << uniform(rng), 0.5 + uniform(rng), 0.3 * uniform(rng);
    StripOverhangTerm term = overhangTerm(q, 0.05, 8, 4);
    testing::expectNoDuplicateEntries(term);
    testing::expectJacobianMatches(term, x);
  }
}

TEST(StripOverhangTerm, RefusesNoPointsNoReachAndTooFewSamples) {
  EXPECT_THROW(overhangTerm(Eigen::MatrixX3d(0, 3), 0.1), std::invalid_argument);
  EXPECT_THROW(overhangTerm(leftHalf(), 0.0), std::invalid_argument);
  EXPECT_THROW(overhangTerm(leftHalf(), std::nan("")), std::invalid_argument);
  EXPECT_THROW(overhangTerm(leftHalf(), 0.1, 1, 5), std::invalid_argument);
  Eigen::MatrixX3d bad = leftHalf();
  bad(3, 1) = std::nan("");
  EXPECT_THROW(overhangTerm(bad, 0.1), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
