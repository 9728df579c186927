#include "devsurf/creases/PlanarFold.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace devsurf::creases {

namespace {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;

Vec3 normalizedRuling(const Vec3& d, const char* who) {
  const double len = d.norm();
  if (!(len > 0.0) || !std::isfinite(len))
    throw std::invalid_argument(std::string(who) + ": ruling direction must be a finite nonzero vector");
  const Vec3 u = d / len;
  if (std::abs(u.z()) < 1e-9)
    throw std::invalid_argument(std::string(who) +
                                ": ruling direction must not lie in the crease plane z = 0");
  return u;
}

// Gauss–Kronrod 7–15 on [a, b]: returns the Kronrod estimate, err = |K15 − G7|.
template <class F>
double gk15(const F& f, double a, double b, double& err) {
  static const double xk[8] = {0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
                               0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
                               0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                               0.207784955007898467600689403773245, 0.0};
  static const double wk[8] = {0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                               0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                               0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                               0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
  static const double wg[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                               0.381830050505118944950369775488975, 0.417959183673469387755102040816327};
  const double c = 0.5 * (a + b), h = 0.5 * (b - a);
  const double fc = f(c);
  double k = wk[7] * fc, g = wg[3] * fc;
  for (int j = 0; j < 7; ++j) {
    const double f1 = f(c - h * xk[j]), f2 = f(c + h * xk[j]);
    k += wk[j] * (f1 + f2);
    if (j % 2 == 1) g += wg[j / 2] * (f1 + f2);
  }
  err = std::abs((k - g) * h);
  return k * h;
}

template <class F>
double integrate(const F& f, double a, double b, double tol, int depth = 0) {
  double err = 0.0;
  const double whole = gk15(f, a, b, err);
  if (err <= tol || depth >= 16) return whole;  // bounded work on non-smooth integrands
  const double m = 0.5 * (a + b);
  return integrate(f, a, m, 0.5 * tol, depth + 1) + integrate(f, m, b, 0.5 * tol, depth + 1);
}

void allocate(FoldSamples& f, int n, bool derivatives) {
  f.u.resize(n);
  f.crease.resize(n, 3);
  f.creaseD1.resize(derivatives ? n : 0, 3);
  f.creaseD2.resize(derivatives ? n : 0, 3);
  for (auto& s : f.sheet) {
    s.crease.resize(n, 3);
    s.rulingEnd.resize(n, 3);
    s.devCrease.resize(n, 2);
    s.devRulingEnd.resize(n, 2);
    const int m = derivatives ? n : 0;
    s.dCrease.resize(m, 3);
    s.dRulingEnd.resize(m, 3);
    s.dDevCrease.resize(m, 2);
    s.dDevRulingEnd.resize(m, 2);
  }
}

// Fills the positions of both sheets from c(u_j) and c̄(u_j).
void fillPositions(FoldSamples& f, int j, const Vec3& c, const Vec2& cb, const Vec3& d1,
                   const Vec3& d2, double L) {
  f.crease.row(j) = c;
  const Vec3 dir[2] = {d1, d2};
  const Vec2 ddir[2] = {Vec2(0.0, 1.0), Vec2(0.0, -1.0)};
  for (int i = 0; i < 2; ++i) {
    SheetSamples& s = f.sheet[i];
    s.crease.row(j) = c;
    s.rulingEnd.row(j) = c + L * dir[i];
    s.devCrease.row(j) = cb;
    s.devRulingEnd.row(j) = cb + L * ddir[i];
  }
}

}  // namespace

QuadMesh3 PlanarFold::sheetMesh(int sheet) const {
  if (sheet != 0 && sheet != 1) throw std::invalid_argument("PlanarFold::sheetMesh: sheet must be 0 or 1");
  return surfaceMesh(samples.sheet[sheet]);
}

QuadMesh2 PlanarFold::developmentMesh(int sheet) const {
  if (sheet != 0 && sheet != 1)
    throw std::invalid_argument("PlanarFold::developmentMesh: sheet must be 0 or 1");
  return creases::developmentMesh(samples.sheet[sheet]);
}

PlanarFold planarFoldByReflection(const PlanarCurve& curve, const Vec3& rulingDirection,
                                  double rulingLength, int n) {
  const char* who = "planarFoldByReflection";
  if (!curve.evaluate) throw std::invalid_argument(std::string(who) + ": empty curve");
  if (!(curve.u0 < curve.u1)) throw std::invalid_argument(std::string(who) + ": need u0 < u1");
  if (n < 2) throw std::invalid_argument(std::string(who) + ": need n >= 2 samples");
  if (!(rulingLength > 0.0)) throw std::invalid_argument(std::string(who) + ": rulingLength must be positive");
  PlanarFold fold;
  const Vec3 d = normalizedRuling(rulingDirection, who);
  fold.rulingFirst = d;
  fold.rulingSecond = Vec3(-d.x(), -d.y(), d.z());
  fold.rulingLength = rulingLength;
  const Vec2 dh(d.x(), d.y());
  // s′(u) = |γ′ − (γ′·d) d| (orthogonal section of the cylinder).
  auto speed = [&](double u) {
    const Vec2 g1 = curve.evaluate(u, 1);
    const double along = g1.dot(dh);
    return std::sqrt(std::max(0.0, g1.squaredNorm() - along * along));
  };
  FoldSamples& f = fold.samples;
  allocate(f, n, true);
  double s = 0.0, uPrev = curve.u0;
  for (int j = 0; j < n; ++j) {
    const double u =
        (j == n - 1) ? curve.u1 : curve.u0 + (curve.u1 - curve.u0) * static_cast<double>(j) / (n - 1);
    if (j > 0) {
      double err = 0.0;
      const double rough = gk15(speed, uPrev, u, err);
      s += integrate(speed, uPrev, u, 1e-15 * std::abs(rough) + 1e-300);
    }
    uPrev = u;
    f.u(j) = u;
    const Vec2 g = curve.evaluate(u, 0), g1 = curve.evaluate(u, 1), g2 = curve.evaluate(u, 2);
    const Vec3 c(g.x(), g.y(), 0.0), dc(g1.x(), g1.y(), 0.0), ddc(g2.x(), g2.y(), 0.0);
    const Vec2 cb(s, g.dot(dh)), dcb(speed(u), g1.dot(dh));
    fillPositions(f, j, c, cb, fold.rulingFirst, fold.rulingSecond, rulingLength);
    f.creaseD1.row(j) = dc;
    f.creaseD2.row(j) = ddc;
    for (auto& sh : f.sheet) {  // the rulings are constant: r′ = 0
      sh.dCrease.row(j) = dc;
      sh.dRulingEnd.row(j) = dc;
      sh.dDevCrease.row(j) = dcb;
      sh.dDevRulingEnd.row(j) = dcb;
    }
  }
  return fold;
}

PlanarFold planarFoldByReflection(const Eigen::MatrixX2d& polyline, const Vec3& rulingDirection,
                                  double rulingLength) {
  const char* who = "planarFoldByReflection";
  const int n = static_cast<int>(polyline.rows());
  if (n < 2) throw std::invalid_argument(std::string(who) + ": need at least 2 polyline points");
  if (!(rulingLength > 0.0)) throw std::invalid_argument(std::string(who) + ": rulingLength must be positive");
  PlanarFold fold;
  const Vec3 d = normalizedRuling(rulingDirection, who);
  fold.rulingFirst = d;
  fold.rulingSecond = Vec3(-d.x(), -d.y(), d.z());
  fold.rulingLength = rulingLength;
  const Vec2 dh(d.x(), d.y());
  FoldSamples& f = fold.samples;
  allocate(f, n, false);
  double s = 0.0;
  for (int j = 0; j < n; ++j) {
    const Vec2 g = polyline.row(j);
    if (j > 0) {
      const Vec2 e = g - Vec2(polyline.row(j - 1));
      if (!(e.norm() > 0.0))
        throw std::invalid_argument(std::string(who) + ": repeated polyline point " + std::to_string(j));
      // Orthogonal section edge e − (e·d) d, of squared length |e|² − (e·d)².
      const double along = e.dot(dh);
      s += std::sqrt(std::max(0.0, e.squaredNorm() - along * along));
    }
    f.u(j) = j;
    fillPositions(f, j, Vec3(g.x(), g.y(), 0.0), Vec2(s, g.dot(dh)), fold.rulingFirst,
                  fold.rulingSecond, rulingLength);
  }
  return fold;
}

}  // namespace devsurf::creases
