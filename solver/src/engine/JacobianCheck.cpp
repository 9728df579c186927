#include "devsurf/engine/JacobianCheck.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

namespace devsurf::engine {

JacobianCheckResult checkJacobian(Term& term, const Eigen::VectorXd& x, double h) {
  term.linearizeAt(x);
  const int rows = term.numResiduals();
  std::vector<JacobianEntry> entries;
  term.jacobianStructure(entries);

  Eigen::VectorXd r(rows);
  std::vector<double> values(entries.size());
  term.evaluate(x, r.data(), values.data());

  // Analytic Jacobian as a map (row, variable) → value; duplicates are summed.
  std::map<std::pair<int, int>, double> analytic;
  for (std::size_t e = 0; e < entries.size(); ++e)
    analytic[{entries[e].row, entries[e].variable}] += values[e];

  JacobianCheckResult result;
  Eigen::VectorXd xp = x, rp(rows), rm(rows);
  for (Eigen::Index v = 0; v < x.size(); ++v) {
    xp[v] = x[v] + h;
    term.evaluate(xp, rp.data(), nullptr);
    xp[v] = x[v] - h;
    term.evaluate(xp, rm.data(), nullptr);
    xp[v] = x[v];
    for (int row = 0; row < rows; ++row) {
      const double fd = (rp[row] - rm[row]) / (2.0 * h);
      const auto it = analytic.find({row, static_cast<int>(v)});
      const double an = it == analytic.end() ? 0.0 : it->second;
      const double err = std::abs(an - fd);
      if (it == analytic.end() && std::abs(fd) > 0.0) {
        result.maxOutsideStructure = std::max(result.maxOutsideStructure, std::abs(fd));
        if (std::abs(fd) > 1e-7) result.structureComplete = false;
      }
      const double rel = err / std::max(1.0, std::abs(fd));
      if (rel > result.maxRelativeError || !std::isfinite(rel)) {
        result.maxRelativeError = rel;
        result.worstRow = row;
        result.worstVariable = static_cast<int>(v);
      }
      result.maxAbsoluteError = std::max(result.maxAbsoluteError, err);
    }
  }
  return result;
}

}  // namespace devsurf::engine
