#include "devsurf/engine/LinearSolver.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <vector>

namespace devsurf::engine {
namespace {

std::vector<LinearSolverKind> availableKinds() {
  std::vector<LinearSolverKind> kinds{LinearSolverKind::SimplicialLDLT};
  if (cholmodAvailable()) kinds.push_back(LinearSolverKind::Cholmod);
  return kinds;
}

SymmetricUpper upperOf(const Eigen::MatrixXd& dense) {
  SymmetricUpper upper = dense.sparseView();
  upper = SymmetricUpper(upper.triangularView<Eigen::Upper>());
  upper.makeCompressed();
  return upper;
}

TEST(LinearSolver, SolvesAPositiveDefiniteBandedSystem) {
  const int n = 40;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    A(i, i) = 4.0 + 0.01 * i;
    if (i + 1 < n) A(i, i + 1) = A(i + 1, i) = -1.0;
    if (i + 3 < n) A(i, i + 3) = A(i + 3, i) = 0.5;
  }
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  const Eigen::VectorXd expected = A.ldlt().solve(b);
  for (LinearSolverKind kind : availableKinds()) {
    auto solver = makeLinearSolver(kind);
    const SymmetricUpper upper = upperOf(A);
    solver->analyzePattern(upper);
    for (int repeat = 0; repeat < 2; ++repeat) {  // same pattern, numbers refilled
      ASSERT_TRUE(solver->factorize(upper)) << solver->name();
      Eigen::VectorXd x(n);
      solver->solve(b, x);
      EXPECT_LT((x - expected).norm(), 1e-12) << solver->name();
    }
  }
}

/// Both solvers report an indefinite matrix (a negative pivot; CHOLMOD's simplicial LDLᵀ itself
/// only flags zero pivots).
TEST(LinearSolver, RejectsAnIndefiniteMatrix) {
  Eigen::MatrixXd A(3, 3);
  A << 1, 2, 0, 2, 1, 0, 0, 0, 1;  // eigenvalues 3, −1, 1
  for (LinearSolverKind kind : availableKinds()) {
    auto solver = makeLinearSolver(kind);
    const SymmetricUpper upper = upperOf(A);
    solver->analyzePattern(upper);
    EXPECT_FALSE(solver->factorize(upper)) << solver->name();
  }
}

TEST(LinearSolver, AnEmptySystemHasAnEmptySolution) {
  for (LinearSolverKind kind : availableKinds()) {
    auto solver = makeLinearSolver(kind);
    const SymmetricUpper empty(0, 0);
    solver->analyzePattern(empty);
    EXPECT_TRUE(solver->factorize(empty)) << solver->name();
    Eigen::VectorXd x;
    solver->solve(Eigen::VectorXd(), x);
    EXPECT_EQ(x.size(), 0);
  }
}

}  // namespace
}  // namespace devsurf::engine
