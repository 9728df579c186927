// Degree elevation of a clamped B-spline curve (The NURBS Book A5.9, DegreeElevateCurve).
#include <algorithm>
#include <cassert>
#include <stdexcept>
#include <string>
#include <vector>

#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::spline {

BSplineCurve elevateDegree(const BSplineCurve& curve, int t) {
  curve.validate();
  if (curve.knots.kind() != KnotKind::Clamped) {
    throw std::invalid_argument("elevateDegree: only clamped curves are supported (periodic given)");
  }
  if (curve.isRational()) {
    throw std::invalid_argument("elevateDegree: only non-rational curves are supported");
  }
  if (t < 0) throw std::invalid_argument("elevateDegree: t must be >= 0, got " + std::to_string(t));
  if (t == 0) return curve;

  const std::vector<double>& U = curve.knots.knots();
  const Eigen::MatrixXd& Pw = curve.points;
  const Eigen::Index dim = Pw.cols();
  const int p = curve.degree();
  const int n = curve.knots.numControlPoints() - 1;  // last index
  const int m = n + p + 1;                            // last knot index
  const int ph = p + t;

  // bezalfs(i, j): coefficient of P_j in the i-th control point of the elevated Bézier segment.
  const Eigen::MatrixXd bezalfs = elevateBezierDegree(Eigen::MatrixXd::Identity(p + 1, p + 1), t);

  const int numBreaks = static_cast<int>(curve.knots.breakpoints().size());
  // Every distinct knot value gains t copies.
  const int numKnotsOut = m + 1 + numBreaks * t;
  const int numPointsOut = numKnotsOut - ph - 1;
  std::vector<double> Uh(static_cast<size_t>(numKnotsOut));
  Eigen::MatrixXd Qw(numPointsOut, dim);

  Eigen::MatrixXd bpts(p + 1, dim);
  Eigen::MatrixXd ebpts(ph + 1, dim);
  Eigen::MatrixXd nextbpts(std::max(p - 1, 1), dim);
  std::vector<double> alfs(static_cast<size_t>(std::max(p - 1, 1)));

  int mh = ph;
  int kind = ph + 1;
  int r = -1;
  int a = p;
  int b = p + 1;
  int cind = 1;
  double ua = U[0];
  Qw.row(0) = Pw.row(0);
  for (int i = 0; i <= ph; ++i) Uh[i] = ua;
  bpts = Pw.topRows(p + 1);

  while (b < m) {
    const int first0 = b;
    while (b < m && U[b] == U[b + 1]) ++b;
    const int mul = b - first0 + 1;
    mh += mul + t;
    const double ub = U[b];
    const int oldr = r;
    r = p - mul;
    const int lbz = oldr > 0 ? (oldr + 2) / 2 : 1;
    const int rbz = r > 0 ? ph - (r + 1) / 2 : ph;
    if (r > 0) {  // insert ub r times to get the Bézier segment [ua, ub]
      const double numer = ub - ua;
      for (int k = p; k > mul; --k) alfs[k - mul - 1] = numer / (U[a + k] - ua);
      for (int j = 1; j <= r; ++j) {
        const int save = r - j;
        const int s = mul + j;
        for (int k = p; k >= s; --k) {
          bpts.row(k) = alfs[k - s] * bpts.row(k) + (1.0 - alfs[k - s]) * bpts.row(k - 1);
        }
        nextbpts.row(save) = bpts.row(p);
      }
    }
    for (int i = lbz; i <= ph; ++i) {  // degree-elevate the Bézier segment
      ebpts.row(i).setZero();
      for (int j = std::max(0, i - t); j <= std::min(p, i); ++j) {
        ebpts.row(i) += bezalfs(i, j) * bpts.row(j);
      }
    }
    if (oldr > 1) {  // remove knot ua (oldr − 1 times) that was inserted for the last segment
      int first = kind - 2;
      int last = kind;
      const double den = ub - ua;
      const double bet = (ub - Uh[kind - 1]) / den;
      for (int tr = 1; tr < oldr; ++tr) {
        int i = first;
        int j = last;
        int kj = j - kind + 1;
        while (j - i > tr) {
          if (i < cind) {
            const double alf = (ub - Uh[i]) / (ua - Uh[i]);
            Qw.row(i) = alf * Qw.row(i) + (1.0 - alf) * Qw.row(i - 1);
          }
          if (j >= lbz) {
            if (j - tr <= kind - ph + oldr) {
              const double gam = (ub - Uh[j - tr]) / den;
              ebpts.row(kj) = gam * ebpts.row(kj) + (1.0 - gam) * ebpts.row(kj + 1);
            } else {
              ebpts.row(kj) = bet * ebpts.row(kj) + (1.0 - bet) * ebpts.row(kj + 1);
            }
          }
          ++i;
          --j;
          --kj;
        }
        --first;
        ++last;
      }
    }
    if (a != p) {  // load the knot ua
      for (int i = 0; i < ph - oldr; ++i) Uh[kind++] = ua;
    }
    for (int j = lbz; j <= rbz; ++j) Qw.row(cind++) = ebpts.row(j);
    if (b < m) {  // set up the next segment
      for (int j = 0; j < r; ++j) bpts.row(j) = nextbpts.row(j);
      for (int j = r; j <= p; ++j) bpts.row(j) = Pw.row(b - p + j);
      a = b;
      ++b;
      ua = ub;
    } else {  // end knot
      for (int i = 0; i <= ph; ++i) Uh[kind + i] = ub;
    }
  }
  const int nh = mh - ph - 1;  // last control point index
  assert(nh + 1 == numPointsOut && cind == numPointsOut && "A5.9 output size");
  assert(kind + ph + 1 == numKnotsOut && "A5.9 knot count");

  BSplineCurve out;
  out.knots = KnotVector::clamped(ph, std::move(Uh), nh + 1);
  out.points = std::move(Qw);
  return out;
}

}  // namespace devsurf::spline
