// Property test of the quasi-developable strip (issue 11, item 5): over random but plausible
// curve pairs the solved strip is never worse than the identity mapping σ(t) = t, stays near the
// input curves and extends them a bounded number of times by a bounded amount.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "devsurf/models/quasi_strip/QuasiStripModel.h"
#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/KnotVector.h"

namespace devsurf::models::quasi_strip {
namespace {

constexpr int kCases = 240;
constexpr int kDenseRulings = 1000;

struct RandomPair {
  QuasiStripDesign design;
  std::string label;  ///< how the pair was made, for failure messages
};

spline::BSplineCurve clampedCurve(int degree, const Eigen::MatrixXd& points) {
  spline::BSplineCurve c;
  c.knots = spline::KnotVector::clampedUniform(degree, static_cast<int>(points.rows()));
  c.points = points;
  return c;
}

/// C1: a gently bent cubic or quintic (5–9 control points, length ~1); C2: C1's control points
/// offset by 0.15–0.8 across C1's chord direction, twisted about that direction by 0–90° along
/// the curve, scaled 0.5–1.5 along it, with 1% noise. Every third pair then has one control point
/// moved by 10–40% of the bounding-box diagonal (an editing session's drag). A random rigid
/// motion and scale put the pair somewhere in space.
RandomPair randomPair(std::mt19937_64& rng, int index) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  auto uniform = [&](double a, double b) { return a + (b - a) * unit(rng); };
  const int degree = index % 2 == 0 ? 3 : 5;
  const int n = std::uniform_int_distribution<int>(degree == 3 ? 5 : 6, 9)(rng);
  const double bendY = uniform(-0.3, 0.3), bendZ = uniform(-0.3, 0.3);
  const double waveY = uniform(0.5, 1.5), waveZ = uniform(0.5, 1.5), phaseY = uniform(0, M_PI),
               phaseZ = uniform(0, M_PI);
  Eigen::MatrixXd p1(n, 3);
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1);
    p1.row(i) << s + 0.02 * gauss(rng), bendY * std::sin(M_PI * waveY * s + phaseY),
        bendZ * std::sin(M_PI * waveZ * s + phaseZ);
  }
  const Eigen::Vector3d origin = p1.row(0).transpose();
  const Eigen::Vector3d dir = (p1.row(n - 1) - p1.row(0)).transpose().normalized();
  const Eigen::Vector3d across = dir.unitOrthogonal();
  const double offsetAngle = uniform(0, 2 * M_PI), distance = uniform(0.15, 0.8);
  const Eigen::Vector3d offset =
      distance * Eigen::AngleAxisd(offsetAngle, dir).toRotationMatrix() * across;
  const double twist = uniform(0.0, M_PI / 2) * (unit(rng) < 0.5 ? -1.0 : 1.0);
  const double stretch = uniform(0.5, 1.5);
  Eigen::MatrixXd p2(n, 3);
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1);
    const Eigen::Vector3d q = p1.row(i).transpose() - origin;
    const double along = q.dot(dir);
    const Eigen::Vector3d radial = q - along * dir + offset;
    const Eigen::Vector3d moved = origin + (0.5 + stretch * (along - 0.5)) * dir +
                                  Eigen::AngleAxisd(twist * s, dir).toRotationMatrix() * radial;
    p2.row(i) = (moved + 0.01 * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng))).transpose();
  }
  std::ostringstream label;
  label << "case " << index << ": degree " << degree << ", " << n << " control points, offset "
        << distance << ", twist " << twist * 180 / M_PI << "°, stretch " << stretch;
  if (index % 3 == 2) {
    Eigen::MatrixXd all(2 * n, 3);
    all << p1, p2;
    const double diagonal = (all.colwise().maxCoeff() - all.colwise().minCoeff()).norm();
    Eigen::Vector3d step(gauss(rng), gauss(rng), gauss(rng));
    step *= uniform(0.1, 0.4) * diagonal / step.norm();
    const int curve = std::uniform_int_distribution<int>(0, 1)(rng);
    const int point = std::uniform_int_distribution<int>(0, n - 1)(rng);
    (curve == 0 ? p1 : p2).row(point) += step.transpose();
    label << ", c" << curve + 1 << " point " << point << " dragged by " << step.norm() / diagonal
          << " of the diagonal";
  }
  const Eigen::Matrix3d rotation =
      Eigen::Quaterniond(gauss(rng), gauss(rng), gauss(rng), gauss(rng)).normalized().toRotationMatrix();
  const double scale = std::exp(uniform(std::log(0.1), std::log(100.0)));
  const Eigen::RowVector3d shift(uniform(-10, 10), uniform(-10, 10), uniform(-10, 10));
  RandomPair pair;
  pair.design.c1 = clampedCurve(degree, ((p1 * rotation.transpose()) * scale).rowwise() + shift * scale);
  pair.design.c2 = clampedCurve(degree, ((p2 * rotation.transpose()) * scale).rowwise() + shift * scale);
  pair.label = label.str();
  return pair;
}

