#include "devsurf/engine/GuidedProjectionSolver.h"

#include <gtest/gtest.h>

#include <cstring>

#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <thread>

#include "solver/engine/TestProblems.h"
#include "solver/engine/TestTerms.h"

namespace devsurf::engine {
namespace {

using testing::LinearRowsTerm;
using testing::ProductTerm;
using testing::SqrtTerm;

/// The hard constraint x0·x1 = 1 from x = (3, 1).
Problem productProblem() {
  Problem problem;
  problem.addBlock("x", 2);
  problem.x() << 3.0, 1.0;
  problem.addTerm(std::make_unique<ProductTerm>("product", 0, 1, 1.0), 1.0, Strength::Hard);
  return problem;
}

TEST(GuidedProjectionSolver, SolvesALinearLeastSquaresProblemInOneStep) {
  Problem problem;
  problem.addBlock("x", 3);
  Eigen::MatrixXd A(4, 3);
  A << 1, 2, 0, 0, 1, 1, 1, 0, 1, 2, 1, 1;
  const Eigen::VectorXd b = Eigen::Vector4d(1, -2, 3, 0.5);
  problem.addTerm(std::make_unique<LinearRowsTerm>("fit", A, b), 1.0, Strength::Hard);
  GuidedProjectionSolver solver(problem);
  SolverOptions options;
  options.maxIterations = 1;
  options.regularization = 0.0;
  solver.solve(options);
  const Eigen::VectorXd expected = (A.transpose() * A).ldlt().solve(A.transpose() * b);
  EXPECT_LT((problem.x() - expected).norm(), 1e-12);
}

TEST(GuidedProjectionSolver, FixedVariablesLeaveTheSystemAndNeverMove) {
  Problem problem;
  const int block = problem.addBlock("x", 3);
  problem.x() << 5.0, 0.0, 0.0;
  problem.layout().setFixed(block, 0, 1);
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(3, 3);
  problem.addTerm(std::make_unique<LinearRowsTerm>("target", A, Eigen::Vector3d(1, 2, 3)), 1.0,
                  Strength::Hard);
  GuidedProjectionSolver solver(problem);
  EXPECT_EQ(solver.numFree(), 2);
  SolverOptions options;
  options.maxIterations = 5;
  options.regularization = 1e-6;
  solver.solve(options);
  EXPECT_EQ(problem.x()[0], 5.0);
  EXPECT_NEAR(problem.x()[1], 2.0, 1e-9);
  EXPECT_NEAR(problem.x()[2], 3.0, 1e-9);
}

TEST(GuidedProjectionSolver, ConvergesQuadraticallyOnAQuadraticConstraint) {
  // x0·x1 = 2 with a soft target pulling x0 to 1: solution near (1, 2).
  Problem problem;
  problem.addBlock("x", 2);
  problem.x() << 1.0, 1.0;
  problem.addTerm(std::make_unique<ProductTerm>("product", 0, 1, 2.0), 1.0, Strength::Hard);
  Eigen::MatrixXd A(1, 2);
  A << 1, 0;
  problem.addTerm(std::make_unique<LinearRowsTerm>("anchor", A, Eigen::VectorXd::Ones(1)), 1e-3,
                  Strength::Soft);
  GuidedProjectionSolver solver(problem);
  SolverOptions options;
  options.maxIterations = 30;
  options.regularization = 1e-4;
  options.residualTolerance = -1.0;        // run all iterations
  options.relativeChangeTolerance = -1.0;
  const SolveSummary summary = solver.solve(options);
  EXPECT_NEAR(problem.x()[0] * problem.x()[1], 2.0, 1e-10);
  EXPECT_EQ(terminationReasonName(summary.reason), std::string("max_iterations"));
  ASSERT_EQ(summary.iterations.size(), 31u);
  EXPECT_LT(summary.iterations.back().hardResidual, 1e-20);
}

/// x0·x1 = c (hard) from x = (1, 1): one step, plain (no step control), with or without a
/// correction step. ε_reg keeps the system regular along (1, −1), where J = (1, 1) sees nothing.
SolveSummary oneProductStep(double c, int correctionSteps, Eigen::VectorXd& x) {
  Problem problem;
  problem.addBlock("x", 2);
  problem.x() << 1.0, 1.0;
  problem.addTerm(std::make_unique<ProductTerm>("product", 0, 1, c), 1.0, Strength::Hard);
  GuidedProjectionSolver solver(problem);
  SolverOptions options;
  options.maxIterations = 1;
  options.regularization = 1e-6;
  options.stepControl.enabled = false;
  options.correctionSteps = correctionSteps;
  SolveSummary summary = solver.solve(options);
  x = problem.x();
  return summary;
}

TEST(GuidedProjectionSolver, ACorrectionStepRemovesTheSecondOrderErrorALinearStepLeaves) {
  // x0·x1 = 1.02 from (1, 1), where J = (1, 1): the linear step δ meets δ0 + δ1 = 0.02 and leaves
  // r⁺ = δ0·δ1 (the quadratic part). The chord step δc from there, with the same J, meets
  // δc0 + δc1 = −r⁺ and leaves δ1·δc0 + δ0·δc1 + δc0·δc1: third order.
  Eigen::VectorXd plain, corrected;
  const SolveSummary a = oneProductStep(1.02, 0, plain);
  const SolveSummary b = oneProductStep(1.02, 1, corrected);
  const Eigen::Vector2d delta = plain - Eigen::Vector2d(1.0, 1.0), chord = corrected - plain;
  const double rPlus = plain[0] * plain[1] - 1.02, rCorrected = corrected[0] * corrected[1] - 1.02;
  EXPECT_NEAR(delta.sum(), 0.02, 1e-7);
  EXPECT_NEAR(rPlus, delta[0] * delta[1], 1e-7);
  EXPECT_GT(rPlus, 5e-5);
  EXPECT_NEAR(chord.sum(), -rPlus, 1e-9);
  // What is left is of third order: the chord's error against the Jacobian at the new iterate.
  EXPECT_LT(std::abs(rCorrected), 0.05 * rPlus);
  EXPECT_EQ(a.iterations[1].corrections, 0);
  EXPECT_EQ(b.iterations[1].corrections, 1);
  EXPECT_LT(b.iterations[1].hardResidual, 0.01 * a.iterations[1].hardResidual);
  // The record is the corrected iterate's: its residual and the length of the whole move.
  EXPECT_NEAR(b.iterations[1].hardResidual, rCorrected * rCorrected, 1e-15);
  EXPECT_NEAR(b.iterations[1].stepNorm, (corrected - Eigen::Vector2d(1.0, 1.0)).norm(), 1e-12);
}

TEST(GuidedProjectionSolver, ACorrectionThatWouldRaiseTheHardResidualIsNotKept) {
  // x0·x1 = 100 from (1, 1): the step overshoots far (r⁺ in the hundreds), and the chord step from
  // there, with the Jacobian of (1, 1), would overshoot the other way by more. It is undone: the
  // iterate is the plain step's.
  Eigen::VectorXd plain, corrected;
  const SolveSummary a = oneProductStep(100.0, 0, plain);
  const SolveSummary b = oneProductStep(100.0, 3, corrected);
  EXPECT_GT(plain[0] * plain[1] - 100.0, 100.0);
  EXPECT_EQ(b.iterations[1].corrections, 0);
  EXPECT_EQ(corrected, plain);
  EXPECT_EQ(b.iterations[1].hardResidual, a.iterations[1].hardResidual);
}

TEST(GuidedProjectionSolver, CorrectionStepsAreTheSameWithAndWithoutElimination) {
  // A correction through the elimination groups' factors (NormalEquations::correctionRhs) gives
  // the iterate of the same problem solved with nothing eliminated. One step: at this
  // regularization later steps amplify rounding differences (~1e-9 after four, with or without
  // corrections).
  Problem eliminated, full;
  testing::buildStripLike(eliminated, 5, 7, 3);
  testing::buildStripLike(full, 5, 7, 3);
  for (int b = 0; b < full.layout().numBlocks(); ++b) full.layout().setEliminable(b, 0);
  GuidedProjectionSolver s1(eliminated), s2(full);
  ASSERT_GT(NormalEquations(eliminated).numEliminated(), 0);
  SolverOptions options;
  options.maxIterations = 1;
  options.regularization = 0.01;  // (here the step's correction lowers the hard residual)
  options.residualTolerance = 0.0;
  options.relativeChangeTolerance = 0.0;
  options.correctionSteps = 1;
  const SolveSummary a = s1.solve(options);
  const SolveSummary b = s2.solve(options);
  ASSERT_EQ(a.stepsTaken(), 1);
  EXPECT_EQ(a.iterations[1].corrections, 1);
  EXPECT_EQ(b.iterations[1].corrections, 1);
  EXPECT_NEAR(a.iterations[1].totalResidual, b.iterations[1].totalResidual, 1e-10 * b.iterations[1].totalResidual);
  EXPECT_LT((eliminated.x() - full.x()).norm(), 1e-10 * full.x().norm());
}

TEST(GuidedProjectionSolver, FairnessWeightDecaysGeometrically) {
  Problem problem;
  problem.addBlock("x", 1);
  problem.addTerm(std::make_unique<LinearRowsTerm>("fair", Eigen::MatrixXd::Ones(1, 1),
                                                   Eigen::VectorXd::Zero(1)),
                  2.0, Strength::Soft, WeightSchedule::Fairness);
  GuidedProjectionSolver solver(problem);
  SolverOptions options;
  options.fairness = 0.5;
  options.fairnessDecay = 0.8;
  const std::vector<double> w3 = solver.effectiveWeights(options, 3);
  EXPECT_DOUBLE_EQ(w3[0], 2.0 * 0.5 * std::pow(0.8, 3));
}

TEST(GuidedProjectionSolver, SummaryRecordsEveryIterationWithTimesAndTermResiduals) {
  Problem problem = productProblem();
  GuidedProjectionSolver solver(problem);
  SolverOptions options;
  options.maxIterations = 4;
  options.residualTolerance = 0.0;
  options.relativeChangeTolerance = 0.0;
  const SolveSummary summary = solver.solve(options);
  ASSERT_EQ(summary.stepsTaken(), 4);
  EXPECT_EQ(summary.reason, TerminationReason::MaxIterations);
  EXPECT_EQ(summary.termNames, std::vector<std::string>{"product"});
  EXPECT_DOUBLE_EQ(summary.iterations[0].termResiduals[0], 4.0);  // (3·1 − 1)²
  for (int k = 1; k <= 4; ++k) {
    const IterationRecord& r = summary.iterations[k];
    EXPECT_EQ(r.iteration, k);
    EXPECT_GT(r.stepNorm, 0.0);
    EXPECT_GE(r.assemblyMs, 0.0);
    EXPECT_GE(r.totalMs, r.factorizationMs);
    EXPECT_LT(r.termResiduals[0], summary.iterations[k - 1].termResiduals[0]);
  }
}

// A term's per-iteration constants are taken at the initial state before it is measured: a point
// on its line has no hard residual at iteration 0, and the first step is judged against that (with
// the constructor's foot (0, 0) it measured 0.5, and step control let a step break the row by 0.4).
TEST(GuidedProjectionSolver, MeasuresTheInitialStateWithTheTermsConstantsTakenThere) {
  Problem problem;
  problem.addBlock("p", 2);
  problem.x() << 0.3, 0.5;
  problem.addTerm(std::make_unique<testing::LineFootTerm>("on the line", 0, 0.5), 1.0, Strength::Hard);
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(2, 2);
  problem.addTerm(std::make_unique<LinearRowsTerm>("pull", A, Eigen::Vector2d(0.9, 0.5)), 0.1, Strength::Soft);
  GuidedProjectionSolver solver(problem);
  SolverOptions options;
  options.maxIterations = 3;
  const SolveSummary summary = solver.solve(options);
  EXPECT_EQ(summary.iterations[0].hardResidual, 0.0);
  EXPECT_EQ(summary.iterations[0].hardResidualMax, 0.0);
  EXPECT_LT(std::abs(problem.x()[1] - 0.5), 1e-12);  // the point slid along its line
  EXPECT_GT(problem.x()[0], 0.3);
}

TEST(GuidedProjectionSolver, StopsOnResidualTolerance) {
  Problem problem;
  problem.addBlock("x", 1);
  problem.addTerm(std::make_unique<LinearRowsTerm>("t", Eigen::MatrixXd::Ones(1, 1),
                                                   Eigen::VectorXd::Ones(1)),
                  1.0, Strength::Hard);
  GuidedProjectionSolver solver(problem);
  SolverOptions options;
  options.maxIterations = 50;
  options.regularization = 1e-8;
  const SolveSummary summary = solver.solve(options);
  EXPECT_EQ(summary.reason, TerminationReason::ResidualTolerance);
  EXPECT_TRUE(summary.converged);
  EXPECT_LE(summary.stepsTaken(), 3);
}

/// Projection steps with a soft term that stays (as fairness does in a session's polish): the
/// hard row x = 0 against a constant pull toward x = 1 of weight √pull settles at x* = pull/(1 +
/// pull), so the largest hard row stops falling at x*.
Problem heldAboveTheTolerance(double pull) {
  Problem problem;
  problem.addBlock("x", 1);
  problem.x() << 0.5;
  problem.addTerm(std::make_unique<LinearRowsTerm>("hard", Eigen::MatrixXd::Ones(1, 1), Eigen::VectorXd::Zero(1)),
                  1.0, Strength::Hard);
  problem.addTerm(std::make_unique<LinearRowsTerm>("pull", Eigen::MatrixXd::Ones(1, 1), Eigen::VectorXd::Ones(1)),
                  std::sqrt(pull), Strength::Soft);
  return problem;
}

SolverOptions polishOptions() {
  SolverOptions options;
  options.maxIterations = 200;
  options.projectionOnly = true;
  options.hardTolerance = 1e-7;
  options.regularization = 1.0;  // each step halves the distance to x*
  options.residualTolerance = -1.0;
  options.relativeChangeTolerance = -1.0;
  return options;
}

TEST(GuidedProjectionSolver, APolishHeldJustAboveTheHardToleranceStopsOnItsPlateau) {
  Problem problem = heldAboveTheTolerance(2e-7);
  GuidedProjectionSolver solver(problem);
  const SolveSummary summary = solver.solve(polishOptions());
  EXPECT_EQ(terminationReasonName(summary.reason), std::string("hard_plateau"));
  EXPECT_TRUE(summary.converged);
  EXPECT_LT(summary.stepsTaken(), 60);
  EXPECT_NEAR(problem.x()[0], 2e-7 / (1 + 2e-7), 1e-9);
  EXPECT_GT(summary.iterations.back().hardResidualMax, 1e-7);
}

TEST(GuidedProjectionSolver, APolishFarAboveTheToleranceOrWithThePlateauOffRunsOn) {
  {  // x* = 1e-5: a hundred tolerances, beyond the plateau's range of ten
    Problem problem = heldAboveTheTolerance(1e-5);
    GuidedProjectionSolver solver(problem);
    EXPECT_EQ(terminationReasonName(solver.solve(polishOptions()).reason), std::string("max_iterations"));
  }
  {
    Problem problem = heldAboveTheTolerance(2e-7);
    GuidedProjectionSolver solver(problem);
    SolverOptions options = polishOptions();
    options.hardPlateau.steps = 0;
    EXPECT_EQ(terminationReasonName(solver.solve(options).reason), std::string("max_iterations"));
  }
  {  // not a projection-only solve: the rule does not apply
    Problem problem = heldAboveTheTolerance(2e-7);
    GuidedProjectionSolver solver(problem);
    SolverOptions options = polishOptions();
    options.projectionOnly = false;
    EXPECT_EQ(terminationReasonName(solver.solve(options).reason), std::string("max_iterations"));
  }
}

/// heldAboveTheTolerance with a second block b that alternates (hard row b = 0 from b = 0.5): the
/// polish holds x at x* = pull/(1 + pull) while b reaches its row.
Problem heldAboveTheToleranceWithAnAlternatingSide(double pull) {
  Problem problem;
  problem.addBlock("x", 1);
  const int b = problem.addBlock("b", 1);
  problem.layout().setAlternating(b);
  problem.x() << 0.5, 0.5;
  using Row = testing::SparseLinearTerm::Row;
  problem.addTerm(std::make_unique<testing::SparseLinearTerm>("hard", std::vector<Row>{{{{0, 1.0}}, 0.0}, {{{1, 1.0}}, 0.0}}),
                  1.0, Strength::Hard);
  problem.addTerm(std::make_unique<testing::SparseLinearTerm>("pull", std::vector<Row>{{{{0, 1.0}}, 1.0}}), std::sqrt(pull),
                  Strength::Soft);
  return problem;
}

TEST(GuidedProjectionSolver, AnAlternatingPolishHeldFarAboveTheToleranceStopsOnItsPlateauWithinItsWiderRange) {
  for (double held : {5e-6, 8e-6}) {  // 50 and 80 tolerances (the annulus's development rows): within it
    Problem problem = heldAboveTheToleranceWithAnAlternatingSide(held);
    GuidedProjectionSolver solver(problem);
    ASSERT_TRUE(solver.alternates());
    const SolveSummary summary = solver.solve(polishOptions());
    EXPECT_EQ(terminationReasonName(summary.reason), std::string("hard_plateau")) << held;
    EXPECT_LT(summary.stepsTaken(), 80) << held;
    EXPECT_NEAR(problem.x()[0], held / (1 + held), 1e-8) << held;
    EXPECT_LT(std::abs(problem.x()[1]), 1e-7) << held;
  }
  for (double held : {3e-5, 2e-3}) {  // 300 tolerances (a stall a release got out of), 20 000: beyond it
    Problem problem = heldAboveTheToleranceWithAnAlternatingSide(held);
    GuidedProjectionSolver solver(problem);
    EXPECT_EQ(terminationReasonName(solver.solve(polishOptions()).reason), std::string("max_iterations")) << held;
  }
}

TEST(GuidedProjectionSolver, CallbackCanAbortTheSolve) {
  Problem problem = productProblem();
  GuidedProjectionSolver solver(problem);
  SolverOptions options;
  options.maxIterations = 20;
  int calls = 0;
  options.callback = [&calls](const IterationRecord& r) { return ++calls < 3; };
  const SolveSummary summary = solver.solve(options);
  EXPECT_EQ(summary.reason, TerminationReason::Aborted);
  EXPECT_EQ(calls, 3);  // iteration 0, 1 and 2
  EXPECT_EQ(summary.stepsTaken(), 2);
}

TEST(GuidedProjectionSolver, WithoutStepControlADivergingStepRestoresThePreviousIterate) {
  // sqrt(x) − 1 from x = 9: the Newton step δ = −2/(1/6) = −12 lands at x = −3 (NaN residual).
  Problem problem;
  problem.addBlock("x", 1);
  problem.x() << 9.0;
  problem.addTerm(std::make_unique<SqrtTerm>("sqrt"), 1.0, Strength::Hard);
  GuidedProjectionSolver solver(problem);
  SolverOptions options;
  options.regularization = 0.0;
  options.stepControl.enabled = false;
  const SolveSummary summary = solver.solve(options);
  EXPECT_EQ(summary.reason, TerminationReason::Diverged);
  EXPECT_FALSE(summary.converged);
  EXPECT_EQ(problem.x()[0], 9.0);
  EXPECT_EQ(summary.stepsTaken(), 0);
}

TEST(GuidedProjectionSolver, StopsWhenTheTimeBudgetRunsOut) {
  Problem problem = productProblem();
  GuidedProjectionSolver solver(problem);
  SolverOptions options;
  options.maxIterations = 1000000;
  options.residualTolerance = -1.0;          // never satisfied
  options.relativeChangeTolerance = -1.0;    // never satisfied
  options.timeBudgetMs = 1e-9;               // any positive budget ends after one step
  const SolveSummary summary = solver.solve(options);
  EXPECT_EQ(summary.reason, TerminationReason::TimeBudget);
  EXPECT_EQ(summary.stepsTaken(), 1);
}

/// Six steps of productProblem() with a 60 ms budget on `clock`, each iteration's callback sleeping
/// 40 ms (the thread off the CPU, as under a busy machine's load; one step of this problem costs
/// microseconds); `wallCapMs` > 0 caps a CPU-clock budget's wall time.
SolveSummary solveSleepingIterations(BudgetClock clock, double wallCapMs = 0.0) {
  Problem problem = productProblem();
  GuidedProjectionSolver solver(problem);
  SolverOptions options;
  options.maxIterations = 6;
  options.residualTolerance = -1.0;
  options.relativeChangeTolerance = -1.0;
  options.timeBudgetMs = 60.0;
  options.budgetClock = clock;
  options.budgetWallCapMs = wallCapMs;
  options.callback = [](const IterationRecord&) {
    std::this_thread::sleep_for(std::chrono::milliseconds(40));
    return true;
  };
  return solver.solve(options);
}

TEST(GuidedProjectionSolver, ABudgetOnTheThreadsCpuClockIgnoresTimeTheThreadSpentWaiting) {
  // A 60 ms wall-clock budget ends the solve after its first step (iteration 0 and step 1 slept
  // 80 ms); the same budget on the thread's CPU clock runs all six.
  const SolveSummary wall = solveSleepingIterations(BudgetClock::Wall);
  EXPECT_EQ(wall.reason, TerminationReason::TimeBudget);
  EXPECT_EQ(wall.stepsTaken(), 1);
  const SolveSummary cpu = solveSleepingIterations(BudgetClock::ThreadCpu);
  EXPECT_EQ(cpu.reason, TerminationReason::MaxIterations);
  EXPECT_EQ(cpu.stepsTaken(), 6);
}

TEST(GuidedProjectionSolver, ABudgetOnTheThreadsCpuClockStillEndsAtItsWallClockCap) {
  // With a wall-clock cap of 100 ms: iteration 0 and two steps have slept 120 ms when the cap is
  // checked after step 2.
  const SolveSummary summary = solveSleepingIterations(BudgetClock::ThreadCpu, 100.0);
  EXPECT_EQ(summary.reason, TerminationReason::TimeBudget);
  EXPECT_EQ(summary.stepsTaken(), 2);
}

TEST(GuidedProjectionSolver, StopsWhenTheObjectiveNoLongerChanges) {
  // An inconsistent pair of targets: the objective settles at a positive value.
  Problem problem;
  problem.addBlock("x", 1);
  Eigen::MatrixXd A(2, 1);
  A << 1, 1;
  problem.addTerm(std::make_unique<LinearRowsTerm>("targets", A, Eigen::Vector2d(0, 2)), 1.0,
                  Strength::Hard);
  GuidedProjectionSolver solver(problem);
  SolverOptions options;
  options.maxIterations = 100;
  options.relativeChangeTolerance = 1e-9;
  const SolveSummary summary = solver.solve(options);
  EXPECT_EQ(summary.reason, TerminationReason::RelativeChange);
  EXPECT_NEAR(problem.x()[0], 1.0, 1e-6);
}

TEST(GuidedProjectionSolver, CholmodAndLdltTakeTheSameStep) {
  if (!cholmodAvailable()) GTEST_SKIP() << "CHOLMOD not compiled in";
  auto build = [](Problem& p) {
    p.addBlock("x", 3);
    p.x() << 0.5, 2.0, -1.0;
    p.addTerm(std::make_unique<ProductTerm>("p01", 0, 1, 1.0), 1.0, Strength::Hard);
    p.addTerm(std::make_unique<ProductTerm>("p12", 1, 2, -3.0), 1.0, Strength::Hard);
  };
  Problem p1, p2;
  build(p1);
  build(p2);
  GuidedProjectionSolver s1(p1, LinearSolverKind::SimplicialLDLT);
  GuidedProjectionSolver s2(p2, LinearSolverKind::Cholmod);
  SolverOptions options;
  options.maxIterations = 3;
  s1.solve(options);
  s2.solve(options);
  EXPECT_LT((p1.x() - p2.x()).norm(), 1e-12);
}

/// Eliminating the normals (Schur complement) is exact: the iterates, step norms and residuals
/// are those of the solver that factors all of H, with either linear solver.
TEST(GuidedProjectionSolver, EliminationLeavesTheIteratesUnchanged) {
  std::vector<LinearSolverKind> kinds{LinearSolverKind::SimplicialLDLT};
  if (cholmodAvailable()) kinds.push_back(LinearSolverKind::Cholmod);
  for (LinearSolverKind kind : kinds) {
    Problem eliminated, full;
    testing::buildStripLike(eliminated, 5, 7, 3);
    testing::buildStripLike(full, 5, 7, 3);
    for (int b = 0; b < full.layout().numBlocks(); ++b) full.layout().setEliminable(b, 0);
    GuidedProjectionSolver s1(eliminated, kind);
    GuidedProjectionSolver s2(full, kind);
    EXPECT_EQ(s1.numFree(), s2.numFree());
    EXPECT_EQ(s1.normalMatrixNonZeros(), s2.normalMatrixNonZeros());
    SolverOptions options;
    options.maxIterations = 6;
    options.regularization = 0.1;  // a converging run (rounding differences stay at ~1e-12)
    options.residualTolerance = 0.0;
    options.relativeChangeTolerance = 0.0;
    const SolveSummary a = s1.solve(options);
    const SolveSummary b = s2.solve(options);
    ASSERT_EQ(a.stepsTaken(), 6);
    ASSERT_EQ(b.stepsTaken(), 6);
    EXPECT_LT((eliminated.x() - full.x()).norm(), 1e-9 * full.x().norm());
    for (int k = 1; k <= 6; ++k) {
      EXPECT_NEAR(a.iterations[k].stepNorm, b.iterations[k].stepNorm,
                  1e-9 * (1.0 + b.iterations[k].stepNorm));
      EXPECT_NEAR(a.iterations[k].totalResidual, b.iterations[k].totalResidual,
                  1e-9 * (1e-12 + b.iterations[k].totalResidual));
    }
    EXPECT_LT(a.iterations[6].hardResidual, a.iterations[0].hardResidual);
  }
}

/// Keeping the evaluation that judged a step for the next assembly (SolverOptions::
/// keepEvaluations) changes no iterate — with corrections, with an alternating block (which moves
/// x after the evaluation: the next assembly is elsewhere) and over a second solve — and
/// evaluates the terms that evaluate from x alone once per iteration instead of twice.
TEST(GuidedProjectionSolver, KeptEvaluationsChangeNoIterateAndSaveAnEvaluationPerIteration) {
  struct Case {
    int corrections;
    bool alternating;
  };
  for (const Case c : {Case{0, false}, Case{1, false}, Case{0, true}}) {
    const int corrections = c.corrections;
    Problem kept, plain;
    testing::buildStripLike(kept, 5, 7, 3);
    testing::buildStripLike(plain, 5, 7, 3);
    if (c.alternating)
      for (Problem* p : {&kept, &plain}) {
        const int normals = p->layout().blockId("normals");
        p->layout().setEliminable(normals, 0);
        p->layout().setAlternating(normals);
      }
    auto everyOther = [](int t) { return t % 2 == 0; };
    const std::vector<testing::ForwardingTerm*> a = testing::forwardTerms(kept, everyOther);
    const std::vector<testing::ForwardingTerm*> b = testing::forwardTerms(plain, everyOther);
    GuidedProjectionSolver s1(kept, LinearSolverKind::SimplicialLDLT);
    GuidedProjectionSolver s2(plain, LinearSolverKind::SimplicialLDLT);
    SolverOptions options;
    options.maxIterations = 8;
    options.regularization = 1e-4;  // long first steps: step control shortens some
    options.residualTolerance = 0.0;
    options.relativeChangeTolerance = 0.0;
    options.correctionSteps = corrections;
    SolverOptions without = options;
    without.keepEvaluations = false;
    for (int solve = 0; solve < 2; ++solve) {
      const SolveSummary sa = s1.solve(options);
      const SolveSummary sb = s2.solve(without);
      ASSERT_EQ(sa.iterations.size(), sb.iterations.size());
      for (std::size_t k = 0; k < sa.iterations.size(); ++k) {
        EXPECT_EQ(sa.iterations[k].totalResidual, sb.iterations[k].totalResidual) << k;
        EXPECT_EQ(sa.iterations[k].stepScale, sb.iterations[k].stepScale) << k;
        EXPECT_EQ(sa.iterations[k].corrections, sb.iterations[k].corrections) << k;
      }
      EXPECT_EQ(std::memcmp(kept.x().data(), plain.x().data(), sizeof(double) * kept.x().size()), 0)
          << "solve " << solve << ", corrections " << corrections;
      kept.x()[7] += 0.05;  // the next solve starts elsewhere
      plain.x()[7] += 0.05;
    }
    int evaluationsKept = 0, evaluationsPlain = 0;
    for (int t = 0; t < kept.numTerms(); t += 2) {
      // Its residual-only evaluations: the corrections' right-hand sides, the alternating side's
      // step control.
      if (corrections == 0 && !c.alternating) EXPECT_EQ(a[t]->residualOnly, 0) << "a term evaluated from x alone keeps its Jacobian";
      evaluationsKept += a[t]->withJacobian + a[t]->residualOnly;
      evaluationsPlain += b[t]->withJacobian + b[t]->residualOnly;
    }
    // Two solves of 8 iterations: at least one evaluation per term and iteration saved (not with
    // the alternation, whose step moves x after the evaluation).
    if (!c.alternating)
      EXPECT_LE(evaluationsKept, evaluationsPlain - 16 * static_cast<int>(a.size() + 1) / 2)
          << evaluationsKept << " against " << evaluationsPlain << ", corrections " << corrections;
  }
}

/// Reusing the first factorization (CG preconditioned with it) takes the steps of a solver that
/// factorizes every iteration, with one factorization per solve(); the next solve() factorizes
/// again first.
TEST(GuidedProjectionSolver, FactorizationReuseTakesTheSameStepsWithOneFactorization) {
  std::vector<LinearSolverKind> kinds{LinearSolverKind::SimplicialLDLT};
  if (cholmodAvailable()) kinds.push_back(LinearSolverKind::Cholmod);
  for (LinearSolverKind kind : kinds) {
    Problem reusing, factorizing;
    testing::buildStripLike(reusing, 5, 7, 3);
    testing::buildStripLike(factorizing, 5, 7, 3);
    GuidedProjectionSolver s1(reusing, kind);
    GuidedProjectionSolver s2(factorizing, kind);
    SolverOptions options;
    options.maxIterations = 6;
    options.regularization = 0.1;
    options.residualTolerance = 0.0;
    options.relativeChangeTolerance = 0.0;
    const SolveSummary b = s2.solve(options);
    options.factorizationReuse.maxAge = 10;
    options.factorizationReuse.maxIterations = 100;
    options.factorizationReuse.tolerance = 1e-13;
    const SolveSummary a = s1.solve(options);
    ASSERT_EQ(a.stepsTaken(), 6);
    ASSERT_EQ(b.stepsTaken(), 6);
    EXPECT_LT((reusing.x() - factorizing.x()).norm(), 1e-9 * factorizing.x().norm());
    for (int k = 1; k <= 6; ++k) {
      EXPECT_NEAR(a.iterations[k].stepNorm, b.iterations[k].stepNorm, 1e-9 * (1.0 + b.iterations[k].stepNorm));
      EXPECT_TRUE(b.iterations[k].factorized);
      EXPECT_EQ(b.iterations[k].pcgIterations, 0);
      EXPECT_EQ(a.iterations[k].factorized, k == 1) << "iteration " << k;
      if (k > 1) EXPECT_GE(a.iterations[k].pcgIterations, 1) << "iteration " << k;
    }
    const SolveSummary again = s1.solve(options);
    ASSERT_GE(again.iterations.size(), 2u);
    EXPECT_TRUE(again.iterations[1].factorized);
    EXPECT_EQ(again.iterations[1].pcgIterations, 0);
  }
}

/// When CG does not reach the tolerance within its iterations, the matrix is factorized after all:
/// the steps are still the factorizing solver's.
TEST(GuidedProjectionSolver, FactorizationReuseFactorizesWhenCgGivesUp) {
  Problem reusing, factorizing;
  testing::buildStripLike(reusing, 5, 7, 3);
  testing::buildStripLike(factorizing, 5, 7, 3);
  GuidedProjectionSolver s1(reusing);
  GuidedProjectionSolver s2(factorizing);
  SolverOptions options;
  options.maxIterations = 4;
  options.regularization = 0.1;
  options.residualTolerance = 0.0;
  options.relativeChangeTolerance = 0.0;
  const SolveSummary b = s2.solve(options);
  options.factorizationReuse.maxAge = 10;
  options.factorizationReuse.maxIterations = 0;  // only the start (one preconditioned solve)
  options.factorizationReuse.tolerance = 1e-300;
  const SolveSummary a = s1.solve(options);
  ASSERT_EQ(a.stepsTaken(), 4);
  EXPECT_LT((reusing.x() - factorizing.x()).norm(), 1e-12 * factorizing.x().norm());
  for (int k = 1; k <= 4; ++k) {
    EXPECT_TRUE(a.iterations[k].factorized) << "iteration " << k;
    EXPECT_EQ(a.iterations[k].pcgIterations, k == 1 ? 0 : 1) << "iteration " << k;
  }
}

/// Random rows A (rows × cols) and targets y, entries in [−1, 1].
void randomRows(std::mt19937& rng, int rows, int cols, Eigen::MatrixXd& A, Eigen::VectorXd& y) {
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  A.resize(rows, cols);
  y.resize(rows);
  for (int i = 0; i < rows; ++i) {
    y[i] = uni(rng);
    for (int j = 0; j < cols; ++j) A(i, j) = uni(rng);
  }
}

/// Linear rows over a (2 scalars) and b (2, alternating): one iteration is the least-squares
/// solution over a with b held, then over b with the new a held (block Gauss–Seidel), exactly.
TEST(GuidedProjectionSolver, AnAlternatingIterationStepsEachSideWithTheOtherHeld) {
  Problem problem;
  problem.addBlock("a", 2);
  const int b = problem.addBlock("b", 2);
  problem.layout().setAlternating(b);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  Eigen::MatrixXd A;
  Eigen::VectorXd y;
  randomRows(rng, 6, 4, A, y);
  for (int i = 0; i < 4; ++i) problem.x()[i] = uni(rng);
  const Eigen::Vector2d b0 = problem.x().tail<2>();
  problem.addTerm(std::make_unique<LinearRowsTerm>("rows", A, y), 1.0, Strength::Hard);
  GuidedProjectionSolver solver(problem);
  EXPECT_TRUE(solver.alternates());
  EXPECT_EQ(solver.numFree(), 4);
  SolverOptions options;
  options.maxIterations = 1;
  options.regularization = 0.0;
  options.stepControl.enabled = false;
  const SolveSummary summary = solver.solve(options);
  ASSERT_EQ(summary.stepsTaken(), 1);
  EXPECT_EQ(summary.iterations[1].alternatingStepScale, 1.0);
  const Eigen::MatrixXd Aa = A.leftCols(2), Ab = A.rightCols(2);
  const Eigen::Vector2d a1 = (Aa.transpose() * Aa).ldlt().solve(Aa.transpose() * (y - Ab * b0));
  const Eigen::Vector2d b1 = (Ab.transpose() * Ab).ldlt().solve(Ab.transpose() * (y - Aa * a1));
  EXPECT_LT((problem.x().head<2>() - a1).norm(), 1e-12);
  EXPECT_LT((problem.x().tail<2>() - b1).norm(), 1e-12);
}

/// a0·b0 = 2, a1 + b1 = 3, a0 = 1, b1 = 1 (hard; one solution): alternating and coupled solves
/// both reach it, with step control as a session runs it. Alternation converges linearly, at a
/// rate the coupling sets: here a0 ← (2 b0 + 1)/(b0² + 1), b0 ← 2/a0, whose derivative at the
/// solution is 0.8 — 109 iterations to 1e-8 where the coupled Gauss–Newton takes 3.
TEST(GuidedProjectionSolver, AlternatingAndCoupledSolvesReachTheSameSolution) {
  int coupledSteps = 0;
  for (const bool alternate : {false, true}) {
    Problem problem;
    problem.addBlock("a", 2);
    const int b = problem.addBlock("b", 2);
    if (alternate) problem.layout().setAlternating(b);
    problem.x() << 2.0, 0.5, 0.5, 0.2;
    using Row = testing::SparseLinearTerm::Row;
    problem.addTerm(std::make_unique<ProductTerm>("product", 0, 2, 2.0), 1.0, Strength::Hard);
    problem.addTerm(std::make_unique<testing::SparseLinearTerm>(
                        "linear", std::vector<Row>{{{{1, 1.0}, {3, 1.0}}, 3.0}, {{{0, 1.0}}, 1.0}, {{{3, 1.0}}, 1.0}}),
                    1.0, Strength::Hard);
    GuidedProjectionSolver solver(problem);
    EXPECT_EQ(solver.alternates(), alternate);
    SolverOptions options;
    options.maxIterations = 400;
    options.regularization = 1e-3;
    options.residualTolerance = 1e-22;
    options.relativeChangeTolerance = 0.0;
    const SolveSummary summary = solver.solve(options);
    EXPECT_TRUE(summary.converged) << (alternate ? "alternating" : "coupled");
    EXPECT_LT((problem.x() - Eigen::Vector4d(1.0, 2.0, 2.0, 1.0)).norm(), 1e-8) << (alternate ? "alternating" : "coupled");
    if (!alternate) coupledSteps = summary.stepsTaken();
    else EXPECT_GT(summary.stepsTaken(), 4 * coupledSteps) << "block Gauss–Seidel converges linearly";
  }
}

/// The alternating side's factorization is reused across iterations and solves (CG preconditioned
/// with it) where its matrix changes little — here rows linear in the alternating block, so CG
/// needs one correction — and the iterates are the factorizing solver's up to CG's tolerance.
TEST(GuidedProjectionSolver, TheAlternatingSideReusesItsFactorizationAndTakesTheSameSteps) {
  auto build = [](Problem& problem) {
    problem.addBlock("a", 2);
    const int b = problem.addBlock("b", 3);
    problem.layout().setAlternating(b);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> uni(-1.0, 1.0);
    Eigen::MatrixXd A;
    Eigen::VectorXd y;
    randomRows(rng, 6, 5, A, y);
    for (int i = 0; i < 5; ++i) problem.x()[i] = 1.0 + 0.5 * uni(rng);
    problem.addTerm(std::make_unique<LinearRowsTerm>("rows", A, y), 0.5, Strength::Soft);
    problem.addTerm(std::make_unique<ProductTerm>("product", 0, 1, 2.0), 1.0, Strength::Hard);
  };
  Problem reusing, factorizing;
  build(reusing);
  build(factorizing);
  GuidedProjectionSolver s1(reusing), s2(factorizing);
  ASSERT_TRUE(s1.alternates());
  SolverOptions options;
  options.maxIterations = 6;
  options.regularization = 0.1;
  options.residualTolerance = 0.0;
  options.relativeChangeTolerance = 0.0;
  options.alternatingReuse.maxAge = 0;
  const SolveSummary b = s2.solve(options);
  options.alternatingReuse = {10, 100, 1e-13};
  const SolveSummary a = s1.solve(options);
  ASSERT_EQ(a.stepsTaken(), 6);
  ASSERT_EQ(b.stepsTaken(), 6);
  EXPECT_LT((reusing.x() - factorizing.x()).norm(), 1e-9 * factorizing.x().norm());
  for (int k = 1; k <= 6; ++k) {
    EXPECT_EQ(b.iterations[k].pcgIterations, 0);
    EXPECT_TRUE(b.iterations[k].alternatingFactorized) << "iteration " << k;
    EXPECT_EQ(a.iterations[k].alternatingFactorized, k == 1) << "iteration " << k << ": CG with the first factorization";
    if (k > 1) EXPECT_GE(a.iterations[k].pcgIterations, 1) << "iteration " << k;
  }
  const SolveSummary again = s1.solve(options);  // a later solve goes on with the same factorization
  ASSERT_GE(again.iterations.size(), 2u);
  EXPECT_FALSE(again.iterations[1].alternatingFactorized);
}

/// Where CG does not converge with the earlier factorization (the strip-like toy's normals turn
/// far from step to step), the alternating side is factorized after all: the same steps.
TEST(GuidedProjectionSolver, TheAlternatingSideFactorizesWhenCgGivesUp) {
  Problem reusing, factorizing;
  testing::buildStripLike(reusing, 5, 7, 3);
  testing::buildStripLike(factorizing, 5, 7, 3);
  for (Problem* p : {&reusing, &factorizing}) {  // the normals alternate, kept in their system
    const int normals = p->layout().blockId("normals");
    p->layout().setEliminable(normals, 0);
    p->layout().setAlternating(normals);
  }
  GuidedProjectionSolver s1(reusing), s2(factorizing);
  SolverOptions options;
  options.maxIterations = 4;
  options.regularization = 0.1;
  options.residualTolerance = 0.0;
  options.relativeChangeTolerance = 0.0;
  options.alternatingReuse.maxAge = 0;
  s2.solve(options);
  options.alternatingReuse = {10, 2, 1e-13};
  const SolveSummary a = s1.solve(options);
  ASSERT_EQ(a.stepsTaken(), 4);
  EXPECT_LT((reusing.x() - factorizing.x()).norm(), 1e-12 * factorizing.x().norm());
  for (int k = 1; k <= 4; ++k) {
    EXPECT_TRUE(a.iterations[k].alternatingFactorized) << "iteration " << k;
    EXPECT_EQ(a.iterations[k].pcgIterations, k == 1 ? 0 : 3) << "iteration " << k << ": the start and two CG solves";
  }
}

/// A problem whose free scalars all alternate has nothing to alternate with: one system.
TEST(GuidedProjectionSolver, AlternationNeedsFreeScalarsOnBothSides) {
  Problem problem = productProblem();
  problem.layout().setAlternating(0);
  GuidedProjectionSolver solver(problem);
  EXPECT_FALSE(solver.alternates());
  EXPECT_EQ(solver.numFree(), 2);
  SolverOptions options;
  options.maxIterations = 30;
  options.regularization = 1e-4;
  EXPECT_TRUE(solver.solve(options).converged);
  EXPECT_NEAR(problem.x()[0] * problem.x()[1], 1.0, 1e-6);
}

/// x0·x1 = 1 has one row touching both variables: both are eliminated as one group and the
/// linear solver sees an empty system.
TEST(GuidedProjectionSolver, AnEmptyReducedSystemWorksWithEitherSolver) {
  std::vector<LinearSolverKind> kinds{LinearSolverKind::SimplicialLDLT};
  if (cholmodAvailable()) kinds.push_back(LinearSolverKind::Cholmod);
  for (LinearSolverKind kind : kinds) {
    Problem problem = productProblem();
    GuidedProjectionSolver solver(problem, kind);
    EXPECT_EQ(solver.numFree(), 2);
    SolverOptions options;
    options.maxIterations = 30;
    options.regularization = 1e-4;
    const SolveSummary summary = solver.solve(options);
    EXPECT_TRUE(summary.converged);
    EXPECT_NEAR(problem.x()[0] * problem.x()[1], 1.0, 1e-6);
  }
}

}  // namespace
}  // namespace devsurf::engine
