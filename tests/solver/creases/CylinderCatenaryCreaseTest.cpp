#include "devsurf/creases/CylinderCatenaryCrease.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>
#include <string>

#include "devsurf/creases/CreaseCheck.h"

namespace devsurf::creases {
namespace {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;

constexpr double kU0 = -1.0, kU1 = 1.2, kL = 0.5;

double lineAngle(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b)));
}

// Parameters of the check: the crease angle φ in degrees.
class CylinderCatenaryCreaseTest : public ::testing::TestWithParam<double> {
 protected:
  double phi() const { return GetParam() * M_PI / 180.0; }
  CylinderCatenaryCrease crease(int side = +1) const {
    return CylinderCatenaryCrease(phi(), kU0, kU1, kL, side);
  }
  static std::vector<double> parameters() {
    std::vector<double> u;
    for (int i = 0; i <= 40; ++i) u.push_back(kU0 + (kU1 - kU0) * i / 40.0);
    return u;
  }
};

TEST_P(CylinderCatenaryCreaseTest, TheCreaseLiesOnTheUnitCylinderWithTheThesisParametrization) {
  const auto cc = crease();
  const double k = 1.0 / std::tan(phi());
  for (double u : parameters()) {
    const Vec3 c = cc.crease(u);
    EXPECT_NEAR(c.x() * c.x() + c.y() * c.y(), 1.0, 1e-15);
    EXPECT_NEAR(c.z(), std::tan(phi()) * std::cosh(u * k), 1e-15 * std::abs(c.z()));
    // p′ = (sin α, cos α) with α(u) = u, and |c′| = cosh(u cot φ) (eq. 3.4).
    const Vec3 dc = cc.crease(u, 1);
    EXPECT_NEAR(dc.x(), std::sin(u), 1e-15);
    EXPECT_NEAR(dc.y(), std::cos(u), 1e-15);
    EXPECT_NEAR(dc.z(), std::sinh(u * k), 1e-14);
    EXPECT_NEAR(dc.norm(), std::cosh(u * k), 1e-13);
  }
}

TEST_P(CylinderCatenaryCreaseTest, TheDevelopedCreaseIsTheCatenaryToMachinePrecision) {
  const auto cc = crease();
  const FoldSamples f = cc.sample(501);
  const double a = std::tan(phi());
  for (int i = 0; i < f.size(); ++i) {
    // Unroll the space crease with the cylinder's own development (arc length, z), where
    // p(u) = (−cos u, sin u) has angle atan2(y, −x) = u.
    const Vec3 c = f.crease.row(i);
    const Vec2 unrolled(std::atan2(c.y(), -c.x()), c.z());
    for (int k = 0; k < 2; ++k) {
      const Vec2 dev = f.sheet[k].devCrease.row(i);
      EXPECT_NEAR((dev - unrolled).norm(), 0.0, 1e-12) << "sheet " << k << " u " << f.u(i);
    }
    const Vec2 dev = f.sheet[0].devCrease.row(i);
    // The catenary y = a cosh(x/a), a = tan φ.
    EXPECT_NEAR(dev.y(), a * std::cosh(dev.x() / a), 1e-12 * dev.y());
    // Its curvature a / y², from the exact derivatives and as developedCurvature().
    const Vec2 d1 = cc.developedCrease(f.u(i), 1), d2 = cc.developedCrease(f.u(i), 2);
    const double kappa = (d1.x() * d2.y() - d1.y() * d2.x()) / std::pow(d1.norm(), 3);
    EXPECT_NEAR(kappa, a / (dev.y() * dev.y()), 1e-12 * kappa);
    EXPECT_NEAR(cc.developedCurvature(f.u(i)), kappa, 1e-12 * kappa);
  }
  EXPECT_EQ(cc.developedCreasePolyline(501), f.sheet[0].devCrease);
  EXPECT_EQ(cc.creasePolyline(501), f.crease);
}

