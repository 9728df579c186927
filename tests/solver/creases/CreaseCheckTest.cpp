#include "devsurf/creases/CreaseCheck.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "devsurf/creases/PlanarFold.h"

namespace devsurf::creases {
namespace {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;

PlanarFold circleFold(int n) {
  PlanarCurve g;
  g.u0 = 0.0;
  g.u1 = 2.0;
  g.evaluate = [](double u, int d) -> Vec2 {
    if (d == 0) return {std::cos(u), std::sin(u)};
    if (d == 1) return {-std::sin(u), std::cos(u)};
    return {-std::cos(u), -std::sin(u)};
  };
  return planarFoldByReflection(g, Vec3(0.2, 0.1, 1.0), 0.5, n);
}

// The same fold over the inscribed polygon: exactly isometric meshes (no derivative data).
PlanarFold circlePolygonFold(int n) {
  Eigen::MatrixX2d polygon(n, 2);
  for (int i = 0; i < n; ++i) polygon.row(i) << std::cos(2.0 * i / (n - 1)), std::sin(2.0 * i / (n - 1));
  return planarFoldByReflection(polygon, Vec3(0.2, 0.1, 1.0), 0.5);
}

TEST(QuadWarp, OfATwistedSquareIsTheDihedralAngleOfItsTriangles) {
  // Unit square with one corner lifted by z: splitting along p0p2 gives the normals (0, −z, 1)
  // and (−z, 0, 1), at the angle acos(1/(1+z²)); the other split gives less.
  const double z = 0.1;
  const double w = quadWarpDeg({0, 0, 0}, {1, 0, 0}, {1, 1, z}, {0, 1, 0});
  EXPECT_NEAR(w, std::acos(1 / (1 + z * z)) * 180 / M_PI, 1e-12);
  EXPECT_EQ(quadWarpDeg({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}), 0.0);
}

TEST(RulingWarp, OfAHelicoidRulingIsAtanOmegaAndZeroOnACone) {
  const double omega = 0.7, theta = 0.4;
  const Vec3 b(0.3, std::cos(theta), std::sin(theta));
  const Vec3 db(1, -omega * std::sin(theta), omega * std::cos(theta));
  EXPECT_NEAR(rulingWarpDeg({0.3, 0, 0}, {1, 0, 0}, b, db), std::atan(omega) * 180 / M_PI, 1e-12);
  EXPECT_EQ(rulingWarpDeg({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}), 0.0);
}

TEST(SignedMengerCurvature, IsTheInverseRadiusOfACircleSignedByTheTurn) {
  const double r = 2.5;
  const Vec2 a(r * std::cos(0.1), r * std::sin(0.1)), b(r * std::cos(0.3), r * std::sin(0.3)),
      c(r * std::cos(0.8), r * std::sin(0.8));
  EXPECT_NEAR(signedMengerCurvature(a, b, c), 1 / r, 1e-14);
  EXPECT_NEAR(signedMengerCurvature(c, b, a), -1 / r, 1e-14);
  EXPECT_EQ(signedMengerCurvature(a, b, Vec2(2 * b - a)), 0.0);
}

TEST(CheckCrease, DetectsACreaseWhoseDevelopmentsAreMirrorImages) {
  // The "geodesic" configuration (Tang 8*): the second sheet is the mirror image of the first
  // patch itself, developing to the mirror image of the first development. The osculating plane
  // still bisects, but N₁ − N₂ (not N₁ + N₂) is its normal and κ_g changes sign.
  FoldSamples f = circleFold(1001).samples;
  SheetSamples& s2 = f.sheet[1];
  const SheetSamples& s1 = f.sheet[0];
  for (int i = 0; i < f.size(); ++i) {
    const Vec3 e = s1.rulingEnd.row(i);
    s2.rulingEnd.row(i) = Vec3(e.x(), e.y(), -e.z());
    s2.devCrease.row(i) = Vec2(s1.devCrease(i, 0), -s1.devCrease(i, 1));
    s2.devRulingEnd.row(i) = Vec2(s1.devRulingEnd(i, 0), -s1.devRulingEnd(i, 1));
    s2.dRulingEnd.row(i) = s1.dRulingEnd.row(i);
    s2.dDevCrease.row(i) = Vec2(s1.dDevCrease(i, 0), -s1.dDevCrease(i, 1));
    s2.dDevRulingEnd.row(i) = Vec2(s1.dDevRulingEnd(i, 0), -s1.dDevRulingEnd(i, 1));
  }
  const CreaseCheckReport r = checkCrease(f);
  EXPECT_LE(r.bisectorErrorMax, 1e-9);
  EXPECT_GT(r.foldNormalResidualMax, 0.99);
  // κ_g₂ = −κ_g₁ (about 0.218 here).
  const double kappa = r.sheet[0].geodesicCurvature.cwiseAbs().maxCoeff();
  EXPECT_GT(kappa, 0.2);
  EXPECT_NEAR(r.geodesicCurvatureErrorMax, 2 * kappa, 1e-12);
  EXPECT_NEAR(r.geodesicCurvatureDevErrorMax, 2 * kappa, 1e-5);
  // The developed creases differ (each sheet still lies on "its" other side of its own).
  EXPECT_GT(r.developedCreaseMismatch, 0.1);
  // Each sheet on its own is still developable and isometric to its development.
  for (int k = 0; k < 2; ++k) {
    EXPECT_LE(r.sheet[k].metricErrorMax, 1e-9);
    EXPECT_LE(r.sheet[k].quadWarpMaxDeg, 1e-9);
  }
}

TEST(CheckCrease, DetectsATwistedSheetAndATiltedTangentPlane) {
  FoldSamples f = circlePolygonFold(201).samples;
  const CreaseCheckReport exact = checkCrease(f);
  EXPECT_LE(exact.sheet[1].quadWarpMaxDeg, 1e-9);
  EXPECT_LE(exact.bisectorErrorMaxDiscrete, 1e-12);
  EXPECT_LE(exact.sheet[1].edgeLengthErrorMax, 1e-12);
  SheetSamples& s = f.sheet[1];
  // Twist the second sheet's rulings about the crease tangent by an angle growing with u.
  for (int i = 0; i < f.size(); ++i) {
    const Vec3 c = s.crease.row(i);
    const Vec3 t = (Vec3(s.crease.row(std::min(i + 1, f.size() - 1))) -
                    Vec3(s.crease.row(std::max(i - 1, 0)))).normalized();
    const double a = 0.3 * 2.0 * i / (f.size() - 1);
    const Vec3 r = (Vec3(s.rulingEnd.row(i)) - c) / 0.5;
    const Vec3 rot = r * std::cos(a) + t.cross(r) * std::sin(a) + t * t.dot(r) * (1 - std::cos(a));
    s.rulingEnd.row(i) = c + 0.5 * rot;
  }
  const CreaseCheckReport r = checkCrease(f);
  EXPECT_GT(r.sheet[1].quadWarpMaxDeg, 1e-3);
  EXPECT_GT(r.bisectorErrorMaxDiscrete, 0.1);
  EXPECT_TRUE(std::isnan(r.sheet[1].metricErrorMax));
  EXPECT_GT(std::max(r.sheet[1].edgeLengthErrorMax, r.sheet[1].diagonalLengthErrorMax), 1e-6);
  EXPECT_LE(r.sheet[0].edgeLengthErrorMax, 1e-12);
}

TEST(CheckCrease, MeasuresTheLengthErrorOfAScaledDevelopment) {
  // Sampled lengths, on the exactly isometric polygon fold.
  FoldSamples f = circlePolygonFold(201).samples;
  f.sheet[0].devCrease *= 1.01;
  f.sheet[0].devRulingEnd *= 1.01;
  CreaseCheckReport r = checkCrease(f);
  EXPECT_NEAR(r.sheet[0].edgeLengthErrorMax, 0.01, 1e-12);
  EXPECT_NEAR(r.sheet[0].diagonalLengthErrorMax, 0.01, 1e-12);
  EXPECT_LE(r.sheet[1].edgeLengthErrorMax, 1e-12);
  // Exact first fundamental form, on the parametric fold.
  f = circleFold(201).samples;
  SheetSamples& s = f.sheet[0];
  s.devCrease *= 1.01;
  s.devRulingEnd *= 1.01;
  s.dDevCrease *= 1.01;
  s.dDevRulingEnd *= 1.01;
  r = checkCrease(f);
  EXPECT_NEAR(r.sheet[0].metricErrorMax, 1.01 * 1.01 - 1, 1e-12);  // |E − Ē|/E
  EXPECT_LE(r.sheet[1].metricErrorMax, 1e-9);
}

TEST(CheckCrease, RejectsTooFewSamplesAndMismatchedBlocks) {
  FoldSamples f = circleFold(2).samples;
  EXPECT_THROW(checkCrease(f), std::invalid_argument);
  f = circleFold(10).samples;
  f.sheet[1].devCrease.conservativeResize(9, 2);
  EXPECT_THROW(checkCrease(f), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::creases
