#include "devsurf/engine/Deadline.h"

#include <gtest/gtest.h>

#include <string>
#include <thread>

#include "devsurf/engine/GuidedProjectionSolver.h"
#include "solver/engine/TestProblems.h"

namespace devsurf::engine {
namespace {

TEST(Deadline, TheDefaultAndANonPositiveBudgetNeverExpire) {
  EXPECT_FALSE(Deadline().expired());
  EXPECT_NO_THROW(Deadline().check());
  EXPECT_FALSE(Deadline().bounded());
  EXPECT_FALSE(Deadline::after(0.0).bounded());
  EXPECT_FALSE(Deadline::after(-5.0).expired());
}

TEST(Deadline, ABudgetThatRanOutThrowsNamingTheBudgetAndItsSize) {
  const Deadline d = Deadline::after(1.0, "the job's time limit");
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_TRUE(d.expired());
  try {
    d.check();
    FAIL() << "no DeadlineExceeded";
  } catch (const DeadlineExceeded& e) {
    EXPECT_EQ(std::string(e.what()), "the job's time limit of 1 ms was exceeded");
    EXPECT_EQ(e.budgetMs(), 1.0);
    EXPECT_FALSE(e.cancelled());
  }
}

TEST(Deadline, ACancelFlagStopsTheWorkBeforeItsTime) {
  auto flag = std::make_shared<std::atomic<bool>>(false);
  const Deadline d = Deadline::after(60000.0).withCancelFlag(flag);
  EXPECT_NO_THROW(d.check());
  flag->store(true);
  try {
    d.check();
    FAIL() << "no DeadlineExceeded";
  } catch (const DeadlineExceeded& e) {
    EXPECT_TRUE(e.cancelled());
  }
}

TEST(Deadline, AGuidedProjectionSolvePastItsDeadlineThrowsAndKeepsTheLastIterate) {
  Problem problem;
  testing::buildStripLike(problem, 10, 7, 3);
  GuidedProjectionSolver solver(problem);
  const Eigen::VectorXd start = problem.x();
  SolverOptions options;
  options.maxIterations = 50;
  auto cancelled = std::make_shared<std::atomic<bool>>(true);
  options.deadline = Deadline().withCancelFlag(cancelled);
  EXPECT_THROW(solver.solve(options), DeadlineExceeded);
  EXPECT_EQ(problem.x(), start);  // checked before the first step
  cancelled->store(false);
  EXPECT_NO_THROW(solver.solve(options));
}

TEST(Deadline, BuildingASolverPastItsDeadlineThrows) {
  Problem problem;
  testing::buildStripLike(problem, 10, 7, 3);
  auto cancelled = std::make_shared<std::atomic<bool>>(true);
  EXPECT_THROW(GuidedProjectionSolver(problem, LinearSolverKind::SimplicialLDLT,
                                      Deadline().withCancelFlag(cancelled)),
               DeadlineExceeded);
}

}  // namespace
}  // namespace devsurf::engine
