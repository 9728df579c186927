#include "devsurf/creases/CylinderCatenaryCrease.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace devsurf::creases {

namespace {

using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;

// Moving frame of the cylinder along p(u) = (−cos u, sin u): outward normal ρ, unit tangent
// e_u = p′, axis e₃. ρ′ = e_u, e_u′ = −ρ.
Vec3 rho(double u) { return {-std::cos(u), std::sin(u), 0.0}; }
Vec3 eu(double u) { return {std::sin(u), std::cos(u), 0.0}; }
const Vec3 e3(0.0, 0.0, 1.0);

void requireSheet(int sheet, const char* who) {
  if (sheet != 0 && sheet != 1)
    throw std::invalid_argument(std::string(who) + ": sheet must be 0 or 1");
}

}  // namespace

CylinderCatenaryCrease::CylinderCatenaryCrease(double phi, double u0, double u1,
                                               double rulingLength, int side)
    : phi_(phi), u0_(u0), u1_(u1), length_(rulingLength), side_(side) {
  if (!(phi > 0.0 && phi < M_PI / 2))
    throw std::invalid_argument("CylinderCatenaryCrease: phi must lie in (0, pi/2)");
  if (!(u0 < u1) || !std::isfinite(u0) || !std::isfinite(u1))
    throw std::invalid_argument("CylinderCatenaryCrease: need finite u0 < u1");
  if (!(rulingLength > 0.0) || !std::isfinite(rulingLength))
    throw std::invalid_argument("CylinderCatenaryCrease: rulingLength must be positive");
  if (side != 1 && side != -1)
    throw std::invalid_argument("CylinderCatenaryCrease: side must be +1 or -1");
  k_ = std::cos(phi) / std::sin(phi);
  a_ = std::tan(phi);
}

double CylinderCatenaryCrease::height(double u, int d) const {
  if (d < 0) throw std::invalid_argument("height: negative derivative order");
  // h = a cosh(k u); h^(d) = a k^d (cosh or sinh), a k = 1.
  const double x = k_ * u;
  const double hyp = (d % 2 == 0) ? std::cosh(x) : std::sinh(x);
  return a_ * std::pow(k_, d) * hyp;
}

Vec3 CylinderCatenaryCrease::crease(double u, int d) const {
  if (d < 0) throw std::invalid_argument("crease: negative derivative order");
  // cos^(d)(u) = cos(u + dπ/2), sin^(d)(u) = sin(u + dπ/2), by exact quarter turns.
  double cs, sn;
  switch (d % 4) {
    case 0: cs = std::cos(u), sn = std::sin(u); break;
    case 1: cs = -std::sin(u), sn = std::cos(u); break;
    case 2: cs = -std::cos(u), sn = -std::sin(u); break;
    default: cs = std::sin(u), sn = -std::cos(u); break;
  }
  return {-cs, sn, height(u, d)};
}

Vec2 CylinderCatenaryCrease::developedCrease(double u, int d) const {
  if (d < 0) throw std::invalid_argument("developedCrease: negative derivative order");
  const double x = d == 0 ? u : (d == 1 ? 1.0 : 0.0);
  return {x, height(u, d)};
}

Vec3 CylinderCatenaryCrease::tangent(double u) const {
  const double x = k_ * u;
  return (eu(u) + std::sinh(x) * e3) / std::cosh(x);
}

Vec3 CylinderCatenaryCrease::principalNormal(double u) const {
  return -std::sin(phi_) * rho(u) + std::cos(phi_) * sheetBinormal(0, u);
}

Vec3 CylinderCatenaryCrease::osculatingNormal(double u) const {
  return -std::cos(phi_) * rho(u) - std::sin(phi_) * sheetBinormal(0, u);
}

Vec3 CylinderCatenaryCrease::sheetNormal(int sheet, double u) const {
  requireSheet(sheet, "sheetNormal");
  if (sheet == 0) return rho(u);
  return secondPlaneNormal(u, 0);
}

