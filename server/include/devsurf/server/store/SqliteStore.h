#pragma once

// The embedded store: one SQLite database DIR/devsurf.db in WAL mode (the default of `devsurf
// serve`, for one daemon).
//
// Durability
// ----------
// Every mutating method returns only after its transaction has COMMITted, so an edit acknowledged
// after appendEdit()/appendEdits() returns is "durable" in the sense chosen at construction:
//   Durability::Process  PRAGMA synchronous=NORMAL. In WAL mode a commit write()s the WAL frames
//                        before returning but does not fsync; the data then lives in the kernel's
//                        page cache and survives the daemon dying in any way (SIGKILL, abort,
//                        OOM kill). It does NOT survive power loss or a kernel crash: the last
//                        transactions before such an event can be lost (the database still
//                        reopens consistently, never half-applied). fsync happens at checkpoints.
//   Durability::Power    PRAGMA synchronous=FULL. The WAL is fsynced on every commit, so
//                        commits also survive power loss (given storage that honours fsync);
//                        each commit costs a disk flush.
//
// Threading
// ---------
// All methods are thread-safe. A store owns two connections: one writer (every mutating method,
// serialised by a mutex) and one reader (every const method, serialised by another mutex). In WAL
// mode the reader never waits for the writer, and it sees every transaction committed before the
// read started. Other processes may open the same file (busy_timeout applies), but the daemon is
// expected to be its only writer. WAL needs shared memory between connections, so DIR must be
// on a local file system (not NFS/SMB).
//
// Schema
// ------
// Versioned with PRAGMA user_version (Store::kSchemaVersion). Tables are STRICT (SQLite ≥ 3.37).
// JSON is stored as compact text, so the file can be inspected with sqlite3.

#include <memory>
#include <string>

#include "devsurf/server/store/Store.h"

namespace devsurf::server::store {

class SqliteStore final : public Store {
 public:
  static constexpr const char* kFileName = "devsurf.db";

  /// Opens (creating the directory and the database if missing) DIR/devsurf.db, switches it to
  /// WAL, enables foreign keys, sets busy_timeout and migrates the schema.
  /// @throws StoreError (a std::runtime_error) naming the path and SQLite's message, e.g. for a
  ///         file that is not an SQLite database or a schema newer than kSchemaVersion
  explicit SqliteStore(const std::string& directory, Durability durability = Durability::Process);
  SqliteStore(const std::string& directory, const StoreOptions& options);
  ~SqliteStore() override;

  StoreInfo info() const override;
  bool shared() const override { return false; }

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

}  // namespace devsurf::server::store