TEST_P(CylinderCatenaryCreaseTest, TheCreaseIsAPseudoGeodesicOfConstantAnglePhiOnTheCylinder) {
  const auto cc = crease();
  for (double u : parameters()) {
    const Vec3 d1 = cc.crease(u, 1), d2 = cc.crease(u, 2);
    // Closed-form Frenet frame against the derivatives.
    EXPECT_NEAR((cc.tangent(u) - d1.normalized()).norm(), 0.0, 1e-15);
    EXPECT_NEAR((cc.osculatingNormal(u) - d1.cross(d2).normalized()).norm(), 0.0, 1e-14);
    const Vec3 n = (d2 - d2.dot(cc.tangent(u)) * cc.tangent(u)).normalized();
    EXPECT_NEAR((cc.principalNormal(u) - n).norm(), 0.0, 1e-14);
    // Angle between the osculating plane and the cylinder's tangent plane (normal ρ) is φ, and
    // the thesis' cos φ = n·b₁ holds with the outward normal.
    EXPECT_NEAR(lineAngle(cc.osculatingNormal(u), cc.sheetNormal(0, u)), phi(), 1e-14);
    EXPECT_NEAR(cc.principalNormal(u).dot(cc.sheetBinormal(0, u)), std::cos(phi()), 1e-14);
    // κ_d = κ cos φ in magnitude: the crease is more strongly curved than its development.
    const double kappa = d1.cross(d2).norm() / std::pow(d1.norm(), 3);
    EXPECT_NEAR(cc.developedCurvature(u), kappa * std::cos(phi()), 1e-13 * kappa);
  }
}

TEST_P(CylinderCatenaryCreaseTest, TheSecondTangentPlaneIsTheCylindersReflectedInTheOsculatingPlane) {
  const auto cc = crease();
  for (double u : parameters()) {
    const Vec3 b = cc.osculatingNormal(u), n1 = cc.sheetNormal(0, u);
    const Vec3 reflected = n1 - 2 * n1.dot(b) * b;
    EXPECT_NEAR((cc.secondPlaneNormal(u) + reflected).norm(), 0.0, 1e-14);  // n₂ = −R n₁
    EXPECT_NEAR(cc.secondPlaneNormal(u).norm(), 1.0, 1e-15);
    EXPECT_NEAR(cc.secondPlaneNormal(u).dot(cc.crease(u, 1)), 0.0, 1e-13);  // contains the tangent
    EXPECT_NEAR(cc.secondPlaneOffset(u), cc.secondPlaneNormal(u).dot(cc.crease(u)), 1e-15);
    // Thesis frames: n₂ = sin φ n − cos φ b, b₂ = cos φ n + sin φ b = R b₁.
    const Vec3 n = cc.principalNormal(u);
    const double s = std::sin(phi()), c = std::cos(phi());
    EXPECT_NEAR((cc.sheetNormal(1, u) - (s * n - c * b)).norm(), 0.0, 1e-14);
    EXPECT_NEAR((cc.sheetBinormal(1, u) - (c * n + s * b)).norm(), 0.0, 1e-14);
    EXPECT_NEAR((cc.sheetNormal(0, u) - (-s * n - c * b)).norm(), 0.0, 1e-14);
    EXPECT_NEAR((cc.sheetBinormal(0, u) - (c * n - s * b)).norm(), 0.0, 1e-14);
    // The bisector property: both tangent planes make the angle φ with the osculating plane.
    EXPECT_NEAR(lineAngle(cc.secondPlaneNormal(u), b), phi(), 1e-14);
  }
}

TEST_P(CylinderCatenaryCreaseTest, TheSecondRulingIsTheCharacteristicLineOfTheReflectedPlanes) {
  const auto cc = crease();
  const double h = 1e-5;
  for (double u : parameters()) {
    const Vec3 n2 = cc.secondPlaneNormal(u), dn2 = cc.secondPlaneNormal(u, 1);
    // The exact derivatives of the plane family match central differences.
    const Vec3 fd1 = (cc.secondPlaneNormal(u + h) - cc.secondPlaneNormal(u - h)) / (2 * h);
    const Vec3 fd2 = (cc.secondPlaneNormal(u + h, 1) - cc.secondPlaneNormal(u - h, 1)) / (2 * h);
    EXPECT_NEAR((fd1 - dn2).norm(), 0.0, 1e-9);
    EXPECT_NEAR((fd2 - cc.secondPlaneNormal(u, 2)).norm(), 0.0, 1e-8);
    const double fdOffset = (cc.secondPlaneOffset(u + h) - cc.secondPlaneOffset(u - h)) / (2 * h);
    EXPECT_NEAR(fdOffset, cc.secondPlaneOffset(u, 1), 1e-9);
    EXPECT_GT(dn2.norm(), 0.1);  // the family never stalls: n₂ × n₂′ is a line
    // Every point of the ruling lies on the plane and on its derivative plane.
    const Vec3 r2 = cc.ruling(1, u);
    EXPECT_NEAR(r2.norm(), 1.0, 1e-15);
    for (double v : {0.0, 0.25, kL}) {
      const Vec3 x = cc.crease(u) + v * r2;
      EXPECT_NEAR(n2.dot(x) - cc.secondPlaneOffset(u), 0.0, 1e-14);
      EXPECT_NEAR(dn2.dot(x) - cc.secondPlaneOffset(u, 1), 0.0, 1e-13);
    }
    // Oriented so that the paper continues across the crease: r₂·b₂ < 0 for side +1.
    EXPECT_LT(r2.dot(cc.sheetBinormal(1, u)), 0.0);
  }
}

