#include "devsurf/engine/NormalEquations.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cstring>
#include <memory>
#include <random>
#include <set>

#include "solver/engine/TestProblems.h"
#include "solver/engine/TestTerms.h"

namespace devsurf::engine {
namespace {

using testing::LinearRowsTerm;
using testing::ProductTerm;

/// Dense H = Σ w² JᵀJ + ε² D and g = Σ w² Jᵀr over the free variables in natural order.
struct DenseSystem {
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  std::vector<int> freeVariables;
};

DenseSystem denseNormalEquations(Problem& problem, const std::vector<double>& weights, double eps) {
  const VariableLayout& layout = problem.layout();
  const std::vector<int> column = layout.freeIndex();
  DenseSystem d;
  for (int v = 0; v < layout.numVariables(); ++v)
    if (column[v] >= 0) d.freeVariables.push_back(v);
  const int n = layout.numFree();
  d.H = Eigen::MatrixXd::Zero(n, n);
  d.g = Eigen::VectorXd::Zero(n);
  for (int b = 0; b < layout.numBlocks(); ++b) {
    const VariableBlock& block = layout.block(b);
    for (int v = block.offset; v < block.offset + block.size; ++v)
      if (column[v] >= 0) d.H(column[v], column[v]) += eps * eps * block.regularizationScale;
  }
  for (int t = 0; t < problem.numTerms(); ++t) {
    Term& term = *problem.term(t).term;
    std::vector<JacobianEntry> entries;
    term.jacobianStructure(entries);
    Eigen::VectorXd r(term.numResiduals());
    std::vector<double> values(entries.size());
    term.linearizeAt(problem.x());
    term.evaluate(problem.x(), r.data(), values.data());
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(term.numResiduals(), n);
    for (std::size_t e = 0; e < entries.size(); ++e)
      if (column[entries[e].variable] >= 0) J(entries[e].row, column[entries[e].variable]) = values[e];
    const double w2 = weights[t] * weights[t];
    d.H += w2 * J.transpose() * J;
    d.g += w2 * J.transpose() * r;
  }
  return d;
}

/// The step −H⁻¹g from the dense reference, per free variable in natural order.
Eigen::VectorXd referenceStep(Problem& problem, const std::vector<double>& weights, double eps) {
  const DenseSystem d = denseNormalEquations(problem, weights, eps);
  return d.H.ldlt().solve(-d.g);
}

/// The engine's step: assemble, eliminate, dense solve of the reduced system, back-substitution.
Eigen::VectorXd engineStep(NormalEquations& eq, Problem& problem, const std::vector<double>& weights,
                           double eps, double* stepNormSquared = nullptr) {
  std::vector<double> residuals;
  eq.assemble(problem, weights, eps, residuals);
  EXPECT_TRUE(eq.eliminate());
  const Eigen::MatrixXd S = Eigen::MatrixXd(SymmetricUpper(eq.matrix().selfadjointView<Eigen::Upper>()));
  const Eigen::VectorXd delta = S.ldlt().solve(eq.rhs());
  Eigen::VectorXd stepped = problem.x();
  const double norm2 = eq.applyStep(delta, stepped);
  if (stepNormSquared) *stepNormSquared = norm2;
  const std::vector<int> column = problem.layout().freeIndex();
  Eigen::VectorXd step(problem.layout().numFree());
  for (int v = 0; v < problem.layout().numVariables(); ++v) {
    if (column[v] >= 0) step[column[v]] = stepped[v] - problem.x()[v];
    else EXPECT_EQ(stepped[v], problem.x()[v]) << "fixed variable " << v << " moved";
  }
  return step;
}

std::vector<double> unitWeights(const Problem& problem) {
  return std::vector<double>(static_cast<std::size_t>(problem.numTerms()), 1.0);
}

void disableElimination(Problem& problem) {
  for (int b = 0; b < problem.layout().numBlocks(); ++b) problem.layout().setEliminable(b, 0);
}

/// Sorted eigenvalues (ordering independent).
Eigen::VectorXd eigenvalues(const Eigen::MatrixXd& A) {
  Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A).eigenvalues();
  std::sort(ev.data(), ev.data() + ev.size());
  return ev;
}

Problem denseTestProblem() {
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
  return problem;
}

/// Dense reference: H = Σ w² JᵀJ + ε² I and g over the free variables, natural order.
TEST(NormalEquations, MatchDenseJacobianProductsInAnyOrdering) {
  Problem problem = denseTestProblem();
  disableElimination(problem);  // matrix() is all of H
  NormalEquations eq(problem);
  EXPECT_EQ(eq.numReduced(), 5);
  EXPECT_EQ(eq.numEliminated(), 0);
  std::vector<double> weights = {0.5, 2.0, 1.0};
  std::vector<double> residuals;
  eq.assemble(problem, weights, 0.1, residuals);
  EXPECT_TRUE(eq.eliminate());

  // Dense J and r with weights applied.
  const Eigen::VectorXd& x = problem.x();
  Eigen::MatrixXd A(3, 6);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(5, 6);
  Eigen::VectorXd r(5);
  {
    std::vector<JacobianEntry> e;
    problem.term(0).term->jacobianStructure(e);
    std::vector<double> values(e.size());
    Eigen::Vector3d r0;
    problem.term(0).term->evaluate(x, r0.data(), values.data());
    for (std::size_t k = 0; k < e.size(); ++k) A(e[k].row, e[k].variable) = values[k];
  }
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
  const double norm2 = eq.applyStep(deltaPerm, stepped);
  const Eigen::VectorXd deltaRef = Href.ldlt().solve(rhsRef);
  for (int c = 0; c < 5; ++c) EXPECT_NEAR(stepped[freeVars[c]] - x[freeVars[c]], deltaRef[c], 1e-12);
  EXPECT_NEAR(norm2, deltaRef.squaredNorm(), 1e-10);
  EXPECT_EQ(stepped[2], x[2]);
  // Residuals per term are the weighted squared norms.
  EXPECT_NEAR(residuals[0], r.head(3).squaredNorm(), 1e-12);
  EXPECT_NEAR(residuals[1], r[3] * r[3], 1e-12);
  EXPECT_NEAR(residuals[2], r[4] * r[4], 1e-12);
  // And the matrix itself, entry by entry, up to the permutation.
  EXPECT_NEAR(Hperm.trace(), Href.trace(), 1e-12);
  EXPECT_NEAR(Hperm.squaredNorm(), Href.squaredNorm(), 1e-10);
  EXPECT_EQ(eq.nonZeros(), eq.reducedNonZeros());
}

/// r_i = Σ_k a_ik x_{v_ik} − 1 over each row's own variables (rows of different supports).
class SparseRowsTerm final : public Term {
 public:
  using Row = std::vector<std::pair<int, double>>;
  SparseRowsTerm(std::string name, std::vector<Row> rows) : Term(std::move(name)), rows_(std::move(rows)) {}
  int numResiduals() const override { return static_cast<int>(rows_.size()); }
  void jacobianStructure(std::vector<JacobianEntry>& entries) const override {
    for (std::size_t i = 0; i < rows_.size(); ++i)
      for (const auto& [v, a] : rows_[i]) entries.push_back({static_cast<int>(i), v});
  }
  void evaluate(const Eigen::VectorXd& x, double* r, double* J) const override {
    for (std::size_t i = 0; i < rows_.size(); ++i) {
      double value = rows_[i].empty() || rows_[i][0].second == 0.0 ? 0.0 : -1.0;
      for (const auto& [v, a] : rows_[i]) {
        value += a * x[v];
        if (J) *J++ = a;
      }
      r[i] = value;
    }
  }

