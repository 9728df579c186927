#pragma once

// Two faces on either side of a curved edge, as the crease and smooth-edge term tests build them.

#include <utility>
#include <vector>

#include <Eigen/SparseCore>

#include "devsurf/spline/Basis.h"
#include "devsurf/spline/KnotVector.h"
#include "devsurf/terms/LinearPoints.h"

namespace devsurf::testing {

/// `m` with its columns moved to start at `first`, in a map over `columns` points; `alias` maps a
/// column of m to a different target column (a control point two curves share).
inline spline::EvaluationMatrix placedColumns(const spline::EvaluationMatrix& m, int first, int columns,
                                              const std::vector<std::pair<int, int>>& alias = {}) {
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < m.rows(); ++k)
    for (spline::EvaluationMatrix::InnerIterator it(m, k); it; ++it) {
      int col = first + static_cast<int>(it.col());
      for (const auto& [from, to] : alias)
        if (it.col() == from) col = to;
      t.emplace_back(k, col, it.value());
    }
  spline::EvaluationMatrix out(m.rows(), columns);
  out.setFromTriplets(t.begin(), t.end());
  out.makeCompressed();
  return out;
}

/// An edge a (points 0–5), a crease or a smooth edge, between two faces whose other curves are b1
/// (points 6–11) and b2 (points 12–17): a′ and a″ at the parameters, across_i = b_i − a.
struct CurvedEdgeFixture {
  spline::KnotVector knots = spline::KnotVector::clampedUniform(3, 6);
  std::vector<double> params = knots.spanSamples(7);
  int K = static_cast<int>(params.size());
  terms::LinearPoints da{placedColumns(spline::evaluationMatrix(knots, params, 1), 0, 18), 0};
  terms::LinearPoints dda{placedColumns(spline::evaluationMatrix(knots, params, 2), 0, 18), 0};
  terms::LinearPoints across(int face, const std::vector<std::pair<int, int>>& alias = {}) const {
    const spline::EvaluationMatrix e = spline::evaluationMatrix(knots, params, 0);
    spline::EvaluationMatrix d = placedColumns(e, 6 * face, 18, alias) - placedColumns(e, 0, 18);
    d.makeCompressed();
    return {d, 0};
  }
  std::vector<double> ones() const { return std::vector<double>(static_cast<std::size_t>(K), 1.0); }
};

}  // namespace devsurf::testing
