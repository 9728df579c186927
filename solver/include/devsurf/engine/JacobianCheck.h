#pragma once

#include <Eigen/Core>

#include "devsurf/engine/Term.h"

namespace devsurf::engine {

/// Result of comparing a term's analytic Jacobian with central finite differences.
struct JacobianCheckResult {
  double maxAbsoluteError = 0.0;   ///< max |J_analytic − J_fd| over all (row, variable)
  double maxRelativeError = 0.0;   ///< max of abs error / max(1, |J_fd|)
  int worstRow = -1;
  int worstVariable = -1;
  bool structureComplete = true;   ///< false if J_fd has a nonzero outside the declared structure
  double maxOutsideStructure = 0.0;
};

/// Compares the analytic Jacobian of `term` at x with central differences of its residuals
/// (step h per variable). linearizeAt(x) is called once first, so per-iteration constants are
/// held fixed as the solver holds them. Every term's test uses this.
JacobianCheckResult checkJacobian(Term& term, const Eigen::VectorXd& x, double h = 1e-6);

}  // namespace devsurf::engine