 private:
  std::vector<Row> rows_;
};

TEST(NormalEquations, TwoThreadsAccumulateTheSameSystemAndRunsRepeatBitForBit) {
  // 30 terms of random sparse rows over 60 variables: the second thread takes the later terms.
  Problem problem;
  problem.addBlock("x", 60);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  std::uniform_int_distribution<int> variable(0, 59);
  for (int i = 0; i < 60; ++i) problem.x()[i] = uni(rng);
  for (int t = 0; t < 30; ++t) {
    std::vector<SparseRowsTerm::Row> rows(8);
    for (auto& row : rows) {
      std::set<int> used;
      while (used.size() < 6) used.insert(variable(rng));
      for (int v : used) row.emplace_back(v, uni(rng));
    }
    problem.addTerm(std::make_unique<SparseRowsTerm>("rows" + std::to_string(t), rows), 0.5 + 0.1 * t, Strength::Soft);
  }
  disableElimination(problem);
  NormalEquations eq(problem);
  const std::vector<double> weights(30, 1.3);
  std::vector<double> residuals;
  eq.assemble(problem, weights, 0.1, residuals);
  ASSERT_EQ(eq.assemblyThreads(), 1);
  const Eigen::VectorXd oneH = Eigen::Map<const Eigen::VectorXd>(eq.matrix().valuePtr(), eq.matrix().nonZeros());
  const Eigen::VectorXd oneRhs = eq.rhs();
  eq.setAssemblyThreads(2, 0);
  ASSERT_EQ(eq.assemblyThreads(), 2);
  eq.assemble(problem, weights, 0.1, residuals);
  const Eigen::VectorXd twoH = Eigen::Map<const Eigen::VectorXd>(eq.matrix().valuePtr(), eq.matrix().nonZeros());
  const Eigen::VectorXd twoRhs = eq.rhs();
  EXPECT_LE((twoH - oneH).cwiseAbs().maxCoeff(), 1e-13 * oneH.cwiseAbs().maxCoeff());
  EXPECT_LE((twoRhs - oneRhs).cwiseAbs().maxCoeff(), 1e-13 * oneRhs.cwiseAbs().maxCoeff());
  EXPECT_GT(oneH.cwiseAbs().maxCoeff(), 1.0);  // a system with something in it
  eq.assemble(problem, weights, 0.1, residuals);
  const Eigen::VectorXd againH = Eigen::Map<const Eigen::VectorXd>(eq.matrix().valuePtr(), eq.matrix().nonZeros());
  EXPECT_EQ(againH, twoH);  // the same partition and order of sums: the same bits
  EXPECT_EQ(eq.rhs(), twoRhs);
  // Below the threshold (the default) one thread does it.
  eq.setAssemblyThreads(2);
  EXPECT_EQ(eq.assemblyThreads(), 1);
}

/// The engine's step on `rows` (a SparseRowsTerm, weight 0.7) and x0·x5 = 1 (weight 2) over `size`
/// random variables, nothing eliminated, against the dense reference; returns the reference step.
Eigen::VectorXd expectSparseRowsStepMatchesTheReference(const std::vector<SparseRowsTerm::Row>& rows, int size,
                                                        unsigned seed) {
  Problem problem;
  problem.addBlock("x", size);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (int i = 0; i < size; ++i) problem.x()[i] = uni(rng);
  problem.addTerm(std::make_unique<SparseRowsTerm>("rows", rows), 0.7, Strength::Soft);
  problem.addTerm(std::make_unique<ProductTerm>("p", 0, 5, 1.0), 2.0, Strength::Hard);
  disableElimination(problem);
  NormalEquations eq(problem);
  const std::vector<double> weights = {0.7, 2.0};
  const Eigen::VectorXd step = engineStep(eq, problem, weights, 0.1);
  const Eigen::VectorXd reference = referenceStep(problem, weights, 0.1);
  EXPECT_LT((step - reference).cwiseAbs().maxCoeff(), 1e-12);
  return reference;
}

TEST(NormalEquations, RowsWithAZeroJacobianAddNothingAndTheRowsAfterThemStillLandInTheirSlots) {
  // A guard at rest (a hinge row: residual and Jacobian zero) is skipped by the assembler; the
  // rows after it, on other variables, must still scatter into their own slots.
  expectSparseRowsStepMatchesTheReference({{{0, 0.9}, {1, -0.4}},
                                           {{2, 0.0}, {3, 0.0}, {4, 0.0}},  // at rest
                                           {{4, 0.6}, {5, 0.8}},
                                           {{0, 0.0}, {5, 0.0}},  // at rest
                                           {{1, 0.3}, {2, 0.7}, {3, -0.5}}},
                                          6, 11);
}

TEST(NormalEquations, RunsOfRowsWithTheSameColumnsAreSummedAsTheRowsWouldBe) {
  // Consecutive rows on the same columns in the same order (the samples of one span) are summed
  // densely and scattered once: runs of three and two, a row at rest inside a run and one at its
  // start, a run whose rows are all at rest, and rows on the same columns in another order (no
  // run). The step must be the dense reference's.
  const Eigen::VectorXd reference =
      expectSparseRowsStepMatchesTheReference({{{0, 0.9}, {1, -0.4}, {3, 0.2}},
                                               {{0, 0.3}, {1, 0.8}, {3, -0.6}},
                                               {{0, -0.7}, {1, 0.1}, {3, 0.5}},
                                               {{2, 0.0}, {4, 0.0}},  // at rest, starting a run
                                               {{2, 0.4}, {4, -0.9}},
                                               {{5, 0.0}, {6, 0.0}},  // a run all at rest
                                               {{5, 0.0}, {6, 0.0}},
                                               {{1, 0.6}, {6, 0.3}},
                                               {{1, 0.0}, {6, 0.0}},  // at rest inside a run
                                               {{1, -0.2}, {6, 0.7}},
                                               {{6, 0.5}, {1, 0.4}}},  // the same columns, another order
                                              7, 12);
  EXPECT_GT(reference.cwiseAbs().maxCoeff(), 0.1);
}

TEST(NormalEquations, AutomaticEliminationTakesTheSameStep) {
  Problem problem = denseTestProblem();
  const std::vector<double> weights = {0.5, 2.0, 1.0};
  NormalEquations eq(problem);
  Problem twin = denseTestProblem();
  disableElimination(twin);
  NormalEquations full(twin);
  EXPECT_EQ(eq.numFree(), 5);
  EXPECT_EQ(eq.nonZeros(), full.nonZeros());  // nonZeros() counts all of H either way
  double norm2 = 0.0;
  const Eigen::VectorXd step = engineStep(eq, problem, weights, 0.1, &norm2);
  const Eigen::VectorXd ref = referenceStep(problem, weights, 0.1);
  EXPECT_LT((step - ref).norm(), 1e-12 * (1.0 + ref.norm()));
  EXPECT_NEAR(norm2, ref.squaredNorm(), 1e-10 * (1.0 + ref.squaredNorm()));
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
  disableElimination(problem);
  NormalEquations eq(problem);
  std::vector<double> residuals;
  eq.assemble(problem, {1.0}, 2.0, residuals);
  EXPECT_TRUE(eq.eliminate());
  const Eigen::MatrixXd H = Eigen::MatrixXd(SymmetricUpper(eq.matrix().selfadjointView<Eigen::Upper>()));
  (void)a;
  // Diagonal entries 4 and 1 in some order.
  EXPECT_NEAR(H.diagonal().sum(), 5.0, 1e-15);
  EXPECT_NEAR(H.diagonal().prod(), 4.0, 1e-15);
}

/// The strip's structure: every normal is a group of 3, eliminated exactly; the reduced matrix
/// is the Schur complement on the control points and has the pattern of H there (no fill).
TEST(NormalEquations, StripLikeNormalsAreEliminatedWithoutFill) {
  const int spans = 3, samples = 4;
  Problem problem;
  testing::buildStripLike(problem, spans, samples, 11);
  const std::vector<double> weights = {1.0, 0.1, 0.05};
  NormalEquations eq(problem);
  const int numKept = 3 * (spans + 3) - 3;
  EXPECT_EQ(eq.numEliminationGroups(), spans * samples);
  EXPECT_EQ(eq.numEliminated(), 3 * spans * samples);
  EXPECT_EQ(eq.numReduced(), numKept);

  Problem twin;
  testing::buildStripLike(twin, spans, samples, 11);
  disableElimination(twin);
  NormalEquations full(twin);
  EXPECT_EQ(full.numEliminationGroups(), 0);
  EXPECT_EQ(eq.nonZeros(), full.nonZeros());

  const double eps = 0.01;
  const Eigen::VectorXd step = engineStep(eq, problem, weights, eps);
  const Eigen::VectorXd ref = referenceStep(problem, weights, eps);
  EXPECT_LT((step - ref).norm(), 1e-9 * (1.0 + ref.norm()));
  const Eigen::VectorXd stepFull = engineStep(full, twin, weights, eps);
  EXPECT_LT((stepFull - ref).norm(), 1e-9 * (1.0 + ref.norm()));

  // The reduced matrix is the Schur complement H_cc − H_cn H_nn⁻¹ H_nc (up to the ordering) and
  // stores exactly the nonzeros of H_cc.
  const DenseSystem d = denseNormalEquations(problem, weights, eps);
  const int offN = problem.layout().block(problem.layout().blockId("normals")).offset;
  std::vector<int> kept, elim;
  for (std::size_t c = 0; c < d.freeVariables.size(); ++c)
    (d.freeVariables[c] < offN ? kept : elim).push_back(static_cast<int>(c));
  ASSERT_EQ(static_cast<int>(kept.size()), numKept);
  const Eigen::MatrixXd Hcc = d.H(kept, kept), Hcn = d.H(kept, elim), Hnn = d.H(elim, elim);
  const Eigen::MatrixXd schur = Hcc - Hcn * Hnn.ldlt().solve(Hcn.transpose());
  const Eigen::MatrixXd S = Eigen::MatrixXd(SymmetricUpper(eq.matrix().selfadjointView<Eigen::Upper>()));
  const Eigen::VectorXd evS = eigenvalues(S), evRef = eigenvalues(schur);
  EXPECT_LT((evS - evRef).norm(), 1e-9 * evRef.norm());
  const Eigen::VectorXd reducedRhs = -(d.g(kept) - Hcn * Hnn.ldlt().solve(d.g(elim)));
  EXPECT_NEAR(eq.rhs().norm(), reducedRhs.norm(), 1e-9 * (1.0 + reducedRhs.norm()));
  long keptNonZeros = 0;
  for (int j = 0; j < numKept; ++j)
    for (int i = 0; i <= j; ++i) keptNonZeros += Hcc(i, j) != 0.0 ? 1 : 0;
  EXPECT_EQ(eq.reducedNonZeros(), keptNonZeros);
}

/// Without a row that covers all of a normal's neighbours, the automatic rule keeps the normals
/// (eliminating them would create fill); declaring them eliminable still eliminates them exactly.
TEST(NormalEquations, DeclaredGroupsAreEliminatedEvenWithFill) {
  const int spans = 3, samples = 2;
  const std::vector<double> weights = {1.0, 0.1, 0.05};
  Problem automatic;
  testing::buildStripLike(automatic, spans, samples, 5, false);
  EXPECT_EQ(NormalEquations(automatic).numEliminationGroups(), 0);

  Problem declared;
  testing::buildStripLike(declared, spans, samples, 5, false);
  declared.layout().setEliminable(declared.layout().blockId("normals"), 3);
  NormalEquations eq(declared);
  EXPECT_EQ(eq.numEliminationGroups(), spans * samples);
  EXPECT_EQ(eq.numReduced(), 3 * (spans + 3) - 3);
  const Eigen::VectorXd step = engineStep(eq, declared, weights, 0.01);
  const Eigen::VectorXd ref = referenceStep(declared, weights, 0.01);
  EXPECT_LT((step - ref).norm(), 1e-9 * (1.0 + ref.norm()));
}

TEST(NormalEquations, RowsCouplingTwoDeclaredGroupsAreRejected) {
  Problem problem;
  const int block = problem.addBlock("pairs", 4);
  problem.layout().setEliminable(block, 2);
  problem.addTerm(std::make_unique<ProductTerm>("couples", 1, 2, 1.0), 1.0, Strength::Hard);
  EXPECT_THROW(NormalEquations eq(problem), std::logic_error);
}

TEST(NormalEquations, EverythingMayBeEliminated) {
  Problem problem;
  problem.addBlock("x", 2);
  problem.x() << 3.0, 1.0;
  problem.addTerm(std::make_unique<ProductTerm>("product", 0, 1, 1.0), 1.0, Strength::Hard);
  NormalEquations eq(problem);
  EXPECT_EQ(eq.numReduced(), 0);
  EXPECT_EQ(eq.numEliminationGroups(), 1);
  EXPECT_EQ(eq.nonZeros(), 3);
  const Eigen::VectorXd step = engineStep(eq, problem, {1.0}, 0.1);
  const Eigen::VectorXd ref = referenceStep(problem, {1.0}, 0.1);
  EXPECT_LT((step - ref).norm(), 1e-12);
}

/// Two sides of an alternation: "surface" (3 scalars) and "development" (3, its second fixed;
/// alternating), coupled by dense linear rows and a product, each with a term of its own.
Problem twoSidedProblem() {
  Problem problem;
  problem.addBlock("surface", 3);
  const int development = problem.addBlock("development", 3);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (int i = 0; i < 6; ++i) problem.x()[i] = uni(rng);
  problem.layout().setFixed(development, 1, 1);
  problem.layout().setAlternating(development);
  Eigen::MatrixXd A(4, 6);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 6; ++j) A(i, j) = uni(rng);
  problem.addTerm(std::make_unique<LinearRowsTerm>("both", A, Eigen::Vector4d(1, -1, 2, 0.5)), 0.7, Strength::Hard);
  problem.addTerm(std::make_unique<ProductTerm>("coupling", 0, 3, 1.0), 1.3, Strength::Hard);
  problem.addTerm(std::make_unique<ProductTerm>("surface only", 1, 2, 0.5), 1.0, Strength::Hard);
  problem.addTerm(std::make_unique<ProductTerm>("development only", 3, 5, -0.4), 0.9, Strength::Soft);
  return problem;
}

