#include "devsurf/engine/LinearSolver.h"

#include <stdexcept>

#include <Eigen/SparseCholesky>
#ifdef DEVSURF_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

namespace devsurf::engine {
namespace {

/// Eigen SimplicialLDLT in natural ordering: the assembler already applied a fill-reducing
/// permutation, and with Upper storage Eigen factorizes the matrix without copying it.
class SimplicialLdltSolver final : public LinearSolver {
 public:
  std::string name() const override { return "ldlt"; }
  void analyzePattern(const SymmetricUpper& matrix) override { ldlt_.analyzePattern(matrix); }
  bool factorize(const SymmetricUpper& matrix) override {
    ldlt_.factorize(matrix);
    if (ldlt_.info() != Eigen::Success) return false;
    return (ldlt_.vectorD().array() > 0.0).all();
  }
  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) override {
    solution = ldlt_.solve(rhs);
  }

 private:
  Eigen::SimplicialLDLT<SymmetricUpper, Eigen::Upper, Eigen::NaturalOrdering<int>> ldlt_;
};

#ifdef DEVSURF_HAVE_CHOLMOD
/// CHOLMOD supernodal Cholesky, natural ordering (see above).
class CholmodSolver final : public LinearSolver {
 public:
  CholmodSolver() {
    llt_.cholmod().nmethods = 1;
    llt_.cholmod().method[0].ordering = CHOLMOD_NATURAL;
    llt_.cholmod().postorder = 0;
  }
  std::string name() const override { return "cholmod"; }
  void analyzePattern(const SymmetricUpper& matrix) override { llt_.analyzePattern(matrix); }
  bool factorize(const SymmetricUpper& matrix) override {
    llt_.factorize(matrix);
    return llt_.info() == Eigen::Success;
  }
  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) override {
    solution = llt_.solve(rhs);
  }

 private:
  Eigen::CholmodSupernodalLLT<SymmetricUpper, Eigen::Upper> llt_;
};
#endif

}  // namespace

bool cholmodAvailable() {
#ifdef DEVSURF_HAVE_CHOLMOD
  return true;
#else
  return false;
#endif
}

std::unique_ptr<LinearSolver> makeLinearSolver(LinearSolverKind kind) {
  switch (kind) {
    case LinearSolverKind::SimplicialLDLT:
      return std::make_unique<SimplicialLdltSolver>();
    case LinearSolverKind::Cholmod:
#ifdef DEVSURF_HAVE_CHOLMOD
      return std::make_unique<CholmodSolver>();
#else
      throw std::invalid_argument("linear_solver: cholmod was not compiled in");
#endif
  }
  throw std::invalid_argument("linear_solver: unknown kind");
}

LinearSolverKind linearSolverKindFromName(const std::string& name) {
  if (name == "ldlt") return LinearSolverKind::SimplicialLDLT;
  if (name == "cholmod") return LinearSolverKind::Cholmod;
  throw std::invalid_argument("linear_solver: expected \"ldlt\" or \"cholmod\", got \"" + name + "\"");
}

}  // namespace devsurf::engine