TEST_P(CylinderCatenaryCreaseTest, TheDevelopedRulingsAreReflectedAtTheDevelopedTangent) {
  // Constant angle ⇒ ψ₂ = π − ψ₁ (thesis 1.8): with ψ₁ from the vertical rulings this gives
  // r̄₂ = (2 sinh, sinh² − 1)/cosh² (argument u cot φ).
  for (int side : {+1, -1}) {
    const auto cc = crease(side);
    const double k = 1.0 / std::tan(phi());
    for (double u : parameters()) {
      const double s = std::sinh(u * k), c = std::cosh(u * k);
      const Vec2 expected = side * Vec2(2 * s, s * s - 1) / (c * c);
      EXPECT_NEAR((cc.developedRuling(1, u) - expected).norm(), 0.0, 1e-14);
      EXPECT_NEAR((cc.developedRuling(0, u) - Vec2(0, side)).norm(), 0.0, 0.0);
      // The mirror image of r̄₁ in the developed tangent t̄ is r̄₂.
      const Vec2 t = cc.developedCrease(u, 1).normalized();
      const Vec2 r1 = cc.developedRuling(0, u);
      const Vec2 mirrored = 2 * r1.dot(t) * t - r1;
      EXPECT_NEAR((mirrored - cc.developedRuling(1, u)).norm(), 0.0, 1e-14);
      // The developed ruling keeps the angle to the tangent it has in space.
      for (int sheet : {0, 1}) {
        EXPECT_NEAR(cc.developedRuling(sheet, u).dot(t), cc.ruling(sheet, u).dot(cc.tangent(u)),
                    1e-14);
      }
    }
  }
}

TEST_P(CylinderCatenaryCreaseTest, TheExactDerivativesMatchFiniteDifferences) {
  const auto cc = crease();
  const double h = 1e-5;
  for (double u : parameters()) {
    for (int d = 0; d < 3; ++d) {
      const Vec3 fd = (cc.crease(u + h, d) - cc.crease(u - h, d)) / (2 * h);
      EXPECT_NEAR((fd - cc.crease(u, d + 1)).norm(), 0.0, 1e-8 * (1 + fd.norm())) << d;
      const Vec2 fdb = (cc.developedCrease(u + h, d) - cc.developedCrease(u - h, d)) / (2 * h);
      EXPECT_NEAR((fdb - cc.developedCrease(u, d + 1)).norm(), 0.0, 1e-8 * (1 + fdb.norm())) << d;
    }
    for (int sheet : {0, 1}) {
      const Vec3 fd = (cc.ruling(sheet, u + h) - cc.ruling(sheet, u - h)) / (2 * h);
      EXPECT_NEAR((fd - cc.ruling(sheet, u, 1)).norm(), 0.0, 1e-8);
      const Vec2 fdb = (cc.developedRuling(sheet, u + h) - cc.developedRuling(sheet, u - h)) / (2 * h);
      EXPECT_NEAR((fdb - cc.developedRuling(sheet, u, 1)).norm(), 0.0, 1e-8);
    }
  }
}

TEST_P(CylinderCatenaryCreaseTest, TheOsculatingPlaneBisectsTheTangentPlanesOfBothSheets) {
  const CreaseCheckReport r = checkCrease(crease().sample(2001));
  EXPECT_EQ(r.osculatingPlaneUndefined, 0);
  EXPECT_LE(r.bisectorErrorMax, 1e-9);
  EXPECT_LE(r.foldNormalResidualMax, 1e-9);  // N₁ + N₂ ∥ b: a curved fold, not a geodesic crease
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < r.sheet[k].tangentPlaneAngle.size(); ++i)
      EXPECT_NEAR(r.sheet[k].tangentPlaneAngle(i), phi(), 1e-12);
  // From the polylines alone (discrete osculating plane, central chord) the property holds to
  // second order.
  EXPECT_LE(r.bisectorErrorMaxDiscrete, 2e-5);
}

