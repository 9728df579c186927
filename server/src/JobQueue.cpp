#include "devsurf/server/JobQueue.h"

#include <algorithm>
#include <chrono>

#include "devsurf/proto/BoundedJson.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/server/SceneSolver.h"
#include "devsurf/server/Tokens.h"

namespace devsurf::server {

using nlohmann::json;
using store::JobRecord;
using store::JobState;

JobQueue::JobQueue(store::Store& store, JobLimits limits) : store_(store), limits_(limits) {
  for (int i = 0; i < std::max(1, limits_.workers); ++i) workers_.emplace_back([this]() { work(); });
}

JobQueue::~JobQueue() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    for (auto& [id, flag] : cancel_) flag->store(true);
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
}

void JobQueue::restore() {
  store_.requeueInterruptedJobs(store::wallClockMs());
  std::lock_guard<std::mutex> lock(mutex_);
  for (const JobRecord& j : store_.unfinishedJobs()) queue_.push_back(j.id);
  wake_.notify_all();
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
  std::lock_guard<std::mutex> lock(mutex_);
  if (queue_.size() >= limits_.maxQueued)
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
  queue_.push_back(job.id);
  wake_.notify_one();
  return {job.id, true};
}

std::optional<JobRecord> JobQueue::job(const std::string& id) const {
  std::optional<JobRecord> j = store_.job(id);
  if (!j) return j;
  std::lock_guard<std::mutex> lock(mutex_);
  const auto p = progress_.find(id);
  if (p != progress_.end()) {
    j->progressIteration = p->second.first;
    j->progressOf = p->second.second;
  }
  return j;
}

bool JobQueue::cancel(const std::string& id) {
  std::optional<JobRecord> j = store_.job(id);
  if (!j) throw store::NotFoundError("no job " + id);
  if (store::isFinished(j->state)) return false;
  std::lock_guard<std::mutex> lock(mutex_);
  const auto running = cancel_.find(id);
  if (running != cancel_.end()) {
    running->second->store(true);  // the worker records the cancellation
    return true;
  }
  const auto queued = std::find(queue_.begin(), queue_.end(), id);
  if (queued != queue_.end()) queue_.erase(queued);
  j->state = JobState::Cancelled;
  j->updatedMs = store::wallClockMs();
  store_.updateJob(*j);
  return true;
}

std::map<JobState, int> JobQueue::counts() const { return store_.jobCounts(); }

std::size_t JobQueue::queued() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return queue_.size();
}

void JobQueue::work() {
  for (;;) {
    std::string id;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this]() { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      id = queue_.front();
      queue_.pop_front();
    }
    std::optional<JobRecord> job = store_.job(id);
    if (!job || job->state != JobState::Queued) continue;
    run(*job);
  }
}

void JobQueue::run(JobRecord job) {
  auto cancelled = std::make_shared<std::atomic<bool>>(false);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    cancel_[job.id] = cancelled;
    progress_[job.id] = {0, job.progressOf};
  }
  job.state = JobState::Running;
  job.updatedMs = store::wallClockMs();
  store_.updateJob(job);
  // A cancellation by shutdown leaves the job running in the store: a restart re-queues it.
  auto leftForRestart = [this, &job]() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!stopping_) return false;
    cancel_.erase(job.id);
    progress_.erase(job.id);
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
    const std::string id = job.id;
    const engine::SolveSummary summary =
        solver.solve(-1, [this, id, cancelled, of = scene.solver.iterations](const engine::IterationRecord& r) {
          std::lock_guard<std::mutex> lock(mutex_);
          progress_[id] = {r.iteration, std::max(of, r.iteration)};
          return !cancelled->load();
        });
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    job.progressIteration = summary.stepsTaken();
    // quasi_strip and conical_strip have their own iteration limits (or none): done is done.
    job.progressOf = solver.keepsInputGeometry() ? job.progressIteration : scene.solver.iterations;
    if (cancelled->load()) {
      if (leftForRestart()) return;
      job.state = JobState::Cancelled;
    } else if (summary.reason == engine::TerminationReason::Diverged) {
      job.state = JobState::Failed;
      job.error = "the solver diverged";
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
      if (leftForRestart()) return;
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
  store_.updateJob(job);
  std::lock_guard<std::mutex> lock(mutex_);
  cancel_.erase(job.id);
  progress_.erase(job.id);
}

}  // namespace devsurf::server