/// Warp angle between the planes through the ruling b − a spanned with a′ and with b′, as lines
/// (0°…90°); 0 where either plane is undefined. Written out here so that the test does not rely
/// on the model's metric.
double rulingWarpDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& da, const Eigen::Vector3d& b,
                     const Eigen::Vector3d& db) {
  const Eigen::Vector3d ruling = b - a;
  const Eigen::Vector3d na = da.cross(ruling), nb = db.cross(ruling);
  if (na.norm() <= 1e-13 * ruling.norm() * da.norm() || nb.norm() <= 1e-13 * ruling.norm() * db.norm()) return 0.0;
  const double cosine = std::min(1.0, std::abs(na.normalized().dot(nb.normalized())));
  const double sine = na.normalized().cross(nb.normalized()).norm();
  return std::atan2(sine, cosine) * 180.0 / M_PI;
}

/// Largest warp of the rulings c1(t)–c2(t), t at `rulings` equally spaced parameters of the
/// (common) domain: the identity mapping σ(t) = t.
double identityWarpMaxDeg(const spline::BSplineCurve& c1, const spline::BSplineCurve& c2, int rulings) {
  const double t0 = c1.knots.domainBegin(), t1 = c1.knots.domainEnd();
  double worst = 0.0;
  for (int i = 0; i < rulings; ++i) {
    const double t = t0 + (t1 - t0) * i / (rulings - 1);
    worst = std::max(worst, rulingWarpDeg(c1.evaluate(t, 0), c1.evaluate(t, 1), c2.evaluate(t, 0), c2.evaluate(t, 1)));
  }
  return worst;
}

/// Largest warp of the result's rulings C1(t)–C2(σ(t)) at the model's dense parameters (equally
/// spaced over σ's domain) that lie on both input curves, from the input curves and σ alone.
double resultWarpOnCurvesDeg(const QuasiStripDesign& d, const Mapping& sigma, int rulings, int& counted) {
  const double t0 = sigma.domainBegin(), t1 = sigma.domainEnd();
  double worst = 0.0;
  counted = 0;
  for (int i = 0; i < rulings; ++i) {
    const double t = t0 + (t1 - t0) * i / (rulings - 1);
    const double T = sigma.evaluate(t);
    if (t < d.c1.knots.domainBegin() || t > d.c1.knots.domainEnd() || T < d.c2.knots.domainBegin() ||
        T > d.c2.knots.domainEnd())
      continue;
    ++counted;
    worst = std::max(worst, rulingWarpDeg(d.c1.evaluate(t, 0), d.c1.evaluate(t, 1), d.c2.evaluate(T, 0), d.c2.evaluate(T, 1)));
  }
  return worst;
}

double polylineLength(const Eigen::MatrixXd& points) {
  double length = 0.0;
  for (Eigen::Index i = 0; i + 1 < points.rows(); ++i) length += (points.row(i + 1) - points.row(i)).norm();
  return length;
}