TEST(NormalEquations, EachSideOfAnAlternationSolvesItsDiagonalBlockOfTheWholeSystem) {
  Problem problem = twoSidedProblem();
  const std::vector<double> weights{0.7, 1.3, 1.0, 0.9};
  const double eps = 0.05;
  const DenseSystem whole = denseNormalEquations(problem, weights, eps);  // all five free scalars
  ASSERT_EQ(whole.freeVariables, (std::vector<int>{0, 1, 2, 3, 5}));
  for (const VariablePart part : {VariablePart::Main, VariablePart::Alternating}) {
    const std::vector<int> side = part == VariablePart::Main ? std::vector<int>{0, 1, 2} : std::vector<int>{3, 4};
    // Reference: H_ss δ_s = −g_s, the other side held.
    Eigen::MatrixXd Hs(side.size(), side.size());
    Eigen::VectorXd gs(side.size());
    for (std::size_t a = 0; a < side.size(); ++a) {
      gs[a] = whole.g[side[a]];
      for (std::size_t b = 0; b < side.size(); ++b) Hs(a, b) = whole.H(side[a], side[b]);
    }
    const Eigen::VectorXd reference = Hs.ldlt().solve(-gs);
    NormalEquations eq(problem, {}, part);
    EXPECT_EQ(eq.numFree(), static_cast<int>(side.size()));
    std::vector<double> residuals;
    eq.assemble(problem, weights, eps, residuals);
    ASSERT_TRUE(eq.eliminate());
    const Eigen::MatrixXd S = Eigen::MatrixXd(SymmetricUpper(eq.matrix().selfadjointView<Eigen::Upper>()));
    Eigen::VectorXd stepped = problem.x();
    eq.applyStep(S.ldlt().solve(eq.rhs()), stepped);
    const Eigen::VectorXd moved = stepped - problem.x();
    for (std::size_t a = 0; a < side.size(); ++a)
      EXPECT_NEAR(moved[whole.freeVariables[side[a]]], reference[a], 1e-12) << "scalar " << whole.freeVariables[side[a]];
    for (int v = 0; v < 6; ++v) {
      const bool onSide = std::any_of(side.begin(), side.end(),
                                      [v, &whole](int c) { return whole.freeVariables[c] == v; });
      if (!onSide) EXPECT_EQ(moved[v], 0.0) << "scalar " << v << " is held on this side";
    }
  }
}

