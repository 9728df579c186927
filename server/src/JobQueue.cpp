#include "devsurf/server/JobQueue.h"

#include <algorithm>
#include <chrono>

#include <spdlog/spdlog.h>

#include "devsurf/proto/BoundedJson.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/server/SceneSolver.h"
#include "devsurf/server/Tokens.h"

namespace devsurf::server {

using nlohmann::json;
using store::JobRecord;
using store::JobState;

namespace {
std::int64_t milliseconds(double ms) { return static_cast<std::int64_t>(ms); }
}  // namespace

JobQueue::JobQueue(store::Store& store, JobLimits limits, std::string nodeId)
    : store_(store), limits_(limits), nodeId_(std::move(nodeId)) {
  limits_.heartbeatMs = std::clamp(limits_.heartbeatMs, 10.0, std::max(10.0, limits_.leaseMs / 3.0));
  // Before any worker claims: what this queue claims itself must not be re-queued.
  const std::int64_t now = store::wallClockMs();
  const int requeued = store_.shared() ? store_.releaseJobLeases(nodeId_, now) : store_.requeueInterruptedJobs(now);
  if (requeued > 0) spdlog::info("{} interrupted job(s) queued again", requeued);
  for (int i = 0; i < std::max(1, limits_.workers); ++i) workers_.emplace_back([this]() { work(); });
  heartbeat_ = std::thread([this]() { heartbeat(); });
}

JobQueue::~JobQueue() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    for (auto& [id, r] : running_) r.cancelled->store(true);
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
  heartbeat_.join();
  // What this node was running goes back to the queue at once (not after its lease).
  try {
    const int released = store_.releaseJobLeases(nodeId_, store::wallClockMs());
    if (released > 0) spdlog::info("{} running job(s) handed back to the queue", released);
  } catch (const std::exception& e) {
    spdlog::warn("could not hand running jobs back to the queue ({}); their leases will end", e.what());
  }
}

JobQueue::Submitted JobQueue::submit(const json& scene, const std::optional<std::string>& key) {
  proto::sceneFromJson(scene, limits_.resources);  // validation and limits: throws SceneError naming the field
  const std::string body = scene.dump();
  const std::string fingerprint = sha256Hex(body);
  if (key) {
    if (auto existing = store_.jobByIdempotencyKey(*key)) {
      if (!hashMatches(body, existing->idempotencyFingerprint))
        throw IdempotencyMismatchError("Idempotency-Key \"" + *key + "\" was used for a different scene");
      return {existing->id, false};
    }
  }
  if (queued() >= limits_.maxQueued)
    throw QueueFullError("the job queue is full (" + std::to_string(limits_.maxQueued) + " queued jobs)");
  JobRecord job;
  job.id = randomToken().substr(0, 16);
  job.state = JobState::Queued;
  job.scene = scene;
  job.idempotencyKey = key;
  job.idempotencyFingerprint = fingerprint;
  job.createdMs = job.updatedMs = store::wallClockMs();
  job.progressOf = std::min(scene.value("solver", json::object()).value("iterations", 20), limits_.maxIterations);
  try {
    store_.putJob(job);
  } catch (const store::IdempotencyConflictError& e) {  // a concurrent submit with the same key
    if (!hashMatches(body, e.existingFingerprint()))
      throw IdempotencyMismatchError("Idempotency-Key \"" + *key + "\" was used for a different scene");
    return {e.existingJobId(), false};
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++submitted_;
  }
  wake_.notify_all();  // the heartbeat thread waits on it too
  return {job.id, true};
}

std::optional<JobRecord> JobQueue::job(const std::string& id) const {
  std::optional<JobRecord> j = store_.job(id);
  if (!j || j->state != JobState::Running) return j;
  std::lock_guard<std::mutex> lock(mutex_);
  const auto r = running_.find(id);  // this node's progress is newer than the last heartbeat's
  if (r != running_.end()) {
    j->progressIteration = r->second.iteration;
    j->progressOf = r->second.of;
  }
  return j;
}

