#include "devsurf/server/store/Store.h"

#include <utility>

#include "devsurf/server/store/PostgresStore.h"
#include "devsurf/server/store/SqliteStore.h"

namespace devsurf::server::store {

// --- errors, records ----------------------------------------------------------------------------

SeqConflictError::SeqConflictError(const std::string& sessionId, std::int64_t expectedSeq,
                                   std::int64_t gotSeq)
    : StoreError("session '" + sessionId + "': edit seq " + std::to_string(gotSeq) +
                 " rejected, expected " + std::to_string(expectedSeq)),
      expected_(expectedSeq),
      got_(gotSeq) {}

IdempotencyConflictError::IdempotencyConflictError(std::string key, std::string existingJobId,
                                                   std::string existingFingerprint)
    : StoreError("idempotency key '" + key + "' already used by job '" + existingJobId + "'"),
      key_(std::move(key)),
      existingJobId_(std::move(existingJobId)),
      existingFingerprint_(std::move(existingFingerprint)) {}

std::int64_t wallClockMs() {
  using namespace std::chrono;
  return duration_cast<milliseconds>(system_clock::now().time_since_epoch()).count();
}

std::string jobStateName(JobState state) {
  switch (state) {
    case JobState::Queued: return "queued";
    case JobState::Running: return "running";
    case JobState::Succeeded: return "succeeded";
    case JobState::Failed: return "failed";
    case JobState::Cancelled: return "cancelled";
  }
  throw std::invalid_argument("invalid JobState " + std::to_string(static_cast<int>(state)));
}

JobState jobStateFromName(const std::string& name) {
  for (JobState s : {JobState::Queued, JobState::Running, JobState::Succeeded, JobState::Failed,
                     JobState::Cancelled}) {
    if (jobStateName(s) == name) return s;
  }
  throw std::invalid_argument("unknown job state '" + name + "'");
}

bool isFinished(JobState state) {
  return state == JobState::Succeeded || state == JobState::Failed ||
         state == JobState::Cancelled;
}

// --- Store ----------------------------------------------------------------------------------------

void Store::appendEdit(const std::string& sessionId, std::int64_t seq, const nlohmann::json& edit,
                       std::optional<std::int64_t> timeMs) {
  appendEdits(sessionId, {EditRecord{seq, edit, timeMs ? *timeMs : wallClockMs()}});
}

void Store::saveSnapshot(const std::string& sessionId, std::int64_t seq, const nlohmann::json& scene) {
  saveSnapshot(sessionId, Snapshot{seq, scene, nullptr, 0});
}

void Store::checkSessionOwner(const std::string& sessionId, const std::optional<std::string>& holder) const {
  if (sessionOwner_.empty() || !holder || *holder == sessionOwner_) return;
  throw LeaseLostError("session '" + sessionId + "' is held by node " + *holder + ", not by " + sessionOwner_ +
                       "; nothing was stored");
}

bool isPostgresLocation(const std::string& location) {
  return location.rfind("postgresql://", 0) == 0 || location.rfind("postgres://", 0) == 0;
}

std::unique_ptr<Store> openStore(const std::string& location, const StoreOptions& options) {
  if (location.empty()) throw StoreError("devsurf store: no location (a directory or postgresql://…)");
  if (isPostgresLocation(location)) return std::make_unique<PostgresStore>(location, options);
  return std::make_unique<SqliteStore>(location, options);
}

}  // namespace devsurf::server::store