TEST(NormalEquations, ASideEvaluatesAndLinearizesOnlyTheTermsThatTouchIt) {
  Problem problem;
  problem.addBlock("surface", 2);
  const int development = problem.addBlock("development", 2);
  problem.x() << 1.0, 2.0, 3.0, 4.0;
  problem.layout().setAlternating(development);
  using Row = testing::SparseLinearTerm::Row;
  auto surfaceOnly = std::make_unique<testing::CountingTerm>("surface", std::vector<Row>{{{{0, 1.0}, {1, 2.0}}, 1.0}});
  auto developmentOnly = std::make_unique<testing::CountingTerm>("development", std::vector<Row>{{{{2, 1.0}}, 0.0}});
  auto both = std::make_unique<testing::CountingTerm>("both", std::vector<Row>{{{{1, 1.0}, {3, -1.0}}, 0.0}});
  testing::CountingTerm* counted[3] = {surfaceOnly.get(), developmentOnly.get(), both.get()};
  problem.addTerm(std::move(surfaceOnly), 1.0, Strength::Hard);
  problem.addTerm(std::move(developmentOnly), 1.0, Strength::Hard);
  problem.addTerm(std::move(both), 1.0, Strength::Hard);
  NormalEquations main(problem, {}, VariablePart::Main), alternating(problem, {}, VariablePart::Alternating);
  EXPECT_TRUE(main.touchesPart(0));
  EXPECT_FALSE(main.touchesPart(1));
  EXPECT_TRUE(main.touchesPart(2));
  EXPECT_FALSE(alternating.touchesPart(0));
  EXPECT_TRUE(alternating.touchesPart(1));
  EXPECT_TRUE(alternating.touchesPart(2));
  const std::vector<double> weights(3, 1.0);
  std::vector<double> residuals;
  main.assemble(problem, weights, 0.1, residuals);
  EXPECT_EQ(counted[0]->evaluations, 1);
  EXPECT_EQ(counted[1]->evaluations, 0);
  EXPECT_EQ(counted[1]->linearizations, 0);
  EXPECT_EQ(counted[2]->evaluations, 1);
  alternating.assemble(problem, weights, 0.1, residuals);
  EXPECT_EQ(counted[0]->evaluations, 1);
  EXPECT_EQ(counted[0]->linearizations, 1);
  EXPECT_EQ(counted[1]->evaluations, 1);
  EXPECT_EQ(counted[2]->evaluations, 2);
  // The residuals of a side's terms replace theirs; the other entries are kept as they were.
  std::vector<double> perTerm{-1.0, -1.0, -1.0}, largest{-1.0, -1.0, -1.0};
  problem.x()[2] = 5.0;
  alternating.partResiduals(problem, problem.x(), weights, perTerm, largest);
  EXPECT_EQ(perTerm, (std::vector<double>{-1.0, 25.0, 4.0}));
  EXPECT_EQ(largest, (std::vector<double>{-1.0, 5.0, 2.0}));
  EXPECT_EQ(counted[0]->evaluations, 1);
}