bool JobQueue::cancel(const std::string& id) {
  std::optional<JobRecord> j = store_.job(id);
  if (!j) throw store::NotFoundError("no job " + id);
  if (store::isFinished(j->state)) return false;
  const JobState after = store_.requestJobCancel(id, store::wallClockMs());
  if (after != JobState::Running) return after == JobState::Cancelled;
  std::lock_guard<std::mutex> lock(mutex_);
  const auto r = running_.find(id);
  if (r != running_.end()) r->second.cancelled->store(true);  // here: at once; elsewhere: its heartbeat
  return true;
}

std::map<JobState, int> JobQueue::counts() const { return store_.jobCounts(); }

std::size_t JobQueue::queued() const { return static_cast<std::size_t>(store_.jobCounts().at(JobState::Queued)); }

void JobQueue::work() {
  std::uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      if (stopping_) return;
      seen = submitted_;
    }
    std::optional<JobRecord> job;
    try {
      job = store_.claimJob(nodeId_, store::wallClockMs(), milliseconds(limits_.leaseMs));
    } catch (const std::exception& e) {
      spdlog::warn("job queue: cannot claim jobs: {}", e.what());
    }
    if (job) {
      ++counters_.claimed;
      run(std::move(*job));
      continue;
    }
    std::unique_lock<std::mutex> lock(mutex_);
    wake_.wait_for(lock, std::chrono::duration<double, std::milli>(limits_.pollMs),
                   [this, seen]() { return stopping_ || submitted_ != seen; });
  }
}

void JobQueue::heartbeat() {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto prunePeriod =
      std::chrono::duration<double, std::milli>(std::clamp(limits_.retentionMs / 4.0, 10.0, 60000.0));
  auto nextPrune = std::chrono::steady_clock::now();
  const double wait = limits_.retentionMs > 0.0 ? std::min(limits_.heartbeatMs, prunePeriod.count()) : limits_.heartbeatMs;
  for (;;) {
    wake_.wait_for(lock, std::chrono::duration<double, std::milli>(wait), [this]() { return stopping_; });
    if (stopping_) return;
    std::vector<std::pair<std::string, Running>> mine(running_.begin(), running_.end());
    lock.unlock();
    for (const auto& [id, r] : mine) {
      try {
        const store::JobLeaseRenewal renewal = store_.renewJobLease(
            id, nodeId_, r.attempt, store::wallClockMs(), milliseconds(limits_.leaseMs), r.iteration, r.of);
        if (!renewal.held || renewal.cancelRequested) {
          std::lock_guard<std::mutex> relock(mutex_);
          const auto it = running_.find(id);
          if (it == running_.end() || it->second.attempt != r.attempt) continue;  // finished, or a later attempt
          if (!renewal.held) {
            spdlog::warn("job {}: its lease was lost (another node runs it now); stopping here", id);
            it->second.leaseLost = true;
            ++counters_.leaseLost;
          }
          it->second.cancelled->store(true);
        }
      } catch (const std::exception& e) {
        spdlog::warn("job {}: cannot renew its lease: {}", id, e.what());
      }
    }
    // After the renewals, so that a slow delete never holds up a lease.
    if (limits_.retentionMs > 0.0 && std::chrono::steady_clock::now() >= nextPrune) {
      nextPrune = std::chrono::steady_clock::now() +
                  std::chrono::duration_cast<std::chrono::steady_clock::duration>(prunePeriod);
      try {
        const int pruned = store_.pruneFinishedJobs(store::wallClockMs() - milliseconds(limits_.retentionMs));
        if (pruned > 0) spdlog::info("job queue: {} finished job(s) past their retention deleted", pruned);
      } catch (const std::exception& e) {
        spdlog::warn("job queue: cannot delete finished jobs past their retention: {}", e.what());
      }
    }
    lock.lock();
  }
}

