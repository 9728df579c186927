#include "devsurf/engine/LinearSolver.h"

#include <cstddef>
#include <cstring>
#include <vector>
#include <stdexcept>

#include <Eigen/SparseCholesky>
#ifdef DEVSURF_HAVE_CHOLMOD
#include <atomic>
#include <mutex>

#include <dlfcn.h>
#include <omp.h>

#include <Eigen/CholmodSupport>

namespace devsurf::engine {
namespace {
std::atomic<std::uint64_t> inlineRegionCount{0};
}  // namespace
}  // namespace devsurf::engine

/// The entry of every `#pragma omp parallel` region GCC compiles (libgomp's GOMP_parallel,
/// GOMP_4.0), defined in the executable so that it comes before libgomp's in the dynamic
/// linker's search: the only OpenMP user in the process is CHOLMOD, whose regions run on the
/// calling thread anyway (see CholmodSolver), and this runs them there without a team.
/// That rests on the BLAS underneath not using OpenMP (scripts/setup.sh installs
/// libopenblas0-pthread, told to run each call on the calling thread: BlasThreading below): an
/// OpenMP build of OpenBLAS would have its regions run inline too, and its threads, which wait
/// for one another, would then wait forever.
///
/// Why: libgomp builds a team for every region, even a one-thread one, and ends it with a
/// barrier that always wakes its futex — a system call per region. CHOLMOD's supernodal
/// factorization enters a few regions per supernode: 766 000 futex calls in one drag-stress test
/// of a composite preset; libgomp and its system calls took a fifth of that test's CPU time on
/// this VM, where system calls are dear. Measured back to back (bench/composite_iteration, one
/// core, factorization medians): folded annulus with development 4.6 → 1.8–2.0 ms, 40 × 40
/// sheet 23.0 → 19.4–20.6 ms, with development 107–109 → 90–95 ms.
///
/// Inside a region called so, omp_get_num_threads() is 1 and omp_get_thread_num() 0 (no team),
/// which is what CHOLMOD's static-schedule loops divide their ranges by: the whole range runs
/// here. The thread count and the flags (proc_bind) have nothing to choose between.
extern "C" void GOMP_parallel(void (*region)(void*), void* data, unsigned /*numThreads*/, unsigned /*flags*/) {
  devsurf::engine::inlineRegionCount.fetch_add(1, std::memory_order_relaxed);
  region(data);
}
#endif

namespace devsurf::engine {
namespace {

#ifdef DEVSURF_HAVE_CHOLMOD
/// The BLAS under CHOLMOD's supernodal factorization, called from several threads at once: the
/// daemon solves its sessions and jobs on a pool, and builds its demos on every core.
///
/// OpenBLAS is found by its own symbols, whichever alternative libblas.so.3 points to:
/// - a threaded build (pthreads; scripts/setup.sh installs libopenblas0-pthread) locks its
///   shared buffers and is told to run each call on the calling thread
///   (openblas_set_num_threads(1)): an iteration stays on one core (see CholmodSolver);
/// - a serial build (libopenblas0-serial) has no locks at all (nor, for threads it did not start,
///   an OpenMP build): two factorizations at once share
///   its buffers and corrupt each other. Measured on Debian 12's 0.3.21: two quad-mesh demos built
///   at once gave different vertices on each of four starts, and one of them took 4 s instead
///   of 1.2. Calls into it are then made one at a time (blasLock).
/// Other BLAS libraries (reference BLAS, BLIS) keep no shared state and need nothing.
class BlasThreading {
 public:
  static BlasThreading& instance() {
    static BlasThreading threading;
    return threading;
  }
  /// Held around every call that may reach the BLAS; engaged only for a serial OpenBLAS.
  std::unique_lock<std::mutex> lock() {
    return serialized_ ? std::unique_lock<std::mutex>(mutex_) : std::unique_lock<std::mutex>();
  }
  bool serialized() const { return serialized_; }

