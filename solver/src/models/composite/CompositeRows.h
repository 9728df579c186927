#pragma once

// Private to the composite model's sources: the parameters a composite edge is sampled at and rows
// picked from a linear map.

#include <vector>

#include <Eigen/SparseCore>

#include "devsurf/spline/Basis.h"
#include "devsurf/spline/KnotVector.h"

namespace devsurf::models::composite::detail {

/// [begin] + 3m−2 per span + [end] (000_… §2.1, plus both ends for ruling edges).
inline std::vector<double> evaluationParams(const spline::KnotVector& k) {
  std::vector<double> p;
  p.push_back(k.domainBegin());
  const std::vector<double> inner = k.spanSamples(3 * k.degree() - 2);
  p.insert(p.end(), inner.begin(), inner.end());
  p.push_back(k.domainEnd());
  return p;
}

/// Rows `rows` of a linear map, in that order.
inline spline::EvaluationMatrix selectRows(const spline::EvaluationMatrix& m, const std::vector<int>& rows) {
  std::vector<Eigen::Triplet<double>> t;
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (spline::EvaluationMatrix::InnerIterator it(m, rows[i]); it; ++it) t.emplace_back(static_cast<int>(i), it.col(), it.value());
  spline::EvaluationMatrix out(static_cast<Eigen::Index>(rows.size()), m.cols());
  out.setFromTriplets(t.begin(), t.end());
  out.makeCompressed();
  return out;
}

}  // namespace devsurf::models::composite::detail