TEST_P(CylinderCatenaryCreaseTest, TheGeodesicCurvaturesOnBothSidesAgree) {
  const auto cc = crease();
  const FoldSamples f = cc.sample(8001);
  const CreaseCheckReport r = checkCrease(f);
  // Exact, in space, with the oriented normals (7*): both equal the catenary's curvature.
  EXPECT_LE(r.geodesicCurvatureErrorMax, 1e-12);
  for (int i = 0; i < f.size(); ++i)
    for (int k = 0; k < 2; ++k)
      EXPECT_NEAR(r.sheet[k].geodesicCurvature(i), cc.developedCurvature(f.u(i)), 1e-12);
  // From the developments by finite differences: the developments share the developed crease
  // and lie on opposite sides of it, and their curvature is each sheet's geodesic curvature.
  EXPECT_TRUE(r.oppositeSides);
  EXPECT_EQ(r.developedCreaseMismatch, 0.0);
  EXPECT_LE(r.geodesicCurvatureDevErrorMax, 1e-6);
  for (int k = 0; k < 2; ++k)
    for (int i = 1; i + 1 < f.size(); ++i)
      EXPECT_NEAR(r.sheet[k].geodesicCurvatureDev(i), r.sheet[k].geodesicCurvature(i), 1e-6);
  // Intrinsically, from the angles of each space mesh at the crease vertices.
  EXPECT_LE(r.geodesicCurvatureMeshErrorMax, 1e-6);
  for (int k = 0; k < 2; ++k)
    for (int i = 1; i + 1 < f.size(); ++i)
      EXPECT_NEAR(r.sheet[k].geodesicCurvatureMesh(i), r.sheet[k].geodesicCurvature(i), 1e-6);
}

TEST_P(CylinderCatenaryCreaseTest, EachSheetIsDevelopable) {
  const CreaseCheckReport coarse = checkCrease(crease().sample(201));
  const CreaseCheckReport fine = checkCrease(crease().sample(2001));
  for (int k = 0; k < 2; ++k) {
    // One tangent plane along every ruling (exact tangents of both ruling ends).
    EXPECT_LE(fine.sheet[k].rulingWarpMaxDeg, 1e-9) << "sheet " << k;
  }
  // The cylinder's ruling quads are planar (parallel rulings).
  EXPECT_LE(fine.sheet[0].quadWarpMaxDeg, 1e-9);
  // The second sheet's rulings at u_i and u_{i+1} are skew lines (as on any developable that is
  // not a cylinder): its sampled quads are planar only to second order in the spacing.
  const double ratio = coarse.sheet[1].quadWarpMaxDeg / fine.sheet[1].quadWarpMaxDeg;
  EXPECT_GT(ratio, 80.0);
  EXPECT_LT(ratio, 120.0);
  EXPECT_LE(fine.sheet[1].quadWarpMaxDeg, 1e-5);
}

TEST_P(CylinderCatenaryCreaseTest, EachSheetsDevelopmentIsIsometric) {
  const CreaseCheckReport r = checkCrease(crease().sample(2001));
  for (int k = 0; k < 2; ++k) {
    // Exact first fundamental forms of c + v r and c̄ + v r̄ along every sampled ruling.
    EXPECT_LE(r.sheet[k].metricErrorMax, 1e-9) << "sheet " << k;
    // Sampled: edge and diagonal lengths of the quad meshes (chords of curves, O(h²)).
    EXPECT_LE(r.sheet[k].edgeLengthErrorMax, 1e-6) << "sheet " << k;
    EXPECT_LE(r.sheet[k].diagonalLengthErrorMax, 1e-6) << "sheet " << k;
  }
}