Vec3 CylinderCatenaryCrease::sheetBinormal(int sheet, double u) const {
  requireSheet(sheet, "sheetBinormal");
  const double x = k_ * u;
  const double S = 1.0 / std::cosh(x), T = std::tanh(x);
  const Vec3 b1 = S * e3 - T * eu(u);  // t × ρ
  if (sheet == 0) return b1;
  return -std::sin(2 * phi_) * rho(u) + std::cos(2 * phi_) * b1;
}

Vec3 CylinderCatenaryCrease::secondPlaneNormal(double u, int d) const {
  const double x = k_ * u, k = k_;
  const double S = 1.0 / std::cosh(x), T = std::tanh(x);
  const double A = std::cos(2 * phi_), B = std::sin(2 * phi_);
  const Vec3 r = rho(u), e = eu(u);
  // n₂ = A ρ + B b₁,  b₁ = S e₃ − T e_u  (T′ = k S², S′ = −k T S).
  switch (d) {
    case 0:
      return A * r + B * (S * e3 - T * e);
    case 1: {
      const Vec3 db1 = -k * T * S * e3 - k * S * S * e + T * r;
      return A * e + B * db1;
    }
    case 2: {
      const Vec3 ddb1 = -k * k * S * (S * S - T * T) * e3 + T * (2 * k * k * S * S + 1) * e +
                        2 * k * S * S * r;
      return -A * r + B * ddb1;
    }
    default:
      throw std::invalid_argument("secondPlaneNormal: derivative order must be 0, 1 or 2");
  }
}

double CylinderCatenaryCrease::secondPlaneOffset(double u, int d) const {
  // d₂ = n₂·c; d₂′ = n₂′·c + n₂·c′ = n₂′·c (c′ lies in the plane).
  if (d == 0) return secondPlaneNormal(u, 0).dot(crease(u, 0));
  if (d == 1)
    return secondPlaneNormal(u, 1).dot(crease(u, 0)) + secondPlaneNormal(u, 0).dot(crease(u, 1));
  throw std::invalid_argument("secondPlaneOffset: derivative order must be 0 or 1");
}

Vec3 CylinderCatenaryCrease::ruling(int sheet, double u, int d) const {
  requireSheet(sheet, "ruling");
  if (d != 0 && d != 1) throw std::invalid_argument("ruling: derivative order must be 0 or 1");
  if (sheet == 0) return d == 0 ? Vec3(side_ * e3) : Vec3::Zero();
  const Vec3 n2 = secondPlaneNormal(u, 0), dn2 = secondPlaneNormal(u, 1),
             ddn2 = secondPlaneNormal(u, 2);
  const Vec3 w = n2.cross(dn2);  // n₂′ ≠ 0 for every φ ∈ (0, π/2), see the tests
  const double len = w.norm();
  const Vec3 dir = w / len;
  // Orientation: the second patch continues the paper across the crease, r₂·b₂ ~ −side.
  const double sign = (dir.dot(sheetBinormal(1, u)) * side_ < 0) ? 1.0 : -1.0;
  if (d == 0) return sign * dir;
  const Vec3 dw = n2.cross(ddn2);
  return sign * (dw - dw.dot(dir) * dir) / len;
}

Vec2 CylinderCatenaryCrease::developedRuling(int sheet, double u, int d) const {
  requireSheet(sheet, "developedRuling");
  if (d != 0 && d != 1)
    throw std::invalid_argument("developedRuling: derivative order must be 0 or 1");
  if (sheet == 0) return d == 0 ? Vec2(0.0, side_) : Vec2::Zero();
  const double x = k_ * u, k = k_;
  const double S = 1.0 / std::cosh(x), T = std::tanh(x);
  const Vec2 tb(S, T), jtb(-T, S);  // t̄ = c̄′/|c̄′| and its left normal J t̄
  const Vec3 t = tangent(u), b2 = sheetBinormal(1, u), r2 = ruling(1, u, 0);
  const double alpha = r2.dot(t), beta = r2.dot(b2);
  if (d == 0) return alpha * tb + beta * jtb;
  // Exact derivative: t′ = (c″ − (c″·t) t)/|c′|, b₂′ = −sin2φ e_u + cos2φ b₁′,
  // t̄′ = k S J t̄, (J t̄)′ = −k S t̄.
  const Vec3 ddc = crease(u, 2);
  const Vec3 dt = (ddc - ddc.dot(t) * t) * S;
  const Vec3 db1 = -k * T * S * e3 - k * S * S * eu(u) + T * rho(u);
  const Vec3 db2 = -std::sin(2 * phi_) * eu(u) + std::cos(2 * phi_) * db1;
  const Vec3 dr2 = ruling(1, u, 1);
  const double dalpha = dr2.dot(t) + r2.dot(dt), dbeta = dr2.dot(b2) + r2.dot(db2);
  return (dalpha - beta * k * S) * tb + (dbeta + alpha * k * S) * jtb;
}

