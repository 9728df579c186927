// Nothing allocates inside the iteration loop of GuidedProjectionSolver::solve (ARCHITECTURE §3).
//
// This executable interposes malloc/calloc/realloc (glibc) to count heap allocations; Eigen and
// operator new both allocate through them. The callback reads the counter after every iteration.

#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>
#include <vector>

#include "devsurf/engine/GuidedProjectionSolver.h"
#include "solver/engine/TestProblems.h"

#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)
#define DEVSURF_COUNT_ALLOCATIONS 1
namespace {
std::atomic<long> allocations{0};
}
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* malloc(std::size_t n) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}
}
#endif

namespace devsurf::engine {
namespace {

TEST(GuidedProjectionSolver, TheIterationLoopDoesNotAllocate) {
#ifndef DEVSURF_COUNT_ALLOCATIONS
  GTEST_SKIP() << "allocation counting needs glibc";
#else
  std::vector<LinearSolverKind> kinds{LinearSolverKind::SimplicialLDLT};
  if (cholmodAvailable()) kinds.push_back(LinearSolverKind::Cholmod);
  for (LinearSolverKind kind : kinds) {
    for (bool eliminate : {true, false}) {
      Problem problem;
      testing::buildStripLike(problem, 20, 7, 9);
      if (!eliminate)
        for (int b = 0; b < problem.layout().numBlocks(); ++b) problem.layout().setEliminable(b, 0);
      GuidedProjectionSolver solver(problem, kind);
      constexpr int kIterations = 5;
      std::vector<long> counts;
      counts.reserve(kIterations + 1);
      SolverOptions options;
      options.maxIterations = kIterations;
      options.residualTolerance = 0.0;
      options.relativeChangeTolerance = 0.0;
      options.callback = [&counts](const IterationRecord&) {
        counts.push_back(allocations.load(std::memory_order_relaxed));
        return true;
      };
      const SolveSummary summary = solver.solve(options);
      ASSERT_EQ(summary.stepsTaken(), kIterations);
      ASSERT_EQ(static_cast<int>(counts.size()), kIterations + 1);
      // CHOLMOD allocates the numeric storage of its factor in the first factorization (its
      // solve workspaces are sized in analyzePattern); from then on nothing allocates.
      const int first = kind == LinearSolverKind::Cholmod ? 2 : 1;
      for (int k = first; k <= kIterations; ++k)
        EXPECT_EQ(counts[k] - counts[k - 1], 0)
            << "iteration " << k << " allocated (solver " << solver.linearSolverName()
            << ", elimination " << eliminate << ")";
    }
  }
#endif
}

}  // namespace
}  // namespace devsurf::engine
