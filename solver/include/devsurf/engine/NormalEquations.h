#pragma once

#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/LinearSolver.h"
#include "devsurf/engine/Problem.h"

namespace devsurf::engine {

/// The normal equations of one guided-projection step on a fixed sparsity pattern:
/// H = Σ_terms w_t² J_tᵀJ_t + ε_reg² I and g = Σ_terms w_t² J_tᵀ r_t over the free variables.
///
/// The constructor does all per-topology work (Tang et al. 2016 §3.2 on a fixed pattern):
/// collects every term's Jacobian structure, drops fixed variables, computes a fill-reducing
/// (AMD) ordering, builds the upper-triangular pattern of H in that order and a scatter map from
/// every pair of Jacobian entries that share a row to its slot in H. `assemble()` then only fills
/// numbers into preallocated storage.
class NormalEquations {
 public:
  explicit NormalEquations(const Problem& problem);

  /// Evaluates every term at x (after linearizeAt) and fills H and g.
  /// @param[in] termWeights  effective weight per term id (schedule applied)
  /// @param[in] regularization  ε_reg (Tikhonov, added to the diagonal as ε_reg²)
  /// @param[out] termResiduals  per term id: Σ (w r)² at x
  void assemble(Problem& problem, const std::vector<double>& termWeights, double regularization,
                std::vector<double>& termResiduals);

  /// Residual-only evaluation: per term id Σ (w r)² at x (no Jacobians, no linearizeAt).
  void residuals(const Problem& problem, const Eigen::VectorXd& x,
                 const std::vector<double>& termWeights, std::vector<double>& termResiduals);

  /// Upper triangle of H in the solver ordering.
  const SymmetricUpper& matrix() const { return H_; }
  /// −g in the solver ordering (the right-hand side of H δ = −g).
  const Eigen::VectorXd& rhs() const { return rhs_; }
  int numFree() const { return numFree_; }
  /// Number of stored (upper-triangular) nonzeros of H.
  long nonZeros() const { return static_cast<long>(H_.nonZeros()); }
  /// Adds the solution δ (solver ordering) to the free variables of x.
  void applyStep(const Eigen::VectorXd& delta, Eigen::VectorXd& x) const;
  /// Euclidean norm of a step in solver ordering (same as in variable ordering).

 private:
  struct TermPlan {
    int numResiduals = 0;
    int numEntries = 0;
    std::vector<int> rowStart;    ///< CSR over rows: entries of row r are order[rowStart[r]..rowStart[r+1])
    std::vector<int> order;       ///< entry ids grouped by row
    std::vector<int> column;      ///< per entry: permuted free column, −1 if fixed
    std::vector<int> pairSlot;    ///< per row, per free pair (a ≤ b in row order): slot in H values
  };

  std::vector<TermPlan> plans_;
  std::vector<int> freeIndex_;    ///< variable → permuted column or −1
  std::vector<int> diagonalSlot_; ///< column → slot of its diagonal entry
  std::vector<double> regularizationScale_;  ///< column → multiplier of ε_reg²
  int numFree_ = 0;
  SymmetricUpper H_;
  Eigen::VectorXd rhs_;
  // per-term scratch storage, allocated once
  std::vector<Eigen::VectorXd> residualBuffers_;
  std::vector<Eigen::VectorXd> jacobianBuffers_;
};

}  // namespace devsurf::engine
