#pragma once

#include <atomic>
#include <chrono>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

namespace devsurf::engine {

/// Long work gave up: its Deadline passed (or it was cancelled). what() says which budget ran
/// out and how large it was ("the time budget of 2000 ms was exceeded").
class DeadlineExceeded : public std::runtime_error {
 public:
  DeadlineExceeded(const std::string& message, double budgetMs, bool cancelled)
      : std::runtime_error(message), budgetMs_(budgetMs), cancelled_(cancelled) {}
  /// The budget that ran out, milliseconds (0 when the work was cancelled before it ran out).
  double budgetMs() const { return budgetMs_; }
  /// The work was cancelled (Deadline::cancelFlag), not out of time.
  bool cancelled() const { return cancelled_; }

 private:
  double budgetMs_;
  bool cancelled_;
};

/// When long work must give up: a point on the steady clock and/or a cancel flag another thread
/// may set. The model builders, the models' solves and the engine check it between iterations and
/// inside their long loops (ARCHITECTURE §8: every session and job has a time budget), and throw
/// DeadlineExceeded. Copyable and cheap to check (one clock read); the default never expires.
///
/// Usage:
///   const engine::Deadline deadline = engine::Deadline::after(2000.0, "the job's time limit");
///   for (...) { deadline.check(); … }   // throws once 2 s have passed
class Deadline {
 public:
  using Clock = std::chrono::steady_clock;

  /// Never expires.
  Deadline() = default;

  /// Expires `budgetMs` milliseconds from now (≤ 0 or not finite: never). `budget` names the
  /// budget in the message ("the time budget", "the job's time limit").
  static Deadline after(double budgetMs, std::string budget = "the time budget") {
    Deadline d;
    d.budget_ = std::move(budget);
    if (budgetMs > 0.0 && budgetMs < 1e15) {
      d.budgetMs_ = budgetMs;
      d.at_ = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                 std::chrono::duration<double, std::milli>(budgetMs));
      d.bounded_ = true;
    }
    return d;
  }

  /// The same deadline, also expiring as soon as `*flag` is true (a job's cancellation).
  Deadline withCancelFlag(std::shared_ptr<const std::atomic<bool>> flag) const {
    Deadline d = *this;
    d.cancel_ = std::move(flag);
    return d;
  }

  /// Whether it has a time limit (false: only a cancel flag, or nothing).
  bool bounded() const { return bounded_; }
  /// The budget it was made with, milliseconds (0 when unbounded).
  double budgetMs() const { return budgetMs_; }
  bool cancelled() const { return cancel_ && cancel_->load(std::memory_order_relaxed); }
  bool expired() const { return cancelled() || (bounded_ && Clock::now() >= at_); }
  /// Milliseconds left (negative once passed; +∞ when unbounded).
  double remainingMs() const {
    if (!bounded_) return std::numeric_limits<double>::infinity();
    return std::chrono::duration<double, std::milli>(at_ - Clock::now()).count();
  }

  /// @throws DeadlineExceeded once expired()
  void check() const {
    if (cancelled()) throw DeadlineExceeded("the work was cancelled", 0.0, true);
    if (bounded_ && Clock::now() >= at_)
      throw DeadlineExceeded(budget_ + " of " + std::to_string(static_cast<long long>(budgetMs_ + 0.5)) +
                                 " ms was exceeded",
                             budgetMs_, false);
  }

 private:
  Clock::time_point at_{};
  double budgetMs_ = 0.0;
  bool bounded_ = false;
  std::string budget_ = "the time budget";
  std::shared_ptr<const std::atomic<bool>> cancel_;
};

}  // namespace devsurf::engine
