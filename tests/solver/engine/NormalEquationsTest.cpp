#include "devsurf/engine/NormalEquations.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <memory>
#include <random>

#include "solver/engine/TestTerms.h"

namespace devsurf::engine {
namespace {

using testing::LinearRowsTerm;
using testing::ProductTerm;

/// Dense reference: H = Σ w² JᵀJ + ε² I and g over the free variables, natural order.
TEST(NormalEquations, MatchDenseJacobianProductsInAnyOrdering) {
  Problem problem;
  const int block = problem.addBlock("x", 6);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (int i = 0; i < 6; ++i) problem.x()[i] = uni(rng);
  problem.layout().setFixed(block, 2, 1);
  Eigen::MatrixXd A(3, 6);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 6; ++j) A(i, j) = (i + j) % 3 == 0 ? 0.0 : uni(rng);
  problem.addTerm(std::make_unique<LinearRowsTerm>("lin", A, Eigen::Vector3d(1, 2, 3)), 0.5,
                  Strength::Soft);
  problem.addTerm(std::make_unique<ProductTerm>("p", 0, 5, 1.0), 2.0, Strength::Hard);
  problem.addTerm(std::make_unique<ProductTerm>("q", 3, 4, -1.0), 1.0, Strength::Hard);

  NormalEquations eq(problem);
  std::vector<double> weights = {0.5, 2.0, 1.0};
  std::vector<double> residuals;
  eq.assemble(problem, weights, 0.1, residuals);

  // Dense J and r with weights applied.
  const Eigen::VectorXd& x = problem.x();
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(5, 6);
  Eigen::VectorXd r(5);
  J.topRows(3) = 0.5 * A;
  r.head(3) = 0.5 * (A * x - Eigen::Vector3d(1, 2, 3));
  J(3, 0) = 2.0 * x[5];
  J(3, 5) = 2.0 * x[0];
  r[3] = 2.0 * (x[0] * x[5] - 1.0);
  J(4, 3) = x[4];
  J(4, 4) = x[3];
  r[4] = x[3] * x[4] + 1.0;
  const std::vector<int> freeVars = {0, 1, 3, 4, 5};
  Eigen::MatrixXd Jf(5, 5);
  for (int c = 0; c < 5; ++c) Jf.col(c) = J.col(freeVars[c]);
  const Eigen::MatrixXd Href = Jf.transpose() * Jf + 0.01 * Eigen::MatrixXd::Identity(5, 5);
  const Eigen::VectorXd rhsRef = -Jf.transpose() * r;

  // Compare through the solution of the step, which is ordering independent.
  const Eigen::MatrixXd Hperm = Eigen::MatrixXd(SymmetricUpper(eq.matrix().selfadjointView<Eigen::Upper>()));
  const Eigen::VectorXd deltaPerm = Hperm.ldlt().solve(eq.rhs());
  Eigen::VectorXd stepped = x;
  eq.applyStep(deltaPerm, stepped);
  const Eigen::VectorXd deltaRef = Href.ldlt().solve(rhsRef);
  for (int c = 0; c < 5; ++c) EXPECT_NEAR(stepped[freeVars[c]] - x[freeVars[c]], deltaRef[c], 1e-12);
  EXPECT_EQ(stepped[2], x[2]);
  // Residuals per term are the weighted squared norms.
  EXPECT_NEAR(residuals[0], r.head(3).squaredNorm(), 1e-12);
  EXPECT_NEAR(residuals[1], r[3] * r[3], 1e-12);
  EXPECT_NEAR(residuals[2], r[4] * r[4], 1e-12);
  // And the matrix itself, entry by entry, up to the permutation.
  EXPECT_NEAR(Hperm.trace(), Href.trace(), 1e-12);
  EXPECT_NEAR(Hperm.squaredNorm(), Href.squaredNorm(), 1e-10);
}

TEST(NormalEquations, RejectATermThatListsAVariableTwiceInOneRow) {
  Problem problem;
  problem.addBlock("x", 2);
  problem.addTerm(std::make_unique<ProductTerm>("square", 1, 1, 1.0), 1.0, Strength::Hard);
  EXPECT_THROW(NormalEquations eq(problem), std::logic_error);
}

TEST(NormalEquations, RegularizationScalesPerBlock) {
  Problem problem;
  const int a = problem.addBlock("a", 1);
  const int b = problem.addBlock("b", 1);
  problem.layout().setRegularizationScale(b, 0.25);
  problem.addTerm(std::make_unique<LinearRowsTerm>("zero", Eigen::MatrixXd::Zero(1, 2),
                                                   Eigen::VectorXd::Zero(1)),
                  1.0, Strength::Hard);
  NormalEquations eq(problem);
  std::vector<double> residuals;
  eq.assemble(problem, {1.0}, 2.0, residuals);
  const Eigen::MatrixXd H = Eigen::MatrixXd(SymmetricUpper(eq.matrix().selfadjointView<Eigen::Upper>()));
  (void)a;
  // Diagonal entries 4 and 1 in some order.
  EXPECT_NEAR(H.diagonal().sum(), 5.0, 1e-15);
  EXPECT_NEAR(H.diagonal().prod(), 4.0, 1e-15);
}

}  // namespace
}  // namespace devsurf::engine
