#pragma once

#include <cstdint>
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

/// Auto's switch point (ldltMultiplyAdds), measured with bench/composite_iteration and strips of
/// 370–1500 spans, CHOLMOD on one thread. Below ~2e6 LDLT wins (small presets, sheet 4×10
/// without development: 1.1 vs 1.5 ms); from ~5e6 CHOLMOD supernodal with METIS wins on
/// composites (cylinder crease with development, 2.2e7: 12 → 7 ms; folded annulus, 2e7: 9 → 5 ms;
/// sheet 40×40 with development, 1.1e10: 7.4 s → 0.45 s). Banded strips are a wash (1500 spans,
/// 3.8e6: 13–18 ms either way), so they stay on LDLT up to ~2000 spans.
inline constexpr double kAutoCholmodFlops = 5e6;

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
/// Sets the BLAS up for the engine's threads (LinearSolver.cpp: BlasThreading): a threaded
/// OpenBLAS runs each call on the calling thread and its own worker threads are ended. Done on
/// the first CHOLMOD solver anyway; a program that blocks signals for its threads calls it
/// first thing in main(), since those workers started with the library, signals unblocked.
void prepareBlasForThreads();
/// Whether calls into the BLAS are made one thread at a time: the BLAS is a serial (or OpenMP)
/// OpenBLAS, which has no locks of its own for threads it did not start (LinearSolver.cpp: BlasThreading). With a threaded OpenBLAS
/// (told to run on the calling thread) or another BLAS, threads factorize at once.
bool blasCallsSerialized();

/// How many OpenMP parallel regions this process has run inline, on the thread that entered
/// them, since it started (CHOLMOD's supernodal kernels: see LinearSolver.cpp). 0 without CHOLMOD.
/// Tests read it to check that the executable's own region entry is the one CHOLMOD calls.
std::uint64_t inlineOpenMpRegions();

}  // namespace devsurf::engine
