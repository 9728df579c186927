#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/ExpectError.h"

#include "devsurf/spline/KnotVector.h"

namespace devsurf::spline {
namespace {

/// Expects `call` to throw std::invalid_argument whose message contains `fragment`.
using devsurf::testing::expectThrowMentioning;

TEST(KnotVector, ClampedUniformHasRepeatedEndsAndEqualSpans) {
  const KnotVector kv = KnotVector::clampedUniform(3, 7);
  const std::vector<double> expected = {0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1};
  EXPECT_EQ(kv.knots(), expected);
  EXPECT_EQ(kv.degree(), 3);
  EXPECT_EQ(kv.kind(), KnotKind::Clamped);
  EXPECT_EQ(kv.numControlPoints(), 7);
  EXPECT_EQ(kv.numSlots(), 7);
  EXPECT_EQ(kv.domainBegin(), 0.0);
  EXPECT_EQ(kv.domainEnd(), 1.0);
  EXPECT_EQ(kv.numSpans(), 4);
  EXPECT_EQ(kv.breakpoints(), (std::vector<double>{0, 0.25, 0.5, 0.75, 1}));
}

TEST(KnotVector, ClampedKeepsTheGivenDomainAndMultiplicities) {
  const std::vector<double> knots = {-1, -1, -1, 0.5, 0.5, 2, 3, 3, 3};
  const KnotVector kv = KnotVector::clamped(2, knots, 6);
  EXPECT_EQ(kv.knots(), knots);
  EXPECT_EQ(kv.domainBegin(), -1.0);
  EXPECT_EQ(kv.domainEnd(), 3.0);
  EXPECT_EQ(kv.breakpoints(), (std::vector<double>{-1, 0.5, 2, 3}));
  EXPECT_EQ(kv.numSpans(), 3);
  EXPECT_EQ(kv.multiplicity(-1), 3);
  EXPECT_EQ(kv.multiplicity(0.5), 2);
  EXPECT_EQ(kv.multiplicity(0.5 + 1e-15), 2);
  EXPECT_EQ(kv.multiplicity(2), 1);
  EXPECT_EQ(kv.multiplicity(1), 0);
}

TEST(KnotVector, PeriodicUniformIsUnwrappedWithDomainZeroToOne) {
  const KnotVector kv = KnotVector::periodicUniform(3, 5);
  EXPECT_EQ(kv.kind(), KnotKind::Periodic);
  EXPECT_EQ(kv.numControlPoints(), 5);
  EXPECT_EQ(kv.numSlots(), 8);
  ASSERT_EQ(kv.knots().size(), 12u);
  for (int i = 0; i < 12; ++i) EXPECT_NEAR(kv.knots()[i], (i - 3) / 5.0, 1e-15);
  EXPECT_EQ(kv.domainBegin(), 0.0);
  EXPECT_EQ(kv.domainEnd(), 1.0);
  EXPECT_EQ(kv.numSpans(), 5);
  for (int slot = 0; slot < 8; ++slot) EXPECT_EQ(kv.controlIndex(slot), slot % 5);
}

TEST(KnotVector, SpanIndexFindsTheHalfOpenSpanAndClampsToTheDomain) {
  const KnotVector kv = KnotVector::clamped(2, {0, 0, 0, 1, 1, 2, 3, 3, 3}, 6);
  EXPECT_EQ(kv.spanIndex(0.0), 2);
  EXPECT_EQ(kv.spanIndex(0.5), 2);
  EXPECT_EQ(kv.spanIndex(1.0), 4);  // the double knot: span [1, 2)
  EXPECT_EQ(kv.spanIndex(1.5), 4);
  EXPECT_EQ(kv.spanIndex(2.0), 5);
  EXPECT_EQ(kv.spanIndex(2.999), 5);
  EXPECT_EQ(kv.spanIndex(3.0), 5);  // end → last non-empty span
  EXPECT_EQ(kv.spanIndex(7.0), 5);
  EXPECT_EQ(kv.spanIndex(-4.0), 2);

  const KnotVector periodic = KnotVector::periodicUniform(2, 4);
  EXPECT_EQ(periodic.spanIndex(0.0), 2);
  EXPECT_EQ(periodic.spanIndex(0.3), 3);
  EXPECT_EQ(periodic.spanIndex(1.0), 5);
}

TEST(KnotVector, SpanSamplesAreMidpointsOfEqualSubdivisions) {
  const KnotVector kv = KnotVector::clamped(2, {0, 0, 0, 1, 1, 3, 3, 3}, 5);
  const std::vector<double> s = kv.spanSamples(2);
  ASSERT_EQ(s.size(), 4u);
  EXPECT_DOUBLE_EQ(s[0], 0.25);
  EXPECT_DOUBLE_EQ(s[1], 0.75);
  EXPECT_DOUBLE_EQ(s[2], 1.5);
  EXPECT_DOUBLE_EQ(s[3], 2.5);
}

TEST(KnotVector, UniformSamplesIncludeBothEnds) {
  const KnotVector kv = KnotVector::clamped(1, {2, 2, 4, 4}, 2);
  const std::vector<double> s = kv.uniformSamples(5);
  const std::vector<double> expected = {2, 2.5, 3, 3.5, 4};
  EXPECT_EQ(s, expected);
  expectThrowMentioning([&] { kv.uniformSamples(1); }, "count must be at least 2");
}

TEST(KnotVector, ClampedRejectsTheWrongLength) {
  expectThrowMentioning([] { KnotVector::clamped(3, {0, 0, 0, 0, 0.5, 1, 1, 1, 1}, 7); },
                "knots: expected 11 values (control points + degree + 1), got 9");
}

TEST(KnotVector, ClampedRejectsDecreasingKnots) {
  expectThrowMentioning([] { KnotVector::clamped(3, {0, 0, 0, 0, 0.6, 0.4, 1, 1, 1, 1}, 6); },
                "knots: must be non-decreasing (knots[5] < knots[4])");
}

TEST(KnotVector, ClampedRejectsNonFiniteKnots) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  expectThrowMentioning([&] { KnotVector::clamped(2, {0, 0, 0, nan, 1, 1, 1}, 4); },
                "knots: must be finite");
  expectThrowMentioning([&] { KnotVector::clamped(2, {0, 0, 0, 0.5, inf, inf, inf}, 4); },
                "knots: must be finite");
}

TEST(KnotVector, ClampedRejectsEndsWithoutMultiplicityDegreePlusOne) {
  expectThrowMentioning([] { KnotVector::clamped(3, {0, 0, 0, 0.2, 0.5, 0.8, 1, 1, 1, 1}, 6); },
                "knots: clamped ends need multiplicity degree+1");
  expectThrowMentioning([] { KnotVector::clamped(2, {0, 0, 0, 0, 0.5, 1, 1}, 4); },
                "knots: clamped ends need multiplicity degree+1");
}

TEST(KnotVector, ClampedRejectsInteriorMultiplicityAboveDegree) {
  expectThrowMentioning([] { KnotVector::clamped(2, {0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1}, 6); },
                "interior multiplicity must not exceed degree");
}

TEST(KnotVector, ClampedRejectsAnEmptyDomain) {
  expectThrowMentioning([] { KnotVector::clamped(1, {2, 2, 2, 2}, 2); }, "domain must be non-empty");
}

TEST(KnotVector, FactoriesRejectDegreeZeroAndTooFewControlPoints) {
  expectThrowMentioning([] { KnotVector::clampedUniform(0, 4); }, "degree: must be at least 1");
  expectThrowMentioning([] { KnotVector::periodicUniform(0, 4); }, "degree: must be at least 1");
  expectThrowMentioning([] { KnotVector::clamped(0, {0, 1}, 1); }, "degree: must be at least 1");
  expectThrowMentioning([] { KnotVector::clampedUniform(3, 3); },
                "control points: need at least degree+1 = 4, got 3");
  expectThrowMentioning([] { KnotVector::periodicUniform(3, 2); },
                "control points: need at least degree+1 = 4, got 2");
}

TEST(KnotVector, DefaultConstructedVectorIsRejectedByQueries) {
  const KnotVector kv;
  expectThrowMentioning([&] { kv.spanIndex(0.5); }, "empty");
  expectThrowMentioning([&] { kv.breakpoints(); }, "empty");
  EXPECT_EQ(kv.multiplicity(0.0), 0);
}

}  // namespace
}  // namespace devsurf::spline
