#include "devsurf/creases/CreaseCheck.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace devsurf::creases {

namespace {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDeg = 180.0 / M_PI;

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Angle between two vectors in [0, π] (atan2 form, accurate near 0 and π).
double angle(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// Angle between the lines of a and b in [0, π/2]; NaN if one vanishes.
double lineAngle(const Vec3& a, const Vec3& b) {
  const double la = a.norm(), lb = b.norm();
  if (!(la > 0.0) || !(lb > 0.0)) return kNaN;
  return std::atan2(a.cross(b).norm() / (la * lb), std::abs(a.dot(b)) / (la * lb));
}

double maxSkipNaN(const Eigen::VectorXd& v) {
  double m = kNaN;
  for (int i = 0; i < v.size(); ++i)
    if (!std::isnan(v(i))) m = std::isnan(m) ? v(i) : std::max(m, v(i));
  return m;
}

double maxAbsDiffSkipNaN(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return maxSkipNaN((a - b).cwiseAbs());
}

void requireRows(Eigen::Index rows, Eigen::Index n, const std::string& what) {
  if (rows != n) throw std::invalid_argument("checkCrease: " + what + " has the wrong number of rows");
}

double relError(double exact, double approx) {
  return exact > 0.0 ? std::abs(exact - approx) / exact : std::abs(approx);
}

// Unit osculating-plane normal from exact derivatives (NaN vector where undefined).
Vec3 osculatingNormal(const Vec3& d1, const Vec3& d2) {
  const Vec3 b = d1.cross(d2);
  const double scale = std::pow(d1.norm(), 3);
  if (!(b.norm() > 1e-14 * scale)) return Vec3::Constant(kNaN);
  return b.normalized();
}

SheetCheck checkSheet(const FoldSamples& f, int k, const Eigen::MatrixX3d& bExact,
                      const Eigen::MatrixX3d& bDiscrete, Eigen::MatrixX3d& orientedNormal) {
  const SheetSamples& s = f.sheet[k];
  const int n = s.size();
  const bool exact = f.hasDerivatives();
  SheetCheck r;
  r.side.resize(n);
  r.tangentPlaneAngle.setConstant(n, kNaN);
  r.tangentPlaneAngleDiscrete.setConstant(n, kNaN);
  r.geodesicCurvature.setConstant(n, kNaN);
  r.geodesicCurvatureDev.setConstant(n, kNaN);
  r.geodesicCurvatureMesh.setConstant(n, kNaN);
  r.rulingWarpDeg.setConstant(n, kNaN);
  r.quadWarpDeg.setConstant(n - 1, kNaN);
  orientedNormal.setConstant(n, 3, kNaN);

  for (int i = 0; i < n; ++i) {
    const Vec3 c = s.crease.row(i), e = s.rulingEnd.row(i);
    const Vec2 cb = s.devCrease.row(i), eb = s.devRulingEnd.row(i);
    const Vec3 R = e - c;
    const Vec2 Rb = eb - cb;
    const int lo = std::max(i - 1, 0), hi = std::min(i + 1, n - 1);
    const Vec2 devTangent = exact ? Vec2(s.dDevCrease.row(i))
                                  : Vec2(Vec2(s.devCrease.row(hi)) - Vec2(s.devCrease.row(lo)));
    r.side(i) = cross2(devTangent, Rb) >= 0 ? 1 : -1;

    if (exact) {
      const Vec3 dc = s.dCrease.row(i), de = s.dRulingEnd.row(i);
      r.rulingWarpDeg(i) = rulingWarpDeg(c, dc, e, de);
      const Vec3 N = r.side(i) * dc.cross(R).normalized();
      orientedNormal.row(i) = N;
      const Vec3 d1 = f.creaseD1.row(i), d2 = f.creaseD2.row(i);
      r.geodesicCurvature(i) = d1.cross(d2).dot(N) / std::pow(d1.norm(), 3);
      const Vec3 b = bExact.row(i);
      if (!b.hasNaN()) r.tangentPlaneAngle(i) = lineAngle(N, b);
    }
    if (i == 0 || i == n - 1) continue;

    // Discrete (polyline) quantities at interior samples.
    const Vec3 cm = s.crease.row(i - 1), cp = s.crease.row(i + 1);
    const Vec3 bd = bDiscrete.row(i);
    if (!bd.hasNaN()) r.tangentPlaneAngleDiscrete(i) = lineAngle((cp - cm).cross(R), bd);
    r.geodesicCurvatureDev(i) =
        signedMengerCurvature(s.devCrease.row(i - 1), s.devCrease.row(i), s.devCrease.row(i + 1));
    const double theta = angle(cm - c, R) + angle(R, cp - c);
    const double lm = (cm - c).norm(), lp = (cp - c).norm();
    const double chord = std::sqrt(std::max(0.0, lm * lm + lp * lp - 2 * lm * lp * std::cos(theta)));
    const double alpha = r.side(i) * (M_PI - theta);
    r.geodesicCurvatureMesh(i) = chord > 0.0 ? 2.0 * std::sin(alpha) / chord : kNaN;
  }

  double edgeErr = 0.0, diagErr = 0.0;
  auto len3 = [&](const Eigen::MatrixX3d& A, int i, const Eigen::MatrixX3d& B, int j) {
    return (A.row(i) - B.row(j)).norm();
  };
  auto len2 = [&](const Eigen::MatrixX2d& A, int i, const Eigen::MatrixX2d& B, int j) {
    return (A.row(i) - B.row(j)).norm();
  };
  for (int i = 0; i < n; ++i) {
    edgeErr = std::max(edgeErr, relError(len3(s.crease, i, s.rulingEnd, i),
                                         len2(s.devCrease, i, s.devRulingEnd, i)));
    if (i + 1 == n) break;
    edgeErr = std::max(edgeErr, relError(len3(s.crease, i, s.crease, i + 1),
                                         len2(s.devCrease, i, s.devCrease, i + 1)));
    edgeErr = std::max(edgeErr, relError(len3(s.rulingEnd, i, s.rulingEnd, i + 1),
                                         len2(s.devRulingEnd, i, s.devRulingEnd, i + 1)));
    diagErr = std::max(diagErr, relError(len3(s.crease, i, s.rulingEnd, i + 1),
                                         len2(s.devCrease, i, s.devRulingEnd, i + 1)));
    diagErr = std::max(diagErr, relError(len3(s.crease, i + 1, s.rulingEnd, i),
                                         len2(s.devCrease, i + 1, s.devRulingEnd, i)));
    r.quadWarpDeg(i) = quadWarpDeg(s.crease.row(i), s.crease.row(i + 1), s.rulingEnd.row(i + 1),
                                   s.rulingEnd.row(i));
  }
  r.edgeLengthErrorMax = edgeErr;
  r.diagonalLengthErrorMax = diagErr;
  r.rulingWarpMaxDeg = maxSkipNaN(r.rulingWarpDeg);
  r.quadWarpMaxDeg = n > 1 ? maxSkipNaN(r.quadWarpDeg) : 0.0;

  if (!exact) {
    r.metricErrorMax = kNaN;
    return r;
  }
  double metricErr = 0.0;
  for (int i = 0; i < n; ++i) {
    const Vec3 R = s.rulingEnd.row(i) - s.crease.row(i);
    const Vec2 Rb = s.devRulingEnd.row(i) - s.devCrease.row(i);
    const double L = R.norm(), Lb = Rb.norm();
    metricErr = std::max(metricErr, relError(L, Lb));
    const Vec3 xv = R / L;
    const Vec2 xvb = Rb / Lb;
    const Vec3 du0 = s.dCrease.row(i), du1 = s.dRulingEnd.row(i);
    const Vec2 db0 = s.dDevCrease.row(i), db1 = s.dDevRulingEnd.row(i);
    for (double t : {0.0, 0.5, 1.0}) {  // X_u is linear along the ruling
      const Vec3 xu = (1 - t) * du0 + t * du1;
      const Vec2 xub = (1 - t) * db0 + t * db1;
      const double E = xu.squaredNorm(), Eb = xub.squaredNorm();
      const double F = xu.dot(xv), Fb = xub.dot(xvb);
      metricErr = std::max(metricErr, relError(E, Eb));
      if (E > 0.0) metricErr = std::max(metricErr, std::abs(F - Fb) / std::sqrt(E));
    }
  }
  r.metricErrorMax = metricErr;
  return r;
}

}  // namespace

double rulingWarpDeg(const Vec3& a, const Vec3& da, const Vec3& b, const Vec3& db) {
  const Vec3 ruling = b - a;
  const Vec3 na = da.cross(ruling), nb = db.cross(ruling);
  const double la = na.norm(), lb = nb.norm();
  const double scale = ruling.norm() * std::max(da.norm(), db.norm());
  if (la <= 1e-14 * scale || lb <= 1e-14 * scale) return 0.0;
  return lineAngle(na, nb) * kDeg;
}

double quadWarpDeg(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3) {
  // Diagonal p0p2: triangles (p0, p1, p2) and (p0, p2, p3); diagonal p1p3: (p1, p2, p3), (p1, p3, p0).
  const double a = lineAngle((p1 - p0).cross(p2 - p0), (p2 - p0).cross(p3 - p0));
  const double b = lineAngle((p2 - p1).cross(p3 - p1), (p3 - p1).cross(p0 - p1));
  const double m = std::max(std::isnan(a) ? 0.0 : a, std::isnan(b) ? 0.0 : b);
  return m * kDeg;
}

double signedMengerCurvature(const Vec2& p0, const Vec2& p1, const Vec2& p2) {
  const Vec2 a = p1 - p0, b = p2 - p1, c = p2 - p0;
  const double denom = a.norm() * b.norm() * c.norm();
  if (!(denom > 0.0)) return kNaN;
  return 2.0 * cross2(a, b) / denom;
}

CreaseCheckReport checkCrease(const FoldSamples& f) {
  const int n = f.size();
  if (n < 3) throw std::invalid_argument("checkCrease: need at least 3 samples");
  for (int k = 0; k < 2; ++k) {
    const SheetSamples& s = f.sheet[k];
    const std::string w = "sheet[" + std::to_string(k) + "].";
    requireRows(s.crease.rows(), n, w + "crease");
    requireRows(s.rulingEnd.rows(), n, w + "rulingEnd");
    requireRows(s.devCrease.rows(), n, w + "devCrease");
    requireRows(s.devRulingEnd.rows(), n, w + "devRulingEnd");
  }
  const bool exact = f.hasDerivatives();

  // Osculating plane normals: exact and discrete.
  Eigen::MatrixX3d bExact = Eigen::MatrixX3d::Constant(n, 3, kNaN);
  Eigen::MatrixX3d bDiscrete = Eigen::MatrixX3d::Constant(n, 3, kNaN);
  CreaseCheckReport rep;
  for (int i = 0; i < n; ++i) {
    if (exact) {
      bExact.row(i) = osculatingNormal(f.creaseD1.row(i), f.creaseD2.row(i));
      if (bExact.row(i).hasNaN()) ++rep.osculatingPlaneUndefined;
    }
    if (i == 0 || i == n - 1) continue;
    const Vec3 em = Vec3(f.crease.row(i)) - Vec3(f.crease.row(i - 1));
    const Vec3 ep = Vec3(f.crease.row(i + 1)) - Vec3(f.crease.row(i));
    const Vec3 b = em.cross(ep);
    if (b.norm() > 1e-14 * em.norm() * ep.norm()) bDiscrete.row(i) = b.normalized();
  }

  Eigen::MatrixX3d N[2];
  for (int k = 0; k < 2; ++k) rep.sheet[k] = checkSheet(f, k, bExact, bDiscrete, N[k]);
  const SheetCheck &s1 = rep.sheet[0], &s2 = rep.sheet[1];

  rep.bisectorErrorMax = exact ? maxAbsDiffSkipNaN(s1.tangentPlaneAngle, s2.tangentPlaneAngle) : kNaN;
  rep.bisectorErrorMaxDiscrete =
      maxAbsDiffSkipNaN(s1.tangentPlaneAngleDiscrete, s2.tangentPlaneAngleDiscrete);
  rep.geodesicCurvatureErrorMax =
      exact ? maxAbsDiffSkipNaN(s1.geodesicCurvature, s2.geodesicCurvature) : kNaN;
  rep.geodesicCurvatureDevErrorMax =
      maxAbsDiffSkipNaN(s1.geodesicCurvatureDev, s2.geodesicCurvatureDev);
  rep.geodesicCurvatureMeshErrorMax =
      maxAbsDiffSkipNaN(s1.geodesicCurvatureMesh, s2.geodesicCurvatureMesh);

  rep.foldNormalResidualMax = kNaN;
  if (exact) {
    Eigen::VectorXd residual = Eigen::VectorXd::Constant(n, kNaN);
    for (int i = 0; i < n; ++i) {
      const Vec3 b = bExact.row(i);
      const Vec3 m = Vec3(N[0].row(i)) + Vec3(N[1].row(i));
      if (b.hasNaN() || !(m.norm() > 1e-12)) continue;
      residual(i) = m.normalized().cross(b).norm();
    }
    rep.foldNormalResidualMax = maxSkipNaN(residual);
  }

  rep.developedCreaseMismatch = (f.sheet[0].devCrease - f.sheet[1].devCrease).rowwise().norm().maxCoeff();
  rep.creaseMismatch = std::max((f.sheet[0].crease - f.crease).rowwise().norm().maxCoeff(),
                                (f.sheet[1].crease - f.crease).rowwise().norm().maxCoeff());
  rep.oppositeSides = true;
  for (int i = 0; i < n; ++i)
    if (s1.side(i) == s2.side(i)) rep.oppositeSides = false;
  return rep;
}

}  // namespace devsurf::creases