/// Distance from x to the polyline through `points` (rows).
double distanceToPolyline(const Eigen::MatrixXd& points, const Eigen::Vector3d& x) {
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i + 1 < points.rows(); ++i) {
    const Eigen::Vector3d a = points.row(i).transpose(), b = points.row(i + 1).transpose();
    const Eigen::Vector3d ab = b - a;
    const double u = ab.squaredNorm() > 0 ? std::clamp((x - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
    best = std::min(best, (a + u * ab - x).norm());
  }
  return best;
}

Eigen::MatrixXd polyline(const spline::BSplineCurve& c, int samples) {
  std::vector<double> params;
  for (int i = 0; i < samples; ++i)
    params.push_back(c.knots.domainBegin() + (c.knots.domainEnd() - c.knots.domainBegin()) * i / (samples - 1));
  return c.evaluate(params, 0);
}

/// Largest distance of the surface's boundaries (201 points each) from the input curves.
double boundaryDeviation(const RuledBSplineSurface& surface, const QuasiStripDesign& d) {
  const Eigen::MatrixXd lines[2] = {polyline(d.c1, 4000), polyline(d.c2, 4000)};
  const double t0 = surface.knots.front(), t1 = surface.knots.back();
  double worst = 0.0;
  for (int side = 0; side < 2; ++side)
    for (int k = 0; k <= 200; ++k)
      worst = std::max(worst, distanceToPolyline(lines[side], surface.evaluate(side, t0 + (t1 - t0) * k / 200.0)));
  return worst;
}

double boundingBoxDiagonal(const QuasiStripDesign& d) {
  Eigen::MatrixXd all(d.c1.points.rows() + d.c2.points.rows(), 3);
  all << d.c1.points, d.c2.points;
  return (all.colwise().maxCoeff() - all.colwise().minCoeff()).norm();
}

bool allFinite(const QuasiStripResults& r) {
  return std::isfinite(r.warpAngleMaxDeg) && std::isfinite(r.warpAngleMaxDegDense) && std::isfinite(r.objective) &&
         r.mapping.coefficients.allFinite() && r.surface.side0.allFinite() && r.surface.side1.allFinite() &&
         std::isfinite(r.trimBegin) && std::isfinite(r.trimEnd);
}

TEST(QuasiStripProperty, RandomCurvePairsAreNeverWorseThanTheIdentityAndStayNearTheCurves) {
  std::mt19937_64 rng(20240611);
  double worstRatio = 0.0, worstExcess = 0.0, worstDeviation = 0.0, worstDeviationOfLength = 0.0,
         worstCrossCheck = 0.0, widestDomain = 0.0;
  int maxRounds = 0, fallbacks = 0, converged = 0, improved = 0, earlier = 0;
  for (int index = 0; index < kCases; ++index) {
    const RandomPair pair = randomPair(rng, index);
    SCOPED_TRACE(pair.label);
    const QuasiStripDesign& d = pair.design;
    const double identity = identityWarpMaxDeg(d.c1, d.c2, kDenseRulings);
    QuasiStripModel model(d);
    const QuasiStripSummary summary = model.solve();
    const QuasiStripResults& r = model.results();
    ASSERT_TRUE(allFinite(r));
    const double maxLength = d.extension.maxLength;
    // Never worse than σ(t) = t (round-off of the two computations allowed).
    EXPECT_LE(r.warpAngleMaxDegDense, identity * (1.0 + 1e-9) + 1e-9) << summary.selection;
    // The model's metric agrees with the warp computed here from the curves and σ.
    int counted = 0;
    const double crossCheck = resultWarpOnCurvesDeg(d, r.mapping, kDenseRulings, counted);
    EXPECT_LE(crossCheck, r.warpAngleMaxDegDense + 1e-6);
    // Near the curves: extension (of C1, or σ past C2's end) by at most maxLength of the arc length.
    const double diagonal = boundingBoxDiagonal(d);
    const double longer = std::max(polylineLength(polyline(d.c1, 4000)), polylineLength(polyline(d.c2, 4000)));
    const double deviation = boundaryDeviation(r.surface, d);
    EXPECT_LE(deviation, maxLength * longer * 1.001);
    const bool extended = r.extension.c1Begin > 0 || r.extension.c1End > 0;
    const bool overrun = r.mapping.coefficients.maxCoeff() > d.c2.knots.domainEnd();
    if (!extended && !overrun) {
      EXPECT_LE(deviation, 1e-5 * diagonal);  // 0 up to the polylines' chords
    }
    // Bounded extension: rounds, and σ's domain within maxLength of C1's domain at either end.
    EXPECT_LE(summary.rounds, d.extension.maxRounds + 2);  // + the retry with end points fixed
    EXPECT_GE(r.mapping.domainBegin(), d.c1.knots.domainBegin() - maxLength - 1e-12);
    EXPECT_LE(r.mapping.domainEnd(), d.c1.knots.domainEnd() + maxLength + 1e-12);
    EXPECT_LE(r.mapping.coefficients.maxCoeff(), d.c2.knots.domainEnd() + maxLength + 1e-12);
    // Honest reporting: the fallback says so and is not "converged".
    if (summary.selectedRound == 0) {
      EXPECT_EQ(summary.termination, kIdentityFallback);
      EXPECT_FALSE(summary.converged);
      EXPECT_NEAR(r.warpAngleMaxDegDense, identity, 1e-9 * (1 + identity));
    } else {
      EXPECT_NE(summary.termination, kIdentityFallback);
    }
    worstRatio = std::max(worstRatio, r.warpAngleMaxDegDense / std::max(identity, 1e-12));
    worstExcess = std::max(worstExcess, r.warpAngleMaxDegDense - identity);
    worstCrossCheck = std::max(worstCrossCheck, crossCheck - r.warpAngleMaxDegDense);
    worstDeviation = std::max(worstDeviation, deviation / diagonal);
    worstDeviationOfLength = std::max(worstDeviationOfLength, deviation / longer);
    widestDomain = std::max(widestDomain, r.mapping.domainEnd() - r.mapping.domainBegin());
    maxRounds = std::max(maxRounds, summary.rounds);
    fallbacks += summary.selectedRound == 0;
    earlier += summary.selectedRound != 0 && summary.selection != "last round";
    improved += r.warpAngleMaxDegDense < 0.5 * identity;
    converged += summary.converged;
    if (std::getenv("QUASI_PROPERTY_VERBOSE"))
      std::cout << index << ": identity " << identity << "° → " << r.warpAngleMaxDegDense << "°, deviation "
                << deviation / diagonal << " of the diagonal, " << summary.rounds << " rounds, "
                << summary.termination << " (" << summary.selection << ") | " << pair.label << "\n";
  }
  std::cout << kCases << " pairs: worst max-warp ratio to the identity " << worstRatio << " (excess " << worstExcess
            << "°), model metric vs. this test's warp " << worstCrossCheck << "°, worst deviation "
            << worstDeviation << " of the diagonal (" << worstDeviationOfLength << " of the longer curve), σ's domain "
            << widestDomain << " wide at most, max rounds " << maxRounds << "; " << improved
            << " at least halved the identity's max warp, " << fallbacks << " identity fallbacks, " << earlier
            << " returned an earlier state, " << converged << " converged\n";
}

}  // namespace
}  // namespace devsurf::models::quasi_strip