double CylinderCatenaryCrease::developedCurvature(double u) const {
  const double S = 1.0 / std::cosh(k_ * u);
  return k_ * S * S;
}

double CylinderCatenaryCrease::regressionParameter(int sheet, double u) const {
  requireSheet(sheet, "regressionParameter");
  const Vec3 dr = ruling(sheet, u, 1);
  const double rr = dr.squaredNorm();
  if (rr == 0.0) return std::numeric_limits<double>::infinity();
  return -crease(u, 1).dot(dr) / rr;
}

FoldSamples CylinderCatenaryCrease::sample(int n) const {
  if (n < 2) throw std::invalid_argument("CylinderCatenaryCrease::sample: need n >= 2");
  FoldSamples f;
  f.u.resize(n);
  f.crease.resize(n, 3);
  f.creaseD1.resize(n, 3);
  f.creaseD2.resize(n, 3);
  for (auto& s : f.sheet) {
    s.crease.resize(n, 3);
    s.rulingEnd.resize(n, 3);
    s.devCrease.resize(n, 2);
    s.devRulingEnd.resize(n, 2);
    s.dCrease.resize(n, 3);
    s.dRulingEnd.resize(n, 3);
    s.dDevCrease.resize(n, 2);
    s.dDevRulingEnd.resize(n, 2);
  }
  const double L = length_;
  for (int j = 0; j < n; ++j) {
    const double u = (j == n - 1) ? u1_ : u0_ + (u1_ - u0_) * static_cast<double>(j) / (n - 1);
    f.u(j) = u;
    const Vec3 c = crease(u, 0), dc = crease(u, 1);
    const Vec2 cb = developedCrease(u, 0), dcb = developedCrease(u, 1);
    f.crease.row(j) = c;
    f.creaseD1.row(j) = dc;
    f.creaseD2.row(j) = crease(u, 2);
    for (int i = 0; i < 2; ++i) {
      SheetSamples& s = f.sheet[i];
      s.crease.row(j) = c;
      s.rulingEnd.row(j) = c + L * ruling(i, u, 0);
      s.devCrease.row(j) = cb;
      s.devRulingEnd.row(j) = cb + L * developedRuling(i, u, 0);
      s.dCrease.row(j) = dc;
      s.dRulingEnd.row(j) = dc + L * ruling(i, u, 1);
      s.dDevCrease.row(j) = dcb;
      s.dDevRulingEnd.row(j) = dcb + L * developedRuling(i, u, 1);
    }
  }
  return f;
}

QuadMesh3 CylinderCatenaryCrease::sheetMesh(int sheet, int n) const {
  requireSheet(sheet, "sheetMesh");
  return surfaceMesh(sample(n).sheet[sheet]);
}

QuadMesh2 CylinderCatenaryCrease::developmentMesh(int sheet, int n) const {
  requireSheet(sheet, "developmentMesh");
  return creases::developmentMesh(sample(n).sheet[sheet]);
}

Eigen::MatrixX3d CylinderCatenaryCrease::creasePolyline(int n) const { return sample(n).crease; }

Eigen::MatrixX2d CylinderCatenaryCrease::developedCreasePolyline(int n) const {
  return sample(n).sheet[0].devCrease;
}

}  // namespace devsurf::creases
