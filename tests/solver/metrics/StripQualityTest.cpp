#include "devsurf/metrics/StripQuality.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace devsurf::metrics {
namespace {

TEST(WarpAngle, OfAHelicoidRulingMatchesTheClosedForm) {
  // a(u) = (u, 0, 0), b(u) = (u, cos θ(u), sin θ(u)) with θ′ = ω: the normal at a is
  // a′×(b−a) = (0, −sin θ, cos θ); at b it is b′×(b−a) with b′ = (1, −ω sin θ, ω cos θ):
  // the angle between them is atan(ω).
  const double omega = 0.7, theta = 0.4;
  const Eigen::Vector3d a(0.3, 0, 0), da(1, 0, 0);
  const Eigen::Vector3d b(0.3, std::cos(theta), std::sin(theta));
  const Eigen::Vector3d db(1, -omega * std::sin(theta), omega * std::cos(theta));
  EXPECT_NEAR(warpAngleDeg(a, da, b, db), std::atan(omega) * 180 / M_PI, 1e-12);
  // |det(b−a, a′, b′)| / (|b−a||a′||b′|) = ω / sqrt(1 + ω²)
  EXPECT_NEAR(developabilityResidual(a, da, b, db), omega / std::sqrt(1 + omega * omega), 1e-14);
}

TEST(WarpAngle, IsZeroOnPlanarAndConicalRulingsAndIgnoresOrientation) {
  const Eigen::Vector3d a(0, 0, 0), b(0, 1, 0);
  EXPECT_EQ(warpAngleDeg(a, {1, 0, 0}, b, {2, 0.5, 0}), 0.0);
  EXPECT_NEAR(warpAngleDeg(a, {1, 0, 0}, b, {-1, 0, 0}), 0.0, 1e-12);
  EXPECT_EQ(warpAngleDeg(a, {1, 0, 0}, b, {0, 0, 0}), 0.0);  // apex
  EXPECT_EQ(developabilityResidual(a, {1, 0, 0}, b, {0, 0, 0}), 0.0);
}

TEST(StripQuality, AveragesTheWarpOverEquallySpacedRulings) {
  // Linear a and b on [0,1] with b turning by a small angle: nearly constant warp angle.
  spline::BSplineCurve a, b;
  a.knots = b.knots = spline::KnotVector::clampedUniform(1, 2);
  a.points.resize(2, 3);
  b.points.resize(2, 3);
  a.points << 0, 0, 0, 1, 0, 0;
  b.points << 0, 1, 0, 1, 0, 1;  // b turns 90° about the x axis (as a chord)
  const StripQuality q = stripQuality(a, b, 1001);
  EXPECT_EQ(q.rulings, 1001);
  // b − a = (0, 1−u, u), a′ = (1,0,0), b′ = (1,−1,1): the normals are (0, −u, 1−u) and
  // (−1, −u, 1−u), so the warp angle is atan(1 / sqrt(u² + (1−u)²)): 45° at the ends and
  // atan(√2) = 54.7356° at u = ½ (a ruling of the sample set).
  EXPECT_NEAR(q.warpAngleMaxDeg, std::atan(std::sqrt(2.0)) * 180 / M_PI, 1e-9);
  double mean = 0.0;
  for (int i = 0; i <= 1000; ++i) {
    const double u = i / 1000.0;
    mean += std::atan(1.0 / std::hypot(u, 1.0 - u)) * 180 / M_PI;
  }
  EXPECT_NEAR(q.warpAngleMeanDeg, mean / 1001, 1e-9);
  EXPECT_THROW(stripQuality(a, b, 1), std::invalid_argument);
}

TEST(StripQuality, OnATabledBasisIsTheSameAsOnTheCurves) {
  // A twisted cubic strip (warp well above zero), measured by the plain function and on a
  // BasisTable at the same 1 000 parameters: the same numbers; curves on another knot vector are
  // refused.
  spline::BSplineCurve a, b;
  a.knots = b.knots = spline::KnotVector::clamped(3, {0, 0, 0, 0, 0.3, 0.5, 1, 1, 1, 1}, 6);
  a.points.resize(6, 3);
  b.points.resize(6, 3);
  for (int i = 0; i < 6; ++i) {
    a.points.row(i) << i, 0.2 * std::sin(i), 0.0;
    b.points.row(i) << i, 1.0, 0.3 * i * std::cos(0.7 * i);
  }
  std::vector<double> params(1000);
  for (int i = 0; i < 1000; ++i) params[static_cast<std::size_t>(i)] = static_cast<double>(i) / 999;
  const spline::BasisTable table(a.knots, params, 1);
  const StripQuality plain = stripQuality(a, b, 1000), tabled = stripQuality(table, a, b);
  EXPECT_GT(plain.warpAngleMaxDeg, 1.0);
  EXPECT_NEAR(tabled.warpAngleMaxDeg, plain.warpAngleMaxDeg, 1e-12);
  EXPECT_NEAR(tabled.warpAngleMeanDeg, plain.warpAngleMeanDeg, 1e-12);
  EXPECT_NEAR(tabled.developabilityResidualMax, plain.developabilityResidualMax, 1e-12);
  EXPECT_EQ(tabled.rulings, 1000);
  spline::BSplineCurve other = b;
  other.knots = spline::KnotVector::clampedUniform(3, 6);
  EXPECT_FALSE(table.fits(other));
  EXPECT_THROW(stripQuality(table, a, other), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::metrics