TEST_P(CylinderCatenaryCreaseTest, TheOppositeSideMirrorsThePatchesAndKeepsTheFold) {
  const auto up = crease(+1), down = crease(-1);
  const FoldSamples f = down.sample(1001);
  for (int i = 0; i < f.size(); ++i) {
    const double u = f.u(i);
    EXPECT_EQ(down.ruling(0, u), Vec3(0, 0, -1));
    EXPECT_NEAR((down.ruling(1, u) + up.ruling(1, u)).norm(), 0.0, 1e-15);
    // The first patch develops below the catenary, the second above it.
    EXPECT_LT(f.sheet[0].devRulingEnd(i, 1), f.sheet[0].devCrease(i, 1));
    const Vec2 tangent = down.developedCrease(u, 1);
    const Vec2 r2 = down.developedRuling(1, u);
    EXPECT_GT(tangent.x() * r2.y() - tangent.y() * r2.x(), 0.0);
  }
  const CreaseCheckReport r = checkCrease(f);
  EXPECT_TRUE(r.oppositeSides);
  EXPECT_LE(r.bisectorErrorMax, 1e-9);
  EXPECT_LE(r.foldNormalResidualMax, 1e-9);
  EXPECT_LE(r.geodesicCurvatureErrorMax, 1e-12);
  for (int k = 0; k < 2; ++k) {
    EXPECT_LE(r.sheet[k].rulingWarpMaxDeg, 1e-9);
    EXPECT_LE(r.sheet[k].metricErrorMax, 1e-9);
  }
}

TEST_P(CylinderCatenaryCreaseTest, TheSecondPatchMeetsItsEdgeOfRegressionOnlyOnTheConcaveSide) {
  // side +1: the second patch develops below the convex catenary, its rulings diverge, the edge
  // of regression lies on the other half of the sheet (v* < 0); side −1: above, converging.
  for (double u : parameters()) {
    EXPECT_LT(crease(+1).regressionParameter(1, u), 0.0);
    EXPECT_GT(crease(-1).regressionParameter(1, u), 0.0);
    EXPECT_TRUE(std::isinf(crease(+1).regressionParameter(0, u)));
  }
}

TEST_P(CylinderCatenaryCreaseTest, TheMeshesAreStripsCounterClockwiseInTheDevelopment) {
  const auto cc = crease();
  const int n = 101;
  for (int sheet : {0, 1}) {
    const QuadMesh3 mesh = cc.sheetMesh(sheet, n);
    const QuadMesh2 dev = cc.developmentMesh(sheet, n);
    ASSERT_EQ(mesh.vertices.rows(), 2 * n);
    ASSERT_EQ(dev.vertices.rows(), 2 * n);
    ASSERT_EQ(mesh.quads.rows(), n - 1);
    EXPECT_EQ(mesh.quads, dev.quads);
    for (int q = 0; q < dev.quads.rows(); ++q) {
      double area = 0.0;
      for (int j = 0; j < 4; ++j) {
        const Vec2 a = dev.vertices.row(dev.quads(q, j)), b = dev.vertices.row(dev.quads(q, (j + 1) % 4));
        area += a.x() * b.y() - a.y() * b.x();
      }
      EXPECT_GT(area, 0.0);
    }
    for (int i = 0; i < n; ++i) {
      EXPECT_NEAR((mesh.vertices.row(2 * i + 1) - mesh.vertices.row(2 * i)).norm(), kL, 1e-14);
      EXPECT_NEAR((dev.vertices.row(2 * i + 1) - dev.vertices.row(2 * i)).norm(), kL, 1e-14);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(CreaseAngles, CylinderCatenaryCreaseTest, ::testing::Values(20.0, 35.0, 60.0),
                         [](const ::testing::TestParamInfo<double>& info) {
                           return "Phi" + std::to_string(static_cast<int>(info.param)) + "Degrees";
                         });

TEST(CylinderCatenaryCrease, RejectsAnglesIntervalsLengthsAndSidesOutOfRange) {
  EXPECT_THROW(CylinderCatenaryCrease(0.0, 0, 1, 1), std::invalid_argument);
  EXPECT_THROW(CylinderCatenaryCrease(M_PI / 2, 0, 1, 1), std::invalid_argument);
  EXPECT_THROW(CylinderCatenaryCrease(0.5, 1, 1, 1), std::invalid_argument);
  EXPECT_THROW(CylinderCatenaryCrease(0.5, 0, 1, 0), std::invalid_argument);
  EXPECT_THROW(CylinderCatenaryCrease(0.5, 0, 1, 1, 0), std::invalid_argument);
  const CylinderCatenaryCrease cc(0.5, 0, 1, 1);
  EXPECT_THROW(cc.sample(1), std::invalid_argument);
  EXPECT_THROW(cc.ruling(2, 0.0), std::invalid_argument);
  EXPECT_THROW(cc.ruling(1, 0.0, 2), std::invalid_argument);
  EXPECT_THROW(cc.secondPlaneNormal(0.0, 3), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::creases