 private:
  BlasThreading() {
    using GetParallel = int (*)();
    using SetThreads = void (*)(int);
    const auto getParallel = reinterpret_cast<GetParallel>(::dlsym(RTLD_DEFAULT, "openblas_get_parallel"));
    const auto setThreads = reinterpret_cast<SetThreads>(::dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
    if (!getParallel) return;  // not OpenBLAS
    const int parallel = getParallel();  // 0: sequential build, 1: pthreads, 2: OpenMP
    if (setThreads) setThreads(1);
    // The sequential build has no locks; the OpenMP build takes its buffer lock only when built
    // for pthreads, and its calls from threads of ours would meet in its unlocked allocator.
    serialized_ = parallel != 1;
    if (serialized_) return;
    // The pthreads build starts its worker threads when it is loaded, before main() can block
    // SIGTERM for every thread (the daemon takes signals on a thread of its own): a worker left
    // running could take a SIGTERM and end the process at once (exit −15 instead of a clean
    // stop). With one thread per call OpenBLAS needs no workers, so they are ended here; it
    // starts them again itself should a call ever want more than one.
    using Shutdown = int (*)();
    if (const auto shutdown = reinterpret_cast<Shutdown>(::dlsym(RTLD_DEFAULT, "blas_thread_shutdown_"));
        shutdown && getParallel() == 1)
      shutdown();
  }
  std::mutex mutex_;
  bool serialized_ = false;
};
#endif

/// Eigen SimplicialLDLT in natural ordering: the assembler already applied a fill-reducing
/// permutation and stores the upper triangle, which is the layout Eigen's numeric kernel works on.
class SimplicialLdltSolver final : public LinearSolver {
 public:
  std::string name() const override { return "ldlt"; }
  void analyzePattern(const SymmetricUpper& matrix) override {
    ldlt_.analyzePattern(matrix);
    ldlt_.sizeDiagonal(matrix.rows());  // else the first factorization allocates it
  }
  bool factorize(const SymmetricUpper& matrix) override {
    ldlt_.factorizeUpper(matrix);
    if (ldlt_.info() != Eigen::Success) return false;
    return (ldlt_.diagonal().array() > 0.0).all();
  }
  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) override {
    solution = ldlt_.solve(rhs);
  }
 private:
  /// SimplicialLDLT::factorize() builds an (unused, here) n×n temporary on the heap on every
  /// call; with natural ordering and upper storage it then factors the input as is, so call that
  /// numeric kernel directly. Its own work arrays (3n scalars) live on the stack while they fit
  /// EIGEN_STACK_ALLOCATION_LIMIT (n ≤ 16 384) and are heap-allocated per call beyond that.
  /// vectorD() returns D by value (a copy per call), so D is read by reference.
  struct Ldlt : Eigen::SimplicialLDLT<SymmetricUpper, Eigen::Upper, Eigen::NaturalOrdering<int>> {
    void factorizeUpper(const SymmetricUpper& upper) { this->factorize_preordered<true>(upper); }
    const Eigen::VectorXd& diagonal() const { return this->m_diag; }
    void sizeDiagonal(Eigen::Index n) { this->m_diag.resize(n); }
  };
  Ldlt ldlt_;
};

#ifdef DEVSURF_HAVE_CHOLMOD
/// CHOLMOD in natural ordering (see above). CHOLMOD picks a supernodal or a simplicial (LDLᵀ)
/// factorization itself from the flop count per nonzero of L (its `supernodal_switch`): banded
/// systems like the strip's reduced matrix go simplicial, which is ~2× faster there than
/// supernodal with a reference BLAS. Solves reuse their workspaces (cholmod_solve2).
///
/// With `ownOrdering` (the large systems LinearSolverKind::Auto hands it) CHOLMOD reorders the
/// matrix itself — METIS nested dissection, or AMD when that fills less — postorders the tree and
/// factors supernodally: on the composite sheets' 2D-like patterns nested dissection fills far
/// less than the assembler's AMD.
///
/// \note CHOLMOD 5 (Debian 12) runs parts of its supernodal factorization in OpenMP regions with
/// a compiled-in num_threads(4), which OMP_NUM_THREADS does not override. An iteration runs on
/// one core (the daemon parallelizes across sessions, one worker per session): four threads on a
/// two-core machine spent half the wall time in futex waits (40 × 40 sheet with development:
/// 1.04 s per iteration, 0.51 s on one thread). So analyzePattern and factorize first set the
/// calling thread's max-active-levels ICV to 0, which runs every OpenMP region on that thread,
/// and GOMP_parallel above runs the region without asking libgomp for a team at all; the ICV
/// stays as the fallback should the executable stop exporting its own (hidden visibility, or
/// the engine linked into a shared object).
class CholmodSolver final : public LinearSolver {
 public:
  explicit CholmodSolver(bool ownOrdering = false) {
    BlasThreading::instance();  // before any call into the BLAS (sets OpenBLAS to the calling thread)
    if (ownOrdering) {
      llt_.setMode(Eigen::CholmodSupernodalLLt);
      llt_.cholmod().nmethods = 2;
      llt_.cholmod().method[0].ordering = CHOLMOD_METIS;
      llt_.cholmod().method[1].ordering = CHOLMOD_AMD;
      llt_.cholmod().postorder = 1;
    } else {
      llt_.setMode(Eigen::CholmodAuto);
      llt_.cholmod().nmethods = 1;
      llt_.cholmod().method[0].ordering = CHOLMOD_NATURAL;
      llt_.cholmod().postorder = 0;
    }
    // A system that is not positive definite is reported through factorize()'s result (the caller
    // damps and retries), not printed as a CHOLMOD warning on stderr.
    llt_.cholmod().print = 0;
  }
  ~CholmodSolver() override {
    cholmod_free_dense(&x_, &llt_.cholmod());
    cholmod_free_dense(&y_, &llt_.cholmod());
    cholmod_free_dense(&e_, &llt_.cholmod());
  }
  std::string name() const override { return "cholmod"; }
  void analyzePattern(const SymmetricUpper& matrix) override {
    empty_ = matrix.rows() == 0;  // CHOLMOD rejects a 0×0 matrix (everything eliminated)
    if (empty_) return;
    omp_set_max_active_levels(0);  // one thread: see the class note
    {
      // METIS (CHOLMOD's nested dissection) draws from one random generator for the whole
      // process: two orderings at once interleave its draws and come out different, and so do
      // the factors' numbers. One analysis at a time (one per model topology, not per iteration).
      static std::mutex orderingMutex;
      const std::lock_guard<std::mutex> ordering(orderingMutex);
      llt_.analyzePattern(matrix);
    }
    // Size the solve workspaces now (shapes as cholmod_solve2 wants them for one right-hand side).
    const std::size_t n = static_cast<std::size_t>(matrix.rows());
    cholmod_factor* factor = llt_.factor();
    cholmod_common* common = &llt_.cholmod();
    if (!factor) return;
    // The supernodal factor's values are allocated and touched now, in the analysis, not by the
    // first factorization: CHOLMOD mallocs L->x there and zeroes it supernode by supernode, so
    // that factorization took every page fault of the factor (the quad mesh at 250 880 unknowns:
    // 2–3 s on this VM, a quarter of its first ten iterations). Every factorization overwrites all
    // of L->x; transparent huge pages for it (madvise) measured no faster.
    if (factor->is_super && factor->xtype == CHOLMOD_PATTERN &&
        cholmod_change_factor(CHOLMOD_REAL, 1, 1, 1, 1, factor, common) && factor->x)
      std::memset(factor->x, 0, factor->xsize * sizeof(double));
    cholmod_ensure_dense(&x_, n, 1, n, CHOLMOD_REAL, common);
    if (factor->is_super) {
      cholmod_ensure_dense(&y_, n, 1, n, CHOLMOD_REAL, common);
      cholmod_ensure_dense(&e_, 1, factor->maxesize, 1, CHOLMOD_REAL, common);
    } else {
      cholmod_ensure_dense(&y_, 4, n, 4, CHOLMOD_REAL, common);
    }
  }
  bool factorize(const SymmetricUpper& matrix) override {
    if (empty_) return true;
    omp_set_max_active_levels(0);  // per thread (OpenMP 5 ICV); the caller may be a new worker
    {
      const auto blas = BlasThreading::instance().lock();
      llt_.factorize(matrix);
    }
    if (llt_.info() != Eigen::Success) return false;
    // An LLᵀ factorization fails on a non-positive pivot, but CHOLMOD's simplicial LDLᵀ only on
    // a zero one: require D > 0 (stored first in every column of L) as the Eigen solver does.
    const cholmod_factor* L = llt_.factor();
    if (!L->is_super && !L->is_ll) {
      const double* values = static_cast<const double*>(L->x);
      const int* columns = static_cast<const int*>(L->p);
      for (std::size_t k = 0; k < L->n; ++k)
        if (!(values[columns[k]] > 0.0)) return false;
    }
    return true;
  }
  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) override {
    const Eigen::Index n = rhs.size();
    solution.resize(n);
    if (empty_ || n == 0) return;
    cholmod_dense b = Eigen::viewAsCholmod(const_cast<Eigen::VectorXd&>(rhs));  // read only
    // A simplicial solve wants Y as 4×n but leaves it reshaped to the columns it used; restore the
    // shape (the storage is large enough) or cholmod_solve2 reallocates Y on every call.
    const std::size_t rows = static_cast<std::size_t>(n);
    if (y_ && !llt_.factor()->is_super && y_->nzmax >= 4 * rows) {
      y_->nrow = 4;
      y_->ncol = rows;
      y_->d = 4;
    }
    {
      const auto blas = BlasThreading::instance().lock();
      cholmod_solve2(CHOLMOD_A, llt_.factor(), &b, nullptr, &x_, nullptr, &y_, &e_, &llt_.cholmod());
    }
    solution = Eigen::Map<const Eigen::VectorXd>(static_cast<const double*>(x_->x), n);
  }

