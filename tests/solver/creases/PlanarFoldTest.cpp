#include "devsurf/creases/PlanarFold.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <stdexcept>

#include "devsurf/creases/CreaseCheck.h"

namespace devsurf::creases {
namespace {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;

// An ellipse arc (2 cos u, sin u), u ∈ [0.2, 2.5]: curvature of one sign.
PlanarCurve ellipseArc() {
  PlanarCurve g;
  g.u0 = 0.2;
  g.u1 = 2.5;
  g.evaluate = [](double u, int d) -> Vec2 {
    if (d == 0) return {2 * std::cos(u), std::sin(u)};
    if (d == 1) return {-2 * std::sin(u), std::cos(u)};
    return {-2 * std::cos(u), -std::sin(u)};
  };
  return g;
}

const Vec3 kDirection(0.3, -0.2, 1.0);
constexpr double kFoldL = 0.7;

Vec3 mirror(const Vec3& x) { return {x.x(), x.y(), -x.z()}; }

TEST(PlanarFoldByReflection, TheSecondSheetIsTheMirrorImageOfTheCylindersOtherHalf) {
  const PlanarFold fold = planarFoldByReflection(ellipseArc(), kDirection, kFoldL, 301);
  const Vec3 d = kDirection.normalized();
  EXPECT_NEAR((fold.rulingFirst - d).norm(), 0.0, 1e-15);
  EXPECT_NEAR((fold.rulingSecond - Vec3(-d.x(), -d.y(), d.z())).norm(), 0.0, 1e-15);
  const FoldSamples& f = fold.samples;
  for (int i = 0; i < f.size(); ++i) {
    const Vec3 c = f.crease.row(i);
    EXPECT_EQ(c.z(), 0.0);
    // The mirror image (in z = 0, the osculating plane) of the cylinder's point c − L d.
    EXPECT_NEAR((Vec3(f.sheet[1].rulingEnd.row(i)) - mirror(c - kFoldL * d)).norm(), 0.0, 1e-15);
    EXPECT_NEAR((Vec3(f.sheet[0].rulingEnd.row(i)) - (c + kFoldL * d)).norm(), 0.0, 1e-15);
    // Both patches lie on the same side of the crease plane.
    EXPECT_GT(f.sheet[0].rulingEnd(i, 2), 0.0);
    EXPECT_GT(f.sheet[1].rulingEnd(i, 2), 0.0);
  }
}

TEST(PlanarFoldByReflection, TheDevelopedRulingsContinueStraightAcrossTheCrease) {
  // Planar crease ⇔ ψ₁ = ψ₂ (thesis 1.7): the developed rulings are collinear.
  const PlanarFold fold = planarFoldByReflection(ellipseArc(), kDirection, kFoldL, 301);
  const FoldSamples& f = fold.samples;
  for (int i = 0; i < f.size(); ++i) {
    const Vec2 r1 = Vec2(f.sheet[0].devRulingEnd.row(i)) - Vec2(f.sheet[0].devCrease.row(i));
    const Vec2 r2 = Vec2(f.sheet[1].devRulingEnd.row(i)) - Vec2(f.sheet[1].devCrease.row(i));
    EXPECT_NEAR((r1 + r2).norm(), 0.0, 1e-15);
  }
}

TEST(PlanarFoldByReflection, TheDevelopmentOfAVerticalCylinderIsTheUnrolledArcLength) {
  // A circle of radius 1.5 with vertical rulings: s(u) = 1.5 (u − u0), c̄ = (s, 0).
  PlanarCurve circle;
  circle.u0 = -0.4;
  circle.u1 = 2.0;
  circle.evaluate = [](double u, int d) -> Vec2 {
    const double r = 1.5;
    if (d == 0) return {r * std::cos(u), r * std::sin(u)};
    if (d == 1) return {-r * std::sin(u), r * std::cos(u)};
    return {-r * std::cos(u), -r * std::sin(u)};
  };
  const PlanarFold fold = planarFoldByReflection(circle, Vec3(0, 0, 2), 1.0, 97);
  for (int i = 0; i < fold.samples.size(); ++i) {
    const Vec2 dev = fold.developedCreasePolyline().row(i);
    EXPECT_NEAR(dev.x(), 1.5 * (fold.samples.u(i) + 0.4), 1e-13);
    EXPECT_NEAR(dev.y(), 0.0, 1e-15);
  }
}

TEST(PlanarFoldByReflection, TheParametricFoldPassesEveryCreaseCheck) {
  const PlanarFold fold = planarFoldByReflection(ellipseArc(), kDirection, kFoldL, 8001);
  const CreaseCheckReport r = checkCrease(fold.samples);
  EXPECT_EQ(r.osculatingPlaneUndefined, 0);
  // Bisector property, exact and from the polylines (the crease polyline is planar too).
  EXPECT_LE(r.bisectorErrorMax, 1e-9);
  EXPECT_LE(r.bisectorErrorMaxDiscrete, 1e-9);
  EXPECT_LE(r.foldNormalResidualMax, 1e-9);
  // Geodesic curvatures: exact in space, from the developments, intrinsically from the meshes.
  EXPECT_LE(r.geodesicCurvatureErrorMax, 1e-12);
  EXPECT_LE(r.geodesicCurvatureDevErrorMax, 1e-6);
  EXPECT_LE(r.geodesicCurvatureMeshErrorMax, 1e-6);
  for (int k = 0; k < 2; ++k)
    for (int i = 1; i + 1 < fold.samples.size(); ++i)
      EXPECT_NEAR(r.sheet[k].geodesicCurvatureDev(i), r.sheet[k].geodesicCurvature(i), 1e-6);
  EXPECT_TRUE(r.oppositeSides);
  EXPECT_EQ(r.developedCreaseMismatch, 0.0);
  for (int k = 0; k < 2; ++k) {
    // Cylinders: ruling quads are parallelograms, hence planar.
    EXPECT_LE(r.sheet[k].rulingWarpMaxDeg, 1e-9);
    EXPECT_LE(r.sheet[k].quadWarpMaxDeg, 1e-9);
    // Exact isometry (s(u) by quadrature) and sampled edges and diagonals.
    EXPECT_LE(r.sheet[k].metricErrorMax, 1e-9);
    EXPECT_LE(r.sheet[k].edgeLengthErrorMax, 1e-6);
    EXPECT_LE(r.sheet[k].diagonalLengthErrorMax, 1e-6);
  }
}

TEST(PlanarFoldByReflection, APolylineFoldIsExactlyIsometricAndPlanar) {
  const int n = 400;
  Eigen::MatrixX2d polyline(n, 2);
  for (int i = 0; i < n; ++i) {
    const double u = 0.2 + 2.3 * i / (n - 1.0);
    polyline.row(i) << 2 * std::cos(u), std::sin(u);
  }
  const PlanarFold fold = planarFoldByReflection(polyline, kDirection, kFoldL);
  EXPECT_FALSE(fold.samples.hasDerivatives());
  const CreaseCheckReport r = checkCrease(fold.samples);
  EXPECT_TRUE(std::isnan(r.bisectorErrorMax));  // no derivative data: the exact checks are off
  EXPECT_LE(r.bisectorErrorMaxDiscrete, 1e-12);
  EXPECT_LE(r.geodesicCurvatureDevErrorMax, 1e-12);
  EXPECT_LE(r.geodesicCurvatureMeshErrorMax, 1e-9);
  EXPECT_TRUE(r.oppositeSides);
  for (int k = 0; k < 2; ++k) {
    EXPECT_LE(r.sheet[k].quadWarpMaxDeg, 1e-9);
    EXPECT_LE(r.sheet[k].edgeLengthErrorMax, 1e-12);
    EXPECT_LE(r.sheet[k].diagonalLengthErrorMax, 1e-12);
    EXPECT_TRUE(std::isnan(r.sheet[k].metricErrorMax));
    // The intrinsic (mesh) geodesic curvature equals the developed polyline's.
    for (int i = 1; i + 1 < n; ++i)
      EXPECT_NEAR(r.sheet[k].geodesicCurvatureMesh(i), r.sheet[k].geodesicCurvatureDev(i), 1e-9);
  }
  // Meshes: strips over the polyline.
  const QuadMesh3 mesh = fold.sheetMesh(1);
  EXPECT_EQ(mesh.vertices.rows(), 2 * n);
  EXPECT_EQ(mesh.quads.rows(), n - 1);
  EXPECT_EQ(fold.developmentMesh(1).quads, mesh.quads);
}

TEST(PlanarFoldByReflection, AnInflectionPointOfTheCreaseIsSkippedByTheExactChecks) {
  // γ(u) = (u, u³) on [−1, 1] sampled with u = 0 among the samples: γ″(0) = 0.
  PlanarCurve cubic;
  cubic.u0 = -1.0;
  cubic.u1 = 1.0;
  cubic.evaluate = [](double u, int d) -> Vec2 {
    if (d == 0) return {u, u * u * u};
    if (d == 1) return {1.0, 3 * u * u};
    return {0.0, 6 * u};
  };
  const PlanarFold fold = planarFoldByReflection(cubic, Vec3(0.2, 0.4, 1.0), 0.5, 2001);
  const CreaseCheckReport r = checkCrease(fold.samples);
  EXPECT_EQ(r.osculatingPlaneUndefined, 1);
  EXPECT_LE(r.bisectorErrorMax, 1e-9);
  EXPECT_LE(r.geodesicCurvatureErrorMax, 1e-12);
  EXPECT_LE(r.geodesicCurvatureDevErrorMax, 1e-6);
  for (int k = 0; k < 2; ++k) EXPECT_LE(r.sheet[k].metricErrorMax, 1e-9);
}

TEST(PlanarFoldByReflection, RejectsRulingsInTheCreasePlaneAndDegenerateInput) {
  EXPECT_THROW(planarFoldByReflection(ellipseArc(), Vec3(1, 0, 0), 1.0, 10), std::invalid_argument);
  EXPECT_THROW(planarFoldByReflection(ellipseArc(), Vec3(0, 0, 0), 1.0, 10), std::invalid_argument);
  EXPECT_THROW(planarFoldByReflection(ellipseArc(), kDirection, 0.0, 10), std::invalid_argument);
  EXPECT_THROW(planarFoldByReflection(ellipseArc(), kDirection, 1.0, 1), std::invalid_argument);
  EXPECT_THROW(planarFoldByReflection(PlanarCurve{}, kDirection, 1.0, 10), std::invalid_argument);
  Eigen::MatrixX2d repeated(3, 2);
  repeated << 0, 0, 1, 0, 1, 0;
  EXPECT_THROW(planarFoldByReflection(repeated, kDirection, 1.0), std::invalid_argument);
  EXPECT_THROW(planarFoldByReflection(Eigen::MatrixX2d(1, 2), kDirection, 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::creases
