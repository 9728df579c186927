#pragma once

// The shared store: a PostgreSQL database that several daemons and workers use at once (`devsurf
// serve --store postgresql://…`, issue 18), through libpq (Debian's libpq-dev).
//
// Durability
// ----------
// A method returns after its transaction committed on the server: what the server's own settings
// make of a commit (synchronous_commit, fsync, replication) is what an acknowledged edit survives.
// With PostgreSQL's defaults that is power loss of the database machine too.
//
// Concurrency
// -----------
// All methods are thread-safe. A store keeps StoreOptions::connections connections and lends one
// to each call; transactions run at READ COMMITTED and lock what they change (a session's row for
// appendEdits/saveSnapshot, a job's row for a claim with FOR UPDATE SKIP LOCKED), so any number of
// processes may write at once. Reads of a session (loadSession[s]) run in one REPEATABLE READ
// transaction: a consistent picture across its tables.
//
// Outages
// -------
// A call on a broken connection tries one reconnect (connect_timeout 5 s unless the URI sets
// one); when the server stays unreachable it throws StoreUnavailableError (a StoreError) and
// nothing is acknowledged. The next call reconnects.
//
// Schema
// ------
// The same versions as SqliteStore (Store::kSchemaVersion) in PostgreSQL's types, recorded in the
// table devsurf_schema; migrations run under an advisory lock, so daemons that start together
// migrate once. Tables live in the connection's search_path (a URI may set it:
// `?options=-csearch_path%3Dmyschema`). JSON is stored as compact text, as in SQLite.

#include <memory>
#include <string>

#include "devsurf/server/store/Store.h"

namespace devsurf::server::store {

/// The server could not be reached (or the connection broke and did not come back).
class StoreUnavailableError : public StoreError {
 public:
  using StoreError::StoreError;
};

class PostgresStore final : public Store {
 public:
  /// Connects (StoreOptions::connections connections) to a libpq connection URI
  /// "postgresql://[user[:password]@][host][:port][/dbname][?param=value…]" and migrates the
  /// schema. @throws StoreError naming the URI (without its password) and the server's message
  explicit PostgresStore(const std::string& uri, const StoreOptions& options = {});
  ~PostgresStore() override;

  StoreInfo info() const override;
  bool shared() const override { return true; }

  void createSession(const SessionRecord& session) override;
  bool deleteSession(const std::string& id) override;
  void appendEdits(const std::string& sessionId, const std::vector<EditRecord>& edits) override;
  std::int64_t lastSeq(const std::string& sessionId) const override;
  using Store::saveSnapshot;
  void saveSnapshot(const std::string& sessionId, const Snapshot& snapshot) override;
  void quarantineSession(const std::string& id, const std::string& reason) override;
  void liftQuarantine(const std::string& id) override;
  std::vector<RestoredSession> loadSessions() const override;
  std::optional<RestoredSession> loadSession(const std::string& id) const override;
  bool acquireSessionLease(const std::string& id, const std::string& owner, std::int64_t nowMs,
                           std::int64_t leaseMs) override;
  std::vector<std::string> renewSessionLeases(const std::string& owner, std::int64_t nowMs,
                                              std::int64_t leaseMs) override;
  int endSessionLeases(const std::string& owner) override;
  void requestSessionHandover(const std::string& id, const std::string& requester) override;
  std::optional<std::pair<std::string, std::int64_t>> sessionLease(const std::string& id) const override;
  std::vector<std::string> sessionsLeasedBy(const std::string& owner) const override;

  void putJob(const JobRecord& job) override;
  std::optional<JobRecord> jobByIdempotencyKey(const std::string& key) const override;
  void updateJob(const JobRecord& job) override;
  std::optional<JobRecord> job(const std::string& id) const override;
  std::vector<JobRecord> unfinishedJobs() const override;
  std::map<JobState, int> jobCounts() const override;
  int pruneFinishedJobs(std::int64_t olderThanMs) override;
  std::optional<JobRecord> claimJob(const std::string& owner, std::int64_t nowMs,
                                    std::int64_t leaseMs) override;
  JobLeaseRenewal renewJobLease(const std::string& id, const std::string& owner, int attempt,
                                std::int64_t nowMs, std::int64_t leaseMs, int progressIteration,
                                int progressOf) override;
  bool finishJob(const JobRecord& job, const std::string& owner, int attempt) override;
  JobState requestJobCancel(const std::string& id, std::int64_t nowMs) override;
  int releaseJobLeases(const std::string& owner, std::int64_t nowMs) override;
  int requeueInterruptedJobs(std::int64_t nowMs) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The URI with its password (userinfo after ':' or a password= parameter) replaced by "***".
std::string redactedUri(const std::string& uri);

}  // namespace devsurf::server::store
