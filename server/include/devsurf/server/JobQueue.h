#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
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
  /// A running job's lease (`--job-lease-ms`): when its node stops renewing it for this long
  /// (the node died), any node may claim the job again.
  double leaseMs = 10000.0;
  /// How often a node renews the leases of its running jobs and stores their progress
  /// (≤ leaseMs / 3).
  double heartbeatMs = 1000.0;
  /// How often an idle worker looks for jobs other nodes queued (a shared store); a job queued on
  /// this node wakes it at once.
  double pollMs = 200.0;
  /// How long a finished job (succeeded, failed, cancelled) and its report stay in the store
  /// (`--job-retention-hours`, default 7 days): the heartbeat deletes older ones (their ids answer
  /// 404 and their idempotency keys are free again) every min(1 min, retention / 4), after it
  /// renewed its leases. 0: this node deletes none. Every node sharing a store deletes with its
  /// own retention, so the shortest among them is the store's.
  double retentionMs = 7.0 * 24 * 3600 * 1000;
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

/// Batch jobs (REST `/api/jobs`): a queue in the store and a pool of workers that claim jobs
/// from it and solve them with `SceneSolver`. Every state change is stored. The queue may be
/// shared by several nodes (PostgresStore): each job runs under a lease (store/Store.h) that a
/// heartbeat renews with the job's progress; a job whose node died is claimed again when its lease
/// ends, its result is written once, and a cancellation asked for on any node stops it.
class JobQueue {
 public:
  /// Re-queues what a previous run left running — every Running job for an embedded store, this
  /// node's own for a shared one (others' end with their leases) — then starts the workers.
  /// @param[in] nodeId  this node's name in the store's leases (DaemonOptions::nodeId)
  JobQueue(store::Store& store, JobLimits limits, std::string nodeId = "local");
  /// Stops the workers: running jobs are stopped and handed back to the queue (Queued) for this or
  /// another node to run.
  ~JobQueue();

  struct Submitted {
    std::string id;
    bool created;  ///< false: an earlier job with the same Idempotency-Key and body
  };
  /// Validates the scene (throws proto::SceneError) and queues it.
  /// @throws QueueFullError, IdempotencyMismatchError
  Submitted submit(const nlohmann::json& scene, const std::optional<std::string>& idempotencyKey);

  /// The job as the REST API shows it, or nullopt.
  std::optional<store::JobRecord> job(const std::string& id) const;
  /// Cancels a queued or running job, wherever it runs (a running job on another node stops at
  /// that node's next heartbeat). @returns false if it had already finished.
  /// @throws store::NotFoundError
  bool cancel(const std::string& id);

  std::map<store::JobState, int> counts() const;
  /// Jobs waiting in the store (all nodes').
  std::size_t queued() const;
  const std::string& nodeId() const { return nodeId_; }

  /// What this node did, for its metrics.
  struct Counters {
    std::atomic<std::uint64_t> claimed{0};    ///< jobs claimed (attempts started here)
    std::atomic<std::uint64_t> finished{0};   ///< results written here
    std::atomic<std::uint64_t> leaseLost{0};  ///< jobs stopped here because another node took them
  };
  const Counters& counters() const { return counters_; }

 private:
  /// A job this node runs.
  struct Running {
    int attempt = 0;
    int iteration = 0, of = 0;
    std::shared_ptr<std::atomic<bool>> cancelled;
    bool leaseLost = false;
  };
  void work();
  void heartbeat();
  void run(store::JobRecord job);
  /// The final write under the job's lease, retried while the store is unreachable.
  void finish(const store::JobRecord& job, int attempt);

  store::Store& store_;
  JobLimits limits_;
  std::string nodeId_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::uint64_t submitted_ = 0;  ///< bumped by submit(): wakes a worker without a poll
  std::map<std::string, Running> running_;
  bool stopping_ = false;
  Counters counters_;
  std::vector<std::thread> workers_;
  std::thread heartbeat_;
};

}  // namespace devsurf::server