 private:
  struct Decomposition : Eigen::CholmodDecomposition<SymmetricUpper, Eigen::Upper> {
    cholmod_factor* factor() { return this->m_cholmodFactor; }
  };
  Decomposition llt_;
  bool empty_ = false;
  cholmod_dense* x_ = nullptr;  // solve2 workspaces, sized by analyzePattern
  cholmod_dense* y_ = nullptr;
  cholmod_dense* e_ = nullptr;
};
#endif

/// LinearSolverKind::Auto: Eigen's LDLT unless a factorization in the given order would take
/// more than kAutoCholmodFlops multiply-adds, then CHOLMOD (supernodal, its own ordering).
class AutoSolver final : public LinearSolver {
 public:
  std::string name() const override { return cholmod_ ? "auto (cholmod)" : "auto (ldlt)"; }
  void analyzePattern(const SymmetricUpper& matrix) override {
#ifdef DEVSURF_HAVE_CHOLMOD
    if (ldltMultiplyAdds(matrix) > kAutoCholmodFlops) solver_ = std::make_unique<CholmodSolver>(true);
#endif
    cholmod_ = solver_ != nullptr;
    if (!solver_) solver_ = std::make_unique<SimplicialLdltSolver>();
    solver_->analyzePattern(matrix);
  }
  bool factorize(const SymmetricUpper& matrix) override { return solver_->factorize(matrix); }
  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) override { solver_->solve(rhs, solution); }

