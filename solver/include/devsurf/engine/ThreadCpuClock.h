#pragma once

#include <chrono>

namespace devsurf::engine {

/// A std::chrono clock that reads the CPU time of the calling thread (POSIX
/// CLOCK_THREAD_CPUTIME_ID): it advances only while this thread runs. A solve's time budget
/// measured with it gives a busy machine the same result later, where a wall-clock budget would
/// cut the solve short (SolverOptions::budgetClock). Time points of different threads are not
/// comparable, and the clock stands still while the thread waits: not for timed waits
/// (condition_variable::wait_until would never return), hence not `is_steady`.
struct ThreadCpuClock {
  using duration = std::chrono::nanoseconds;
  using rep = duration::rep;
  using period = duration::period;
  using time_point = std::chrono::time_point<ThreadCpuClock>;
  static constexpr bool is_steady = false;

  /// CPU time this thread has used so far.
  static time_point now() noexcept;
};

}  // namespace devsurf::engine
