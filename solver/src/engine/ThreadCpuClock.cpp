#include "devsurf/engine/ThreadCpuClock.h"

#include <time.h>

namespace devsurf::engine {

ThreadCpuClock::time_point ThreadCpuClock::now() noexcept {
  timespec ts{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return time_point(std::chrono::seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec));
}

}  // namespace devsurf::engine
