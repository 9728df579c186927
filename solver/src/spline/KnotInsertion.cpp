// Knot insertion (A5.1), knot refinement and Bézier decomposition (A5.6).
#include <algorithm>
#include <cassert>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::spline {

namespace {

[[noreturn]] void failInsertion(const std::string& message) { throw std::invalid_argument(message); }

std::string formatKnot(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

/// Rows [w_i P_i, w_i] for rational curves, the points themselves otherwise.
Eigen::MatrixXd homogeneous(const BSplineCurve& c) {
  if (!c.isRational()) return c.points;
  Eigen::MatrixXd pw(c.points.rows(), c.points.cols() + 1);
  pw.leftCols(c.points.cols()) = c.points.array().colwise() * c.weights.array();
  pw.col(c.points.cols()) = c.weights;
  return pw;
}

/// Inverse of homogeneous(): splits into points and weights of `out` (which has knots set).
void fromHomogeneous(const Eigen::MatrixXd& pw, bool rational, BSplineCurve& out) {
  if (!rational) {
    out.points = pw;
    out.weights.resize(0);
    return;
  }
  const Eigen::Index dim = pw.cols() - 1;
  out.weights = pw.col(dim);
  out.points = pw.leftCols(dim).array().colwise() / out.weights.array();
}

void requireClamped(const BSplineCurve& c, const char* where) {
  if (c.knots.kind() != KnotKind::Clamped) {
    failInsertion(std::string(where) + ": only clamped curves are supported (periodic curve given)");
  }
}

}  // namespace

BSplineCurve insertKnot(const BSplineCurve& curve, double u, int times) {
  curve.validate();
  requireClamped(curve, "insertKnot");
  if (times < 0) failInsertion("insertKnot: times must be >= 0, got " + std::to_string(times));
  if (!std::isfinite(u)) failInsertion("insertKnot: u must be finite");
  const KnotVector& kv = curve.knots;
  const double a = kv.domainBegin();
  const double b = kv.domainEnd();
  if (u < a || u > b) {
    failInsertion("insertKnot: u = " + formatKnot(u) + " lies outside the domain [" + formatKnot(a) +
         ", " + formatKnot(b) + "]");
  }
  if (times == 0) return curve;

  const std::vector<double>& U = kv.knots();
  const int p = kv.degree();
  // Snap u onto an existing knot within the multiplicity tolerance (no near-duplicate knots).
  const double tol = 1e-14 * (b - a);
  for (double k : U) {
    if (std::abs(k - u) <= tol) {
      u = k;
      break;
    }
  }
  int s = 0;
  for (double k : U) s += (k == u) ? 1 : 0;
  if (s + times > p) {
    failInsertion("insertKnot: multiplicity of u = " + formatKnot(u) + " would become " +
         std::to_string(s + times) + ", more than the degree " + std::to_string(p));
  }

  const int k = kv.spanIndex(u);  // t_k ≤ u < t_{k+1} (u < b here since s < p+1 at the end)
  const int np = kv.numControlPoints() - 1;
  const int mp = np + p + 1;
  const int r = times;
  const Eigen::MatrixXd pw = homogeneous(curve);
  const Eigen::Index cols = pw.cols();

  std::vector<double> uq(static_cast<size_t>(mp + r + 1));
  for (int i = 0; i <= k; ++i) uq[i] = U[i];
  for (int i = 1; i <= r; ++i) uq[k + i] = u;
  for (int i = k + 1; i <= mp; ++i) uq[i + r] = U[i];

  Eigen::MatrixXd qw(np + r + 1, cols);
  for (int i = 0; i <= k - p; ++i) qw.row(i) = pw.row(i);
  for (int i = k - s; i <= np; ++i) qw.row(i + r) = pw.row(i);
  Eigen::MatrixXd rw(p - s + 1, cols);
  for (int i = 0; i <= p - s; ++i) rw.row(i) = pw.row(k - p + i);
  int L = k - p;
  for (int j = 1; j <= r; ++j) {
    L = k - p + j;
    for (int i = 0; i <= p - j - s; ++i) {
      const double alpha = (u - U[L + i]) / (U[i + k + 1] - U[L + i]);
      rw.row(i) = alpha * rw.row(i + 1) + (1.0 - alpha) * rw.row(i);
    }
    qw.row(L) = rw.row(0);
    qw.row(k + r - j - s) = rw.row(p - j - s);
  }
  for (int i = L + 1; i < k - s; ++i) qw.row(i) = rw.row(i - L);

  BSplineCurve out;
  out.knots = KnotVector::clamped(p, std::move(uq), np + r + 1);
  fromHomogeneous(qw, curve.isRational(), out);
  return out;
}

BSplineCurve refineKnots(const BSplineCurve& curve, const std::vector<double>& newKnots) {
  BSplineCurve result = curve;
  for (size_t i = 0; i < newKnots.size();) {
    size_t j = i + 1;
    while (j < newKnots.size() && newKnots[j] == newKnots[i]) ++j;
    result = insertKnot(result, newKnots[i], static_cast<int>(j - i));
    i = j;
  }
  return result;
}

std::vector<BezierPiece> bezierPieces(const BSplineCurve& curve) {
  curve.validate();
  requireClamped(curve, "bezierPieces");
  if (curve.isRational()) failInsertion("bezierPieces: only non-rational curves are supported");
  const KnotVector& kv = curve.knots;
  const std::vector<double>& U = kv.knots();
  const int p = kv.degree();
  const int m = static_cast<int>(U.size()) - 1;
  const Eigen::MatrixXd& P = curve.points;
  const std::vector<double> bp = kv.breakpoints();
  const int numPieces = static_cast<int>(bp.size()) - 1;

  // The NURBS Book A5.6 (DecomposeCurve).
  std::vector<BezierPiece> pieces(static_cast<size_t>(numPieces));
  for (auto& piece : pieces) piece.points.resize(p + 1, P.cols());
  std::vector<double> alphas(static_cast<size_t>(p));
  int a = p;
  int b = p + 1;
  int nb = 0;
  pieces[0].points = P.topRows(p + 1);
  while (b < m) {
    const int i = b;
    while (b < m && U[b + 1] == U[b]) ++b;
    const int mult = b - i + 1;
    if (mult < p) {
      const double numer = U[b] - U[a];
      for (int j = p; j > mult; --j) alphas[j - mult - 1] = numer / (U[a + j] - U[a]);
      const int r = p - mult;
      for (int j = 1; j <= r; ++j) {
        const int save = r - j;
        const int s = mult + j;
        Eigen::MatrixXd& Q = pieces[nb].points;
        for (int kk = p; kk >= s; --kk) {
          const double alpha = alphas[kk - s];
          Q.row(kk) = alpha * Q.row(kk) + (1.0 - alpha) * Q.row(kk - 1);
        }
        if (b < m) pieces[nb + 1].points.row(save) = Q.row(p);
      }
    }
    pieces[nb].begin = bp[nb];
    pieces[nb].end = bp[nb + 1];
    ++nb;
    if (b < m) {
      assert(nb < numPieces && "one piece per non-empty span");
      for (int j = p - mult; j <= p; ++j) pieces[nb].points.row(j) = P.row(b - p + j);
      a = b;
      ++b;
    }
  }
  assert(nb == numPieces && "one piece per non-empty span");
  return pieces;
}

BSplineCurve restrictToInterval(const BSplineCurve& curve, double u0, double u1) {
  curve.validate();
  requireClamped(curve, "restrictToInterval");
  const double begin = curve.knots.domainBegin(), end = curve.knots.domainEnd();
  if (!(std::isfinite(u0) && std::isfinite(u1) && begin <= u0 && u0 < u1 && u1 <= end))
    failInsertion("restrictToInterval: need " + formatKnot(begin) + " ≤ u0 < u1 ≤ " + formatKnot(end) + ", got [" +
                  formatKnot(u0) + ", " + formatKnot(u1) + "]");
  const int p = curve.degree();
  BSplineCurve c = curve;
  // At an end of the domain the knot is already there p + 1 times; inside, up to p makes a control
  // point the curve's point there.
  if (u0 > begin) c = insertKnot(c, u0, std::max(0, p - c.knots.multiplicity(u0)));
  if (u1 < end) c = insertKnot(c, u1, std::max(0, p - c.knots.multiplicity(u1)));
  const std::vector<double>& t = c.knots.knots();
  const auto below = [&t](double u) {  // knots strictly below u
    return static_cast<int>(std::lower_bound(t.begin(), t.end(), u) - t.begin());
  };
  const int first = u0 > begin ? below(u0) - 1 : 0;
  const int last = u1 < end ? below(u1) - 1 : c.knots.numControlPoints() - 1;
  std::vector<double> knots(static_cast<std::size_t>(p + 1), u0);
  for (const double k : t)
    if (k > u0 && k < u1) knots.push_back(k);
  knots.insert(knots.end(), static_cast<std::size_t>(p + 1), u1);
  const int count = last - first + 1;
  assert(count == static_cast<int>(knots.size()) - p - 1 && "the kept control points fit the kept knots");
  BSplineCurve out;
  out.knots = KnotVector::clamped(p, knots, count);
  out.points = c.points.middleRows(first, count);
  if (c.isRational()) out.weights = c.weights.segment(first, count);
  return out;
}

}  // namespace devsurf::spline