TEST(NormalEquations, ASingularGroupBlockFailsTheElimination) {
  Problem problem;
  problem.addBlock("a", 1);
  const int idle = problem.addBlock("idle", 1);  // in no row, and not regularized
  problem.layout().setRegularizationScale(idle, 0.0);
  problem.layout().setEliminable(idle, 1);
  problem.addTerm(std::make_unique<LinearRowsTerm>("fit", Eigen::MatrixXd::Ones(1, 1),
                                                   Eigen::VectorXd::Ones(1)),
                  1.0, Strength::Hard);
  NormalEquations eq(problem);
  EXPECT_EQ(eq.numEliminationGroups(), 2);  // "a" automatically, "idle" as declared
  std::vector<double> residuals;
  eq.assemble(problem, {1.0}, 0.1, residuals);
  EXPECT_FALSE(eq.eliminate());
}

/// Whether two assembled systems are the same bit for bit: matrix values, right-hand side and the
/// per-term residuals.
void expectSameSystem(const NormalEquations& a, const NormalEquations& b, const std::vector<double>& ra,
                      const std::vector<double>& rb) {
  ASSERT_EQ(a.matrix().nonZeros(), b.matrix().nonZeros());
  EXPECT_EQ(std::memcmp(a.matrix().valuePtr(), b.matrix().valuePtr(), sizeof(double) * a.matrix().nonZeros()), 0);
  ASSERT_EQ(a.rhs().size(), b.rhs().size());
  EXPECT_EQ(std::memcmp(a.rhs().data(), b.rhs().data(), sizeof(double) * a.rhs().size()), 0);
  EXPECT_EQ(ra, rb);
}

