#pragma once

// Shared helpers of the term tests: random points, the finite-difference Jacobian assertion every
// term's test uses, the no-duplicate-entry rule of the assembler, residual evaluation.

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/JacobianCheck.h"
#include "devsurf/engine/Term.h"

namespace devsurf::testing {

/// n uniform values in [−1, 1], reproducible by seed.
inline Eigen::VectorXd randomVector(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  Eigen::VectorXd x(n);
  for (int i = 0; i < n; ++i) x[i] = uni(rng);
  return x;
}

/// The analytic Jacobian agrees with central differences and declares every nonzero.
inline void expectJacobianMatches(engine::Term& term, const Eigen::VectorXd& x) {
  const engine::JacobianCheckResult r = engine::checkJacobian(term, x, 1e-6);
  EXPECT_LT(r.maxRelativeError, 1e-7) << term.name() << ": worst row " << r.worstRow
                                      << ", variable " << r.worstVariable;
  EXPECT_TRUE(r.structureComplete) << term.name() << ": derivative outside the structure "
                                   << r.maxOutsideStructure;
}

/// No (row, variable) pair is listed twice (the assembler's rule).
inline void expectNoDuplicateEntries(const engine::Term& term) {
  std::vector<engine::JacobianEntry> entries;
  term.jacobianStructure(entries);
  std::vector<std::pair<int, int>> keys;
  for (const auto& e : entries) keys.emplace_back(e.row, e.variable);
  std::sort(keys.begin(), keys.end());
  EXPECT_EQ(std::adjacent_find(keys.begin(), keys.end()), keys.end()) << term.name();
}

/// Residuals at x after linearizing there.
inline Eigen::VectorXd residuals(engine::Term& term, const Eigen::VectorXd& x) {
  term.linearizeAt(x);
  Eigen::VectorXd r(term.numResiduals());
  term.evaluate(x, r.data(), nullptr);
  return r;
}

}  // namespace devsurf::testing
