#include "devsurf/models/conical_strip/ConicalPatch.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/Geometry>

#include "devsurf/metrics/StripQuality.h"
#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::models::conical_strip {

namespace {

constexpr double kGauss8Nodes[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                    -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                    0.7966664774136267,  0.9602898564975363};
constexpr double kGauss8Weights[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                                      0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                                      0.2223810344533745, 0.1012285362903763};
constexpr double kGauss4Nodes[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                                    0.8611363115940526};
constexpr double kGauss4Weights[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                                      0.3478548451374538};

Eigen::Vector3d bezierPoint(const Eigen::MatrixX3d& points, double u) {
  return spline::evaluateBezier(points, u);
}

Eigen::Vector3d bezierDerivative(const Eigen::MatrixX3d& points, double u) {
  const int p = static_cast<int>(points.rows()) - 1;
  if (p < 1) return Eigen::Vector3d::Zero();
  const Eigen::MatrixX3d hodograph =
      p * (points.bottomRows(p) - points.topRows(p));
  return spline::evaluateBezier(hodograph, u);
}

}  // namespace

const char* stripSideName(StripSide side) { return side == StripSide::P ? "P" : "Q"; }

const char* patchTypeName(PatchType type) {
  return type == PatchType::Triangular ? "triangular" : "quadrilateral";
}

Eigen::Vector3d ConicalPatch::pointA(double u) const { return bezierPoint(a, u); }
Eigen::Vector3d ConicalPatch::pointB(double u) const { return bezierPoint(b, u); }
Eigen::Vector3d ConicalPatch::derivativeA(double u) const { return bezierDerivative(a, u); }
Eigen::Vector3d ConicalPatch::derivativeB(double u) const { return bezierDerivative(b, u); }

Eigen::Vector3d ConicalPatch::normal(double u) const {
  const Eigen::Vector3d n =
      (0.5 * (derivativeA(u) + derivativeB(u))).cross(pointB(u) - pointA(u));
  const double len = n.norm();
  return len > 0.0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
}

double ConicalPatch::area() const {
  double total = 0.0;
  constexpr int kSub = 4;
  for (int s = 0; s < kSub; ++s) {
    const double u0 = static_cast<double>(s) / kSub, h = 0.5 / kSub;
    for (int i = 0; i < 8; ++i) {
      const double u = u0 + h * (1.0 + kGauss8Nodes[i]);
      const Eigen::Vector3d pa = pointA(u), pb = pointB(u), da = derivativeA(u),
                            db = derivativeB(u);
      const Eigen::Vector3d ruling = pb - pa;
      double inner = 0.0;
      for (int j = 0; j < 4; ++j) {
        const double v = 0.5 * (1.0 + kGauss4Nodes[j]);
        inner += 0.5 * kGauss4Weights[j] * ((1.0 - v) * da + v * db).cross(ruling).norm();
      }
      total += h * kGauss8Weights[i] * inner;
    }
  }
  return total;
}

double ConicalPatch::momentArm(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1) const {
  const Eigen::Vector3d axis = x1 - x0;
  const double len = axis.norm();
  assert(len > 0.0);
  const Eigen::Vector3d e = axis / len;
  double arm = 0.0;
  for (int k = 0; k <= 32; ++k) {
    const double u = k / 32.0;
    for (const Eigen::Vector3d& x : {pointA(u), pointB(u)}) {
      const Eigen::Vector3d r = x - x0;
      arm = std::max(arm, (r - r.dot(e) * e).norm());
    }
  }
  return arm;
}

void setConicalForm(ConicalPatch& patch, const Eigen::MatrixX3d& base,
                    const Eigen::Vector3d& scaledStart, double f) {
  const Eigen::Vector3d base0 = base.row(0).transpose();
  const Eigen::Vector3d offset = scaledStart - base0;
  Eigen::MatrixX3d scaled(base.rows(), 3);
  for (Eigen::Index k = 0; k < base.rows(); ++k) {
    const Eigen::Vector3d bk = base.row(k).transpose();
    scaled.row(k) = (bk + f * (base0 - bk) + offset).transpose();
  }
  scaled.row(0) = scaledStart.transpose();
  if (f == 1.0) scaled.rowwise() = scaledStart.transpose();  // triangle: the apex, bit-exactly
  patch.scale = f;
  patch.projectionPoint =
      f != 0.0 ? Eigen::Vector3d(base0 + offset / f)
               : Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  if (patch.baseSide == StripSide::P) {
    patch.a = base;
    patch.b = scaled;
  } else {
    patch.b = base;
    patch.a = scaled;
  }
}