/// residuals() at x keeps the Jacobians of the terms that evaluate from x alone; assemble() at the
/// same x takes them instead of evaluating those terms again and builds the same system bit for
/// bit. At another x, after partResiduals() or correctionRhs(), once forgotten or switched off,
/// it evaluates them again.
TEST(NormalEquations, AnAssemblyAtTheJudgedPointTakesTheKeptJacobiansAndBuildsTheSameSystem) {
  Problem kept, plain;
  testing::buildStripLike(kept, 4, 5, 11);
  testing::buildStripLike(plain, 4, 5, 11);
  auto everyOther = [](int t) { return t % 2 == 0; };
  const std::vector<testing::ForwardingTerm*> terms = testing::forwardTerms(kept, everyOther);
  int fromXAlone = 0;
  for (int t = 0; t < kept.numTerms(); ++t) fromXAlone += everyOther(t) ? 1 : 0;
  ASSERT_GT(fromXAlone, 0);
  ASSERT_LT(fromXAlone, kept.numTerms());
  NormalEquations a(kept), b(plain);
  b.setKeepEvaluations(false);
  std::vector<double> weights(static_cast<std::size_t>(kept.numTerms()), 1.0), ra, rb;
  weights[1] = 0.3;

  a.residuals(kept, kept.x(), weights, ra);
  b.residuals(plain, plain.x(), weights, rb);
  EXPECT_EQ(ra, rb);
  for (int t = 0; t < kept.numTerms(); ++t) {
    EXPECT_EQ(terms[t]->withJacobian, everyOther(t) ? 1 : 0) << t;
    EXPECT_EQ(terms[t]->residualOnly, everyOther(t) ? 0 : 1) << t;
  }
  a.assemble(kept, weights, 0.1, ra);
  b.assemble(plain, weights, 0.1, rb);
  EXPECT_EQ(a.reusedTerms(), fromXAlone);
  EXPECT_EQ(b.reusedTerms(), 0);
  for (int t = 0; t < kept.numTerms(); ++t) EXPECT_EQ(terms[t]->withJacobian, 1) << "term " << t << " evaluated once";
  expectSameSystem(a, b, ra, rb);
  ASSERT_TRUE(a.eliminate());
  ASSERT_TRUE(b.eliminate());
  expectSameSystem(a, b, ra, rb);

  // Kept at one x, assembled at another: evaluated again, the same system.
  a.residuals(kept, kept.x(), weights, ra);
  kept.x()[5] += 1e-3;
  plain.x()[5] += 1e-3;
  a.assemble(kept, weights, 0.1, ra);
  b.assemble(plain, weights, 0.1, rb);
  EXPECT_EQ(a.reusedTerms(), 0);
  expectSameSystem(a, b, ra, rb);

  // What replaces residual_ between the evaluation and the assembly drops what was kept.
  std::vector<double> perTerm(static_cast<std::size_t>(kept.numTerms()), 0.0), largest = perTerm;
  a.residuals(kept, kept.x(), weights, ra);
  a.partResiduals(kept, kept.x(), weights, perTerm, largest);
  a.assemble(kept, weights, 0.1, ra);
  EXPECT_EQ(a.reusedTerms(), 0) << "after partResiduals";
  ASSERT_TRUE(a.eliminate());
  a.residuals(kept, kept.x(), weights, ra);
  a.correctionRhs(kept, kept.x());
  a.assemble(kept, weights, 0.1, ra);
  EXPECT_EQ(a.reusedTerms(), 0) << "after correctionRhs";
  a.residuals(kept, kept.x(), weights, ra);
  a.forgetKeptEvaluation();
  a.assemble(kept, weights, 0.1, ra);
  EXPECT_EQ(a.reusedTerms(), 0) << "forgotten";
  a.residuals(kept, kept.x(), weights, ra);
  a.assemble(kept, weights, 0.1, ra);
  EXPECT_EQ(a.reusedTerms(), fromXAlone) << "kept again";
  b.assemble(plain, weights, 0.1, rb);
  expectSameSystem(a, b, ra, rb);
  a.setKeepEvaluations(false);
  a.residuals(kept, kept.x(), weights, ra);
  a.assemble(kept, weights, 0.1, ra);
  EXPECT_EQ(a.reusedTerms(), 0) << "switched off";
  b.assemble(plain, weights, 0.1, rb);
  expectSameSystem(a, b, ra, rb);
}

}  // namespace
}  // namespace devsurf::engine
