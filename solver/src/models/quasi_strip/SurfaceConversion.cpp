#include "devsurf/models/quasi_strip/SurfaceConversion.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace devsurf::models::quasi_strip {

namespace {

void requirePolynomialClamped(const spline::BSplineCurve& c, const std::string& name) {
  c.validate();
  if (c.isRational()) throw std::invalid_argument(name + ".weights: rational curves are not supported");
  if (c.knots.kind() != spline::KnotKind::Clamped) {
    throw std::invalid_argument(name + ".knots: only clamped (open) curves are supported");
  }
}

/// Index of the Bézier piece containing u (first/last piece outside the domain).
int pieceIndex(const std::vector<spline::BezierPiece>& pieces, double u) {
  int j = 0;
  while (j + 1 < static_cast<int>(pieces.size()) && u >= pieces[j].end) ++j;
  return j;
}

/// The Bézier control points of `piece`'s polynomial on [a, b] (extrapolating if outside).
Eigen::MatrixXd restrictPiece(const spline::BezierPiece& piece, double a, double b) {
  Eigen::VectorXd phi(2);
  const double length = piece.end - piece.begin;
  phi << (a - piece.begin) / length, (b - piece.begin) / length;
  return spline::composeBezier(piece.points, phi);
}

/// A clamped B-spline assembled from consecutive Bézier pieces of one degree.
spline::BSplineCurve curveFromPieces(const std::vector<spline::BezierPiece>& pieces) {
  const int p = static_cast<int>(pieces.front().points.rows()) - 1;
  const int dim = static_cast<int>(pieces.front().points.cols());
  const int count = static_cast<int>(pieces.size());
  Eigen::MatrixXd points(count * p + 1, dim);
  std::vector<double> knots(static_cast<size_t>(p + 1), pieces.front().begin);
  for (int j = 0; j < count; ++j) {
    points.middleRows(j * p, p + 1) = pieces[j].points;  // shared end points: later piece wins
    for (int r = 0; r < (j + 1 < count ? p : p + 1); ++r) knots.push_back(pieces[j].end);
  }
  spline::BSplineCurve c;
  c.knots = spline::KnotVector::clamped(p, knots, count * p + 1);
  c.points = points;
  return c;
}

}  // namespace

spline::BSplineCurve RuledBSplineSurface::boundary(int side) const {
  spline::BSplineCurve c;
  c.knots = spline::KnotVector::clamped(degree, knots, static_cast<int>(side0.rows()));
  c.points = side == 0 ? Eigen::MatrixXd(side0) : Eigen::MatrixXd(side1);
  return c;
}

Eigen::Vector3d RuledBSplineSurface::evaluate(double s, double t) const {
  const spline::KnotVector kv = spline::KnotVector::clamped(degree, knots, static_cast<int>(side0.rows()));
  const spline::BasisValues b = spline::basisFunctions(kv, t, 0);
  Eigen::Vector3d p0 = Eigen::Vector3d::Zero(), p1 = Eigen::Vector3d::Zero();
  for (int j = 0; j <= degree; ++j) {
    p0 += b.values(0, j) * side0.row(b.controlIndex[j]).transpose();
    p1 += b.values(0, j) * side1.row(b.controlIndex[j]).transpose();
  }
  return (1.0 - s) * p0 + s * p1;
}

std::pair<spline::BSplineCurve, spline::BSplineCurve> makeCompatible(const spline::BSplineCurve& c1,
                                                                     const spline::BSplineCurve& c2) {
  requirePolynomialClamped(c1, "c1");
  requirePolynomialClamped(c2, "c2");
  const double len = c1.knots.domainEnd() - c1.knots.domainBegin();
  const double tol = 1e-12 * len;
  if (std::abs(c1.knots.domainBegin() - c2.knots.domainBegin()) > tol ||
      std::abs(c1.knots.domainEnd() - c2.knots.domainEnd()) > tol) {
    throw std::invalid_argument("c2.knots: the parameter domain differs from c1's");
  }
  const int p = std::max(c1.degree(), c2.degree());
  spline::BSplineCurve a = c1.degree() < p ? spline::elevateDegree(c1, p - c1.degree()) : c1;
  spline::BSplineCurve b = c2.degree() < p ? spline::elevateDegree(c2, p - c2.degree()) : c2;
  // Snap b's domain ends onto a's so that the knot vectors can be equal.
  auto missing = [tol](const spline::BSplineCurve& from, const spline::BSplineCurve& into) {
    std::vector<double> inserts;
    for (double u : from.knots.breakpoints()) {
      if (u <= into.knots.domainBegin() + tol || u >= into.knots.domainEnd() - tol) continue;
      int mInto = 0, mFrom = 0;
      for (double k : into.knots.knots()) mInto += std::abs(k - u) <= tol;
      for (double k : from.knots.knots()) mFrom += std::abs(k - u) <= tol;
      // Insert at the value `into` already has when it is within tol.
      double value = u;
      for (double k : into.knots.knots()) if (std::abs(k - u) <= tol) value = k;
      for (int r = mInto; r < mFrom; ++r) inserts.push_back(value);
    }
    std::sort(inserts.begin(), inserts.end());
    return inserts;
  };
  const std::vector<double> intoA = missing(b, a), intoB = missing(a, b);
  if (!intoA.empty()) a = spline::refineKnots(a, intoA);
  if (!intoB.empty()) b = spline::refineKnots(b, intoB);
  // Same multiplicities now; make the values bit-identical.
  if (a.knots.knots().size() == b.knots.knots().size()) {
    b.knots = spline::KnotVector::clamped(p, a.knots.knots(), a.knots.numControlPoints());
  }
  return {a, b};
}