 private:
  std::unique_ptr<LinearSolver> solver_;
  bool cholmod_ = false;
};

}  // namespace

double ldltMultiplyAdds(const SymmetricUpper& upper) {
  // Elimination tree and column counts of L as Eigen's SimplicialLDLT::analyzePattern computes
  // them (Liu's row-subtree walk over the upper triangle), without allocating L.
  const int n = static_cast<int>(upper.cols());
  std::vector<int> parent(static_cast<std::size_t>(n), -1), flag(static_cast<std::size_t>(n), -1);
  std::vector<double> count(static_cast<std::size_t>(n), 0.0);
  for (int k = 0; k < n; ++k) {
    flag[k] = k;
    for (SymmetricUpper::InnerIterator it(upper, k); it; ++it) {
      int i = static_cast<int>(it.index());
      if (i >= k) continue;
      for (; flag[i] != k; i = parent[i]) {  // L(k, i) ≠ 0 for every i on the path to k
        if (parent[i] == -1) parent[i] = k;
        count[i] += 1.0;
        flag[i] = k;
      }
    }
  }
  double total = 0.0;
  for (double c : count) total += c * c;
  return total;
}

std::uint64_t inlineOpenMpRegions() {
#ifdef DEVSURF_HAVE_CHOLMOD
  return inlineRegionCount.load(std::memory_order_relaxed);
#else
  return 0;
#endif
}

void prepareBlasForThreads() {
#ifdef DEVSURF_HAVE_CHOLMOD
  BlasThreading::instance();
#endif
}

bool blasCallsSerialized() {
#ifdef DEVSURF_HAVE_CHOLMOD
  return BlasThreading::instance().serialized();
#else
  return false;
#endif
}

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
    case LinearSolverKind::Auto:
      return std::make_unique<AutoSolver>();
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
  if (name == "auto") return LinearSolverKind::Auto;
  throw std::invalid_argument("linear_solver: expected \"auto\", \"ldlt\" or \"cholmod\", got \"" + name + "\"");
}

}  // namespace devsurf::engine
