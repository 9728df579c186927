#include "devsurf/engine/LinearSolver.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <atomic>
#include <filesystem>
#include <iterator>
#include <thread>
#include <vector>

namespace devsurf::engine {
namespace {

std::vector<LinearSolverKind> availableKinds() {
  std::vector<LinearSolverKind> kinds{LinearSolverKind::SimplicialLDLT, LinearSolverKind::Auto};
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

/// The 2D Laplacian of a k×k grid (5-point stencil, shifted to be positive definite): the
/// pattern of a sheet, whose LDLT fill grows like k³.
SymmetricUpper gridLaplacian(int k) {
  std::vector<Eigen::Triplet<double, int>> t;
  auto id = [k](int i, int j) { return i * k + j; };
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      t.emplace_back(id(i, j), id(i, j), 4.1);
      if (i + 1 < k) t.emplace_back(id(i, j), id(i + 1, j), -1.0);
      if (j + 1 < k) t.emplace_back(id(i, j), id(i, j + 1), -1.0);
    }
  SymmetricUpper upper(k * k, k * k);
  upper.setFromTriplets(t.begin(), t.end());
  upper.makeCompressed();
  return upper;
}

TEST(LinearSolver, MultiplyAddsCountTheFillOfLExactly) {
  // Tridiagonal: L has one entry below the diagonal per column but the last: Σ c² = n − 1.
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(6, 6);
  for (int i = 0; i < 6; ++i) {
    A(i, i) = 4.0;
    if (i + 1 < 6) A(i, i + 1) = A(i + 1, i) = -1.0;
  }
  EXPECT_DOUBLE_EQ(ldltMultiplyAdds(upperOf(A)), 5.0);
  // Arrowhead with the dense row last: no fill, c = 1 for columns 0…4. Dense row first: it fills
  // everything, c_j = 5 − j.
  Eigen::MatrixXd last = Eigen::MatrixXd::Identity(6, 6) * 4.0, first = last;
  for (int i = 0; i < 5; ++i) last(i, 5) = last(5, i) = 1.0;
  for (int i = 1; i < 6; ++i) first(0, i) = first(i, 0) = 1.0;
  EXPECT_DOUBLE_EQ(ldltMultiplyAdds(upperOf(last)), 5.0);
  EXPECT_DOUBLE_EQ(ldltMultiplyAdds(upperOf(first)), 25.0 + 16.0 + 9.0 + 4.0 + 1.0);
  // The 2D grid in natural order, beyond the switch point.
  EXPECT_GT(ldltMultiplyAdds(gridLaplacian(200)), kAutoCholmodFlops);
  EXPECT_LT(ldltMultiplyAdds(gridLaplacian(10)), kAutoCholmodFlops);
}

TEST(LinearSolver, AutoKeepsLdltForSmallSystemsAndHandsLargeOnesToCholmod) {
  auto small = makeLinearSolver(LinearSolverKind::Auto);
  small->analyzePattern(gridLaplacian(10));
  EXPECT_EQ(small->name(), "auto (ldlt)");
  // 200 × 200 grid in natural (row-by-row) order: L's columns hold ~k entries each, Σ c² ≈
  // k²·k² = 1.6e9 multiply-adds, beyond kAutoCholmodFlops.
  const int k = 200;
  const SymmetricUpper large = gridLaplacian(k);
  auto solver = makeLinearSolver(LinearSolverKind::Auto);
  solver->analyzePattern(large);
  if (!cholmodAvailable()) {
    EXPECT_EQ(solver->name(), "auto (ldlt)");
    return;
  }
  EXPECT_EQ(solver->name(), "auto (cholmod)");
  ASSERT_TRUE(solver->factorize(large));
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(k * k, -1.0, 2.0);
  Eigen::VectorXd x(k * k);
  solver->solve(b, x);
  const SymmetricUpper full = large.selfadjointView<Eigen::Upper>();
  EXPECT_LT((full * x - b).norm(), 1e-10 * b.norm());
}

/// The daemon analyzes and factorizes several sessions' systems at once, one per pool thread.
/// Each must get exactly the numbers it gets alone. Two ways this failed, both measured here:
/// - a serial OpenBLAS (no locks) shared its buffers between the threads: solutions off by
///   0.9 to 5e4 in norm, every one of the 50;
/// - METIS draws from one random generator per process: two analyses at once made other
///   orderings, and every solution differed by 1e-13 from the one made alone.
TEST(LinearSolver, FactorizationsOnTwoThreadsAtOnceGiveTheNumbersOfOneAtATime) {
  const int k = 120;  // supernodal CHOLMOD (Auto), whose supernodes call the BLAS
  SymmetricUpper first = gridLaplacian(k), second = gridLaplacian(k);
  for (int c = 0; c < second.outerSize(); ++c)
    for (SymmetricUpper::InnerIterator it(second, c); it; ++it)
      it.valueRef() = it.row() == it.col() ? 4.3 + 1e-3 * (c % 7) : -0.9 - 1e-3 * (c % 5);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(k * k, -1.0, 2.0);
  auto solveAlone = [&b](const SymmetricUpper& matrix) {
    auto solver = makeLinearSolver(LinearSolverKind::Auto);
    solver->analyzePattern(matrix);
    EXPECT_TRUE(solver->factorize(matrix));
    Eigen::VectorXd x(b.size());
    solver->solve(b, x);
    return x;
  };
  const Eigen::VectorXd firstAlone = solveAlone(first), secondAlone = solveAlone(second);
  std::atomic<int> differing{0}, failed{0};
  auto repeat = [&b, &differing, &failed](const SymmetricUpper& matrix, const Eigen::VectorXd& alone) {
    auto solver = makeLinearSolver(LinearSolverKind::Auto);
    solver->analyzePattern(matrix);
    Eigen::VectorXd x(b.size());
    for (int round = 0; round < 25; ++round) {
      if (!solver->factorize(matrix)) {
        ++failed;
        continue;
      }
      solver->solve(b, x);
      if (x != alone) ++differing;  // bit for bit: the same arithmetic in the same order
    }
  };
  std::thread other([&repeat, &second, &secondAlone]() { repeat(second, secondAlone); });
  repeat(first, firstAlone);
  other.join();
  EXPECT_EQ(failed.load(), 0);
  EXPECT_EQ(differing.load(), 0) << "of 50 solves made two at a time"
                                 << (blasCallsSerialized() ? " (BLAS calls serialized)" : "");
}

#ifdef __linux__
/// Threads of this process (Linux: the entries of /proc/self/task).
long threadCount() {
  const std::filesystem::directory_iterator tasks("/proc/self/task");
  return static_cast<long>(std::distance(std::filesystem::begin(tasks), std::filesystem::end(tasks)));
}

TEST(LinearSolver, CholmodFactorizesOnTheCallingThreadOnly) {
  if (!cholmodAvailable()) GTEST_SKIP() << "CHOLMOD not compiled in";
  // Large enough for CHOLMOD's supernodal kernel to open its OpenMP regions (num_threads(4) in
  // Debian's build); an iteration must stay on one core, so no worker thread may appear.
  const SymmetricUpper large = gridLaplacian(200);
  prepareBlasForThreads();  // a threaded OpenBLAS's own workers, started with the library, end here
  const long before = threadCount();
  for (LinearSolverKind kind : {LinearSolverKind::Auto, LinearSolverKind::Cholmod}) {
    auto solver = makeLinearSolver(kind);
    solver->analyzePattern(large);
    ASSERT_TRUE(solver->factorize(large));
  }
  EXPECT_EQ(threadCount(), before);
}

/// The daemon blocks SIGTERM on all its threads but one, which stops it cleanly; a thread the
/// BLAS started when it was loaded, with signals unblocked, took the signal and killed the
/// process (exit −15 in every end-to-end test that stops a daemon). None may be left.
TEST(LinearSolver, PreparingTheBlasLeavesNoThreadButTheCallers) {
  if (!cholmodAvailable()) GTEST_SKIP() << "CHOLMOD not compiled in (no BLAS is prepared)";
#if defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "ThreadSanitizer runs a thread of its own";
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
  GTEST_SKIP() << "ThreadSanitizer runs a thread of its own";
#endif
#endif
  const long before = threadCount();  // this test program's main thread, and the BLAS's workers
  prepareBlasForThreads();
  EXPECT_EQ(threadCount(), 1) << "of " << before << " before";
}

TEST(LinearSolver, CholmodsOpenMpRegionsEnterTheExecutablesOwnInlineEntry) {
  if (!cholmodAvailable()) GTEST_SKIP() << "CHOLMOD not compiled in";
  // A supernodal factorization opens OpenMP regions; each must reach the engine's GOMP_parallel
  // (one call, no team, no futex) and not libgomp's. If the executable did not export it, or
  // linked without it, the count would stay where it was.
  const SymmetricUpper large = gridLaplacian(200);
  auto solver = makeLinearSolver(LinearSolverKind::Auto);
  solver->analyzePattern(large);
  const std::uint64_t before = inlineOpenMpRegions();
  ASSERT_TRUE(solver->factorize(large));
  EXPECT_GT(inlineOpenMpRegions(), before);
  // And the factor is still right with every region run inline.
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(200 * 200, 1.0, -3.0);
  Eigen::VectorXd x(200 * 200);
  solver->solve(b, x);
  const SymmetricUpper full = large.selfadjointView<Eigen::Upper>();
  EXPECT_LT((full * x - b).norm(), 1e-10 * b.norm());
}
#endif  // the dynamic linker's search order is glibc's

}  // namespace
}  // namespace devsurf::engine