spline::BSplineCurve extendCurve(const spline::BSplineCurve& curve, double beginLength,
                                 double endLength) {
  requirePolynomialClamped(curve, "curve");
  if (beginLength < 0.0 || endLength < 0.0) {
    throw std::invalid_argument("extendCurve: extension lengths must be >= 0");
  }
  if (beginLength == 0.0 && endLength == 0.0) return curve;
  std::vector<spline::BezierPiece> pieces = spline::bezierPieces(curve);
  spline::BezierPiece& first = pieces.front();
  const double newBegin = first.begin - beginLength;
  {
    const double end = first.end;
    first.points = restrictPiece(first, newBegin, end);
    first.begin = newBegin;
  }
  spline::BezierPiece& last = pieces.back();
  const double newEnd = last.end + endLength;
  last.points = restrictPiece(last, last.begin, newEnd);
  last.end = newEnd;
  return curveFromPieces(pieces);
}

spline::BSplineCurve reparametrizeToUnit(const spline::BSplineCurve& curve) {
  const double a = curve.knots.domainBegin(), b = curve.knots.domainEnd();
  std::vector<double> knots = curve.knots.knots();
  for (double& k : knots) k = (k - a) / (b - a);
  knots.front() = 0.0;
  knots.back() = 1.0;
  for (int i = 0; i <= curve.degree(); ++i) {
    knots[i] = 0.0;
    knots[knots.size() - 1 - i] = 1.0;
  }
  spline::BSplineCurve c = curve;
  c.knots = spline::KnotVector::clamped(curve.degree(), knots, curve.knots.numControlPoints());
  return c;
}

RuledBSplineSurface convertRuledSurface(const spline::BSplineCurve& c1, const spline::BSplineCurve& c2,
                                        const Mapping& sigma, double tBegin, double tEnd) {
  requirePolynomialClamped(c1, "c1");
  requirePolynomialClamped(c2, "c2");
  if (c1.dimension() != 3 || c2.dimension() != 3) {
    throw std::invalid_argument("convertRuledSurface: curves must be 3D");
  }
  if (!(tBegin < tEnd)) throw std::invalid_argument("convertRuledSurface: tBegin must be < tEnd");
  const spline::BSplineCurve sigmaCurve = sigma.curve();
  const std::vector<spline::BezierPiece> sigmaPieces = spline::bezierPieces(sigmaCurve);
  const std::vector<spline::BezierPiece> c1Pieces = spline::bezierPieces(c1);
  const std::vector<spline::BezierPiece> c2Pieces = spline::bezierPieces(c2);
  const int d = sigma.degree, p1 = c1.degree(), p2 = c2.degree();
  const int degree = std::max(p1, p2 * d);

  // Step 1: the breakpoints in t.
  std::vector<double> breaks = {tBegin, tEnd};
  auto inside = [tBegin, tEnd](double u) { return u > tBegin && u < tEnd; };
  for (double u : sigmaCurve.knots.breakpoints()) if (inside(u)) breaks.push_back(u);
  for (double u : c1.knots.breakpoints()) if (inside(u)) breaks.push_back(u);
  const double sBegin = sigma.evaluate(tBegin), sEnd = sigma.evaluate(tEnd);
  for (double T : c2.knots.breakpoints()) {
    if (T > sBegin && T < sEnd) {
      const double u = sigma.inverse(T);
      if (inside(u)) breaks.push_back(u);
    }
  }
  std::sort(breaks.begin(), breaks.end());
  const double tol = 1e-12 * (tEnd - tBegin);
  std::vector<double> unique = {breaks.front()};
  for (double u : breaks) {
    if (u - unique.back() > tol) unique.push_back(u);
  }
  unique.back() = tEnd;
  if (unique.size() < 2) unique = {tBegin, tEnd};

  // Steps 2–5, one Bézier surface per interval.
  const int pieces = static_cast<int>(unique.size()) - 1;
  RuledBSplineSurface surface;
  surface.degree = degree;
  surface.side0.resize(pieces * degree + 1, 3);
  surface.side1.resize(pieces * degree + 1, 3);
  surface.knots.assign(static_cast<size_t>(degree + 1), tBegin);
  for (int j = 0; j < pieces; ++j) {
    const double a = unique[j], b = unique[j + 1], mid = 0.5 * (a + b);
    const Eigen::MatrixXd sigmaHat =
        restrictPiece(sigmaPieces[pieceIndex(sigmaPieces, mid)], a, b);  // (d+1)×1
    Eigen::MatrixXd p0 = restrictPiece(c1Pieces[pieceIndex(c1Pieces, mid)], a, b);
    if (p1 < degree) p0 = spline::elevateBezierDegree(p0, degree - p1);
    const spline::BezierPiece& q = c2Pieces[pieceIndex(c2Pieces, sigma.evaluate(mid))];
    const Eigen::VectorXd phi =
        (sigmaHat.col(0).array() - q.begin) / (q.end - q.begin);  // eq. 13 in q's local parameter
    Eigen::MatrixXd p1Side = spline::composeBezier(q.points, phi);
    if (p2 * d < degree) p1Side = spline::elevateBezierDegree(p1Side, degree - p2 * d);
    surface.side0.middleRows(j * degree, degree + 1) = p0;
    surface.side1.middleRows(j * degree, degree + 1) = p1Side;
    for (int r = 0; r < (j + 1 < pieces ? degree : degree + 1); ++r) surface.knots.push_back(b);
  }
  return surface;
}

}  // namespace devsurf::models::quasi_strip
