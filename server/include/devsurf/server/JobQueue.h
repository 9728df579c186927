#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "devsurf/proto/ResourceLimits.h"
#include "devsurf/server/store/Store.h"

namespace devsurf::server {

/// Limits of the batch queue.
struct JobLimits {
  int workers = 1;                 ///< jobs solved at once
  std::size_t maxQueued = 64;      ///< queued (not yet running) jobs; more → QueueFullError
  /// Wall time per job (`--job-timeout-ms`), building the model included, for every kind: a job
  /// still working then is stopped (engine::Deadline, checked between iterations and inside the
  /// models' long loops) and ends `failed` with an error naming the limit. A scene's own
  /// solver.time_budget_ms below it ends the solve normally (termination time_budget).
  double maxRunMs = 120000.0;
  int maxIterations = 10000;       ///< iterations per job
  /// What a job's scene may ask for (memory estimate, control points); checked at submission and
  /// again when the job runs.
  proto::ResourceLimits resources;
};

class QueueFullError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
/// The same Idempotency-Key was used with a different body.
class IdempotencyMismatchError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Batch jobs (REST `/api/jobs`): a bounded queue and a worker pool that solve scenes with
/// `SceneSolver`, persisting every state change in the store so a restarted daemon re-queues
/// what was queued or running.
class JobQueue {
 public:
  JobQueue(store::Store& store, JobLimits limits);
  ~JobQueue();  ///< stops the workers; running jobs stay "running" in the store (re-queued on restart)

  /// Re-queues the store's unfinished jobs (call once at start-up, before serving).
  void restore();

  struct Submitted {
    std::string id;
    bool created;  ///< false: an earlier job with the same Idempotency-Key and body
  };
  /// Validates the scene (throws proto::SceneError) and queues it.
  /// @throws QueueFullError, IdempotencyMismatchError
  Submitted submit(const nlohmann::json& scene, const std::optional<std::string>& idempotencyKey);

  /// The job as the REST API shows it, or nullopt.
  std::optional<store::JobRecord> job(const std::string& id) const;
  /// Cancels a queued or running job. @returns false if it had already finished.
  /// @throws store::NotFoundError
  bool cancel(const std::string& id);

  std::map<store::JobState, int> counts() const;
  std::size_t queued() const;

 private:
  void work();
  void run(store::JobRecord job);

  store::Store& store_;
  JobLimits limits_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::string> queue_;
  std::map<std::string, std::pair<int, int>> progress_;  ///< running: iteration, of
  std::map<std::string, std::shared_ptr<std::atomic<bool>>> cancel_;
  bool stopping_ = false;
  std::vector<std::thread> workers_;
};

}  // namespace devsurf::server
