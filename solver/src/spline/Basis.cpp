#include "devsurf/spline/Basis.h"

#include <algorithm>
#include <cassert>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/SparseCore>

namespace devsurf::spline {

namespace {

/// The NURBS Book A2.3 (DersBasisFuns) for span s: fills ders(k, j) = N^{(k)}_{s−p+j}(u) for
/// k ≤ min(derivatives, p); rows beyond the degree stay zero. `ders` is (derivatives+1)×(p+1).
/// Scratch lives on the stack up to kStackBasisDegree (the per-sample evaluations of a drag call
/// this hundreds of thousands of times per second), on the heap beyond.
void dersBasisFuns(int s, double u, int p, int derivatives, const std::vector<double>& t,
                   Eigen::Ref<Eigen::MatrixXd> ders) {
  assert(ders.rows() == derivatives + 1 && ders.cols() == p + 1 && "caller sizes the output");
  ders.setZero();
  constexpr int cap = kStackBasisDegree + 1;
  double stack[cap * cap + 4 * cap];
  std::vector<double> heap;
  double* scratch = stack;
  if (p + 1 > cap) {
    heap.resize(static_cast<std::size_t>((p + 1) * (p + 1) + 4 * (p + 1)));
    scratch = heap.data();
  }
  Eigen::Map<Eigen::MatrixXd> ndu(scratch, p + 1, p + 1);
  double* left = scratch + (p + 1) * (p + 1);
  double* right = left + (p + 1);
  Eigen::Map<Eigen::MatrixXd> a(right + (p + 1), 2, p + 1);
  ndu(0, 0) = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = u - t[s + 1 - j];
    right[j] = t[s + j] - u;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      ndu(j, r) = right[r + 1] + left[j - r];  // knot differences (lower triangle)
      assert(ndu(j, r) > 0.0 && "non-empty span gives positive knot differences");
      const double temp = ndu(r, j - 1) / ndu(j, r);
      ndu(r, j) = saved + right[r + 1] * temp;  // basis functions (upper triangle)
      saved = left[j - r] * temp;
    }
    ndu(j, j) = saved;
  }
  for (int j = 0; j <= p; ++j) ders(0, j) = ndu(j, p);

  const int nd = std::min(derivatives, p);
  if (nd == 0) return;
  for (int r = 0; r <= p; ++r) {
    int s1 = 0;
    int s2 = 1;
    a(0, 0) = 1.0;
    for (int k = 1; k <= nd; ++k) {
      double d = 0.0;
      const int rk = r - k;
      const int pk = p - k;
      if (r >= k) {
        a(s2, 0) = a(s1, 0) / ndu(pk + 1, rk);
        d = a(s2, 0) * ndu(rk, pk);
      }
      const int j1 = rk >= -1 ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? k - 1 : p - r;
      for (int j = j1; j <= j2; ++j) {
        a(s2, j) = (a(s1, j) - a(s1, j - 1)) / ndu(pk + 1, rk + j);
        d += a(s2, j) * ndu(rk + j, pk);
      }
      if (r <= pk) {
        a(s2, k) = -a(s1, k - 1) / ndu(pk + 1, r);
        d += a(s2, k) * ndu(r, pk);
      }
      ders(k, r) = d;
      std::swap(s1, s2);
    }
  }
  double factor = p;
  for (int k = 1; k <= nd; ++k) {
    ders.row(k) *= factor;
    factor *= (p - k);
  }
}

void requireUsable(const KnotVector& knots, const char* where) {
  if (knots.knots().empty() || knots.degree() < 1) {
    throw std::invalid_argument(std::string(where) +
                                ": knot vector is empty (default-constructed; use a factory)");
  }
}

}  // namespace

