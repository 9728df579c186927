#pragma once

#include <memory>
#include <string>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace devsurf::engine {

/// Column-major sparse matrix holding the upper triangle of a symmetric matrix.
using SymmetricUpper = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// Which sparse factorization solves the normal equations.
enum class LinearSolverKind {
  SimplicialLDLT,  ///< Eigen SimplicialLDLT (no extra dependency)
  Cholmod,         ///< SuiteSparse CHOLMOD (libsuitesparse-dev); supernodal or simplicial by
                   ///< CHOLMOD's own flop heuristic
  Auto,            ///< the models' default: SimplicialLDLT, unless ldltMultiplyAdds exceeds
                   ///< kAutoCholmodFlops: then CHOLMOD, supernodal, with its own (METIS/AMD)
                   ///< ordering (where compiled in)
};

/// Multiply-adds of an LDLᵀ factorization of `upper` in its given order, up to a constant:
/// Σ_j c_j² over the below-diagonal column counts c_j of L (symbolic only; nothing of L is
/// allocated).
double ldltMultiplyAdds(const SymmetricUpper& upper);

/// Auto's switch point (ldltMultiplyAdds). Measured on the composite sheets of
/// bench/composite_iteration: LDLT wins below ~1e9 (the presets, every strip), CHOLMOD
/// supernodal with METIS above it (sheet 40×40 with development: 7.4 s → 1.2 s per iteration).
inline constexpr double kAutoCholmodFlops = 1e9;

/// A symmetric positive (semi-)definite solver with a symbolic/numeric split: analyzePattern()
/// once per topology, factorize() once per iteration with the same pattern.
/// \note The matrix is already permuted by the assembler (fill-reducing ordering computed once),
///       so implementations use the natural ordering. It is the reduced matrix of
///       NormalEquations (eliminated variables removed).
/// \note factorize() and solve() are called inside the iteration loop and should not allocate.
class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  virtual std::string name() const = 0;
  /// Symbolic analysis of the upper-triangular pattern.
  virtual void analyzePattern(const SymmetricUpper& matrix) = 0;
  /// Numeric factorization; false if the matrix is not positive definite (numerically).
  virtual bool factorize(const SymmetricUpper& matrix) = 0;
  /// Solves with the last factorization; `solution` is preallocated to the same size as rhs.
  virtual void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) = 0;
};

/// @throws std::invalid_argument if the kind was not compiled in.
std::unique_ptr<LinearSolver> makeLinearSolver(LinearSolverKind kind);

/// "auto" / "ldlt" / "cholmod".
LinearSolverKind linearSolverKindFromName(const std::string& name);
bool cholmodAvailable();

}  // namespace devsurf::engine