void JobQueue::finish(const JobRecord& job, int attempt) {
  // Retried while the store is unreachable, up to one lease: after that another node may hold it.
  const auto giveUp = std::chrono::steady_clock::now() + std::chrono::duration<double, std::milli>(limits_.leaseMs);
  for (;;) {
    try {
      if (store_.finishJob(job, nodeId_, attempt))
        ++counters_.finished;
      else
        spdlog::warn("job {}: finished here after its lease was lost; the result is not stored", job.id);
      return;
    } catch (const std::exception& e) {
      if (std::chrono::steady_clock::now() > giveUp) {
        spdlog::error("job {}: cannot store its result ({}); its lease will end and it runs again", job.id, e.what());
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
  }
}

void JobQueue::run(JobRecord job) {
  auto cancelled = std::make_shared<std::atomic<bool>>(job.cancelRequested);
  const int attempt = job.attempt;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // An earlier attempt still running here lost its lease (the store was unreachable longer than
    // a lease, and this worker claimed the job again): it stops, and its result will be refused.
    if (const auto earlier = running_.find(job.id); earlier != running_.end()) {
      earlier->second.leaseLost = true;
      earlier->second.cancelled->store(true);
    }
    running_[job.id] = Running{attempt, 0, job.progressOf, cancelled, false};
    // Claimed in the store before the shutdown began but registered here after it: the destructor
    // did not see this job, so it stops now and is handed back with the rest (under a busy CI run
    // such a job once ran to its end while the queue shut down).
    if (stopping_) cancelled->store(true);
  }
  // This attempt's entry, or end() once a later attempt replaced it. Under mutex_.
  auto mine = [this, &job, attempt]() {
    const auto r = running_.find(job.id);
    return r != running_.end() && r->second.attempt == attempt ? r : running_.end();
  };
  // A stop by shutdown or by a lost lease is not a cancellation: the job is left to the queue
  // (the destructor hands it back; a lost lease means another node, or attempt, has it).
  auto leftForOthers = [this, &mine]() {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto r = mine();
    if (r == running_.end()) return true;  // replaced by a later attempt
    if (!stopping_ && !r->second.leaseLost) return false;
    running_.erase(r);
    return true;
  };
  try {
    // The job's time limit bounds everything from here, the model's construction included; a
    // cancellation stops it the same way.
    const engine::Deadline deadline =
        engine::Deadline::after(limits_.maxRunMs, "the job's time limit").withCancelFlag(cancelled);
    proto::Scene scene = proto::sceneFromJson(job.scene, limits_.resources);
    scene.solver.iterations = std::min(scene.solver.iterations, limits_.maxIterations);
    const auto start = std::chrono::steady_clock::now();
    SceneSolver solver(scene, deadline);
    const engine::SolveSummary summary =
        solver.solve(-1, [this, &mine, cancelled, of = scene.solver.iterations](const engine::IterationRecord& r) {
          std::lock_guard<std::mutex> lock(mutex_);
          if (const auto entry = mine(); entry != running_.end()) {
            entry->second.iteration = r.iteration;
            entry->second.of = std::max(of, r.iteration);
          }
          return !cancelled->load();
        });
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    job.progressIteration = summary.stepsTaken();
    // quasi_strip and conical_strip have their own iteration limits (or none): done is done.
    job.progressOf = solver.keepsInputGeometry() ? job.progressIteration : scene.solver.iterations;
    if (cancelled->load()) {
      if (leftForOthers()) return;
      job.state = JobState::Cancelled;
    } else if (summary.reason == engine::TerminationReason::Diverged) {
      job.state = JobState::Failed;
      job.error = summary.stepsTaken() == 0
                      ? "the solver diverged at its first step: the scene's geometry is likely degenerate (control "
                        "points on top of each other, an edge or a face of no length or area)"
                      : "the solver diverged";
      job.report = solver.report(summary, ms);
    } else {
      json report = solver.report(summary, ms);
      if (const std::string bad = proto::nonFinitePath(report); !bad.empty()) {
        // Never stored as a result (it would read back as null).
        job.state = JobState::Failed;
        job.error = "the solve produced a non-finite value (" + bad + ")";
      } else {
        job.state = JobState::Succeeded;
        job.report = std::move(report);
      }
    }
  } catch (const engine::DeadlineExceeded& e) {
    if (e.cancelled()) {
      if (leftForOthers()) return;
      job.state = JobState::Cancelled;
    } else {
      job.state = JobState::Failed;
      job.error = std::string(e.what()) + " (devsurf serve --job-timeout-ms); the job was stopped";
    }
  } catch (const std::exception& e) {
    job.state = JobState::Failed;
    job.error = e.what();
  }
  job.updatedMs = store::wallClockMs();
  finish(job, attempt);
  std::lock_guard<std::mutex> lock(mutex_);
  if (const auto entry = mine(); entry != running_.end()) running_.erase(entry);
}

}  // namespace devsurf::server