BasisValues basisFunctions(const KnotVector& knots, double u, int derivatives) {
  requireUsable(knots, "basisFunctions");
  if (derivatives < 0) {
    throw std::invalid_argument("basisFunctions: derivatives must be >= 0, got " +
                                std::to_string(derivatives));
  }
  const int p = knots.degree();
  BasisValues result;
  result.values.resize(derivatives + 1, p + 1);
  result.span = basisFunctionsInto(knots, u, derivatives, result.values);
  result.controlIndex.resize(static_cast<size_t>(p + 1));
  for (int j = 0; j <= p; ++j) {
    result.controlIndex[j] = knots.controlIndex(result.span - p + j);
  }
  return result;
}

int basisFunctionsInto(const KnotVector& knots, double u, int derivatives, Eigen::Ref<Eigen::MatrixXd> values) {
  requireUsable(knots, "basisFunctionsInto");
  const int p = knots.degree();
  if (derivatives < 0 || values.rows() != derivatives + 1 || values.cols() != p + 1) {
    throw std::invalid_argument("basisFunctionsInto: values must be (derivatives + 1) x (degree + 1) = " +
                                std::to_string(derivatives + 1) + " x " + std::to_string(p + 1) + ", got " +
                                std::to_string(values.rows()) + " x " + std::to_string(values.cols()));
  }
  const double uc = std::clamp(u, knots.domainBegin(), knots.domainEnd());
  const int span = knots.spanIndex(uc);
  dersBasisFuns(span, uc, p, derivatives, knots.knots(), values);
  return span;
}

EvaluationMatrix evaluationMatrix(const KnotVector& knots, const std::vector<double>& params,
                                  int derivative) {
  requireUsable(knots, "evaluationMatrix");
  if (derivative < 0) {
    throw std::invalid_argument("evaluationMatrix: derivative must be >= 0, got " +
                                std::to_string(derivative));
  }
  const int p = knots.degree();
  const int rows = static_cast<int>(params.size());
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(params.size() * static_cast<size_t>(p + 1));
  for (int k = 0; k < rows; ++k) {
    const BasisValues b = basisFunctions(knots, params[k], derivative);
    for (int j = 0; j <= p; ++j) {
      triplets.emplace_back(k, b.controlIndex[j], b.values(derivative, j));
    }
  }
  EvaluationMatrix m(rows, knots.numControlPoints());
  m.setFromTriplets(triplets.begin(), triplets.end());  // sums slots sharing a control point
  m.makeCompressed();
  return m;
}

EvaluationMatrix deBoorPointMatrix(const KnotVector& knots, double u, int level) {
  requireUsable(knots, "deBoorPointMatrix");
  const int p = knots.degree();
  if (level < 0 || level > p) {
    throw std::invalid_argument("deBoorPointMatrix: level must be in [0, degree = " +
                                std::to_string(p) + "], got " + std::to_string(level));
  }
  const std::vector<double>& t = knots.knots();
  const double uc = std::clamp(u, knots.domainBegin(), knots.domainEnd());
  const int s = knots.spanIndex(uc);
  // Row j holds d_j as coefficients over the slots s−p … s; start with d_j^{[0]} = P_{s−p+j}.
  Eigen::MatrixXd d = Eigen::MatrixXd::Identity(p + 1, p + 1);
  for (int k = 1; k <= p - level; ++k) {
    for (int j = p; j >= k; --j) {
      const double lo = t[s - p + j];
      const double hi = t[s + j - k + 1];
      assert(hi > lo && "de Boor denominators are positive on a non-empty span");
      const double alpha = (uc - lo) / (hi - lo);
      d.row(j) = (1.0 - alpha) * d.row(j - 1) + alpha * d.row(j);
    }
  }
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>((level + 1) * (p + 1)));
  for (int row = 0; row <= level; ++row) {
    for (int j = 0; j <= p; ++j) {
      const double c = d(p - level + row, j);
      if (c != 0.0) triplets.emplace_back(row, knots.controlIndex(s - p + j), c);
    }
  }
  EvaluationMatrix m(level + 1, knots.numControlPoints());
  m.setFromTriplets(triplets.begin(), triplets.end());
  m.makeCompressed();
  return m;
}

}  // namespace devsurf::spline