double projectionResidual(const ConicalPatch& patch) {
  const Eigen::MatrixX3d& base = patch.base();
  const Eigen::MatrixX3d& scaled = patch.scaled();
  const double f = patch.scale;
  const Eigen::Vector3d& o = patch.projectionPoint;
  const Eigen::Vector3d c0 = (scaled.row(0) - base.row(0)).transpose();
  double worst = 0.0;
  for (Eigen::Index k = 0; k < base.rows(); ++k) {
    const Eigen::Vector3d bk = base.row(k).transpose();
    const Eigen::Vector3d ck = scaled.row(k).transpose() - bk;
    const Eigen::Vector3d defect = f != 0.0 ? Eigen::Vector3d(ck - f * (o - bk)) : Eigen::Vector3d(ck - c0);
    const double scale = ck.norm();
    if (scale > 0.0) worst = std::max(worst, defect.norm() / scale);
  }
  return worst;
}

double coplanarityResidual(const ConicalPatch& patch, int samples) {
  double worst = 0.0;
  for (int k = 0; k < samples; ++k) {
    const double u = samples > 1 ? static_cast<double>(k) / (samples - 1) : 0.5;
    worst = std::max(worst, metrics::developabilityResidual(patch.pointA(u), patch.derivativeA(u),
                                                            patch.pointB(u), patch.derivativeB(u)));
  }
  return worst;
}

ConicalPatch elevateDegree(const ConicalPatch& patch) {
  ConicalPatch out = patch;
  out.a = spline::elevateBezierDegree(patch.a, 1);
  out.b = spline::elevateBezierDegree(patch.b, 1);
  return out;
}

Eigen::Vector3d quadraticMiddleControl(const Eigen::Vector3d& e0, const Eigen::Vector3d& t0,
                                       const Eigen::Vector3d& e1, const Eigen::Vector3d& t1,
                                       const Eigen::Vector3d& middle) {
  const Eigen::Vector3d chord = e1 - e0;
  const double chordLength = chord.norm();
  const Eigen::Vector3d fallback = 2.0 * middle - 0.5 * (e0 + e1);
  if (!(chordLength > 0.0)) return fallback;
  // Closest points of the lines e0 + α t0 and e1 − β t1.
  const auto intersect = [&chord, chordLength, &fallback, &e0](const Eigen::Vector3d& d0,
                                                                const Eigen::Vector3d& d1,
                                                                bool requireMeeting) {
    const double aa = d0.dot(d0), bb = d0.dot(d1), cc = d1.dot(d1);
    const double den = aa * cc - bb * bb;
    if (!(den > 1e-12 * aa * cc)) return std::pair<bool, Eigen::Vector3d>{false, fallback};
    // e0 + α d0 = e1 − β d1  ⇔  α d0 + β d1 = chord (least squares).
    const double r0 = d0.dot(chord), r1 = d1.dot(chord);
    const double alpha = (cc * r0 - bb * r1) / den;
    const double beta = (aa * r1 - bb * r0) / den;
    const Eigen::Vector3d x0 = e0 + alpha * d0;
    const Eigen::Vector3d x1 = e0 + chord - beta * d1;
    const bool meets = (x0 - x1).norm() <= 1e-9 * chordLength;
    const bool ahead = alpha > 0.0 && beta > 0.0 && alpha * std::sqrt(aa) < chordLength &&
                       beta * std::sqrt(cc) < chordLength;
    if ((requireMeeting && !meets) || !ahead) {
      return std::pair<bool, Eigen::Vector3d>{false, fallback};
    }
    return std::pair<bool, Eigen::Vector3d>{true, Eigen::Vector3d(0.5 * (x0 + x1))};
  };
  const auto direct = intersect(t0, t1, true);
  if (direct.first) return direct.second;
  // Plane S through e0, e1 and the curve's middle point; project the tangents into it.
  Eigen::Vector3d n = chord.cross(middle - e0);
  if (!(n.norm() > 1e-12 * chordLength * chordLength)) return fallback;  // straight segment
  n.normalize();
  const Eigen::Vector3d p0 = t0 - t0.dot(n) * n, p1 = t1 - t1.dot(n) * n;
  return intersect(p0, p1, false).second;
}

}  // namespace devsurf::models::conical_strip
