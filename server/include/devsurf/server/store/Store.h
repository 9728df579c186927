#pragma once

// Persistence of the devsurf daemon: editing sessions (edit log + snapshots) and batch jobs.
//
// `Store` is the interface; two backends implement it with the same schema versions and the same
// behaviour (tests/server/store/StoreContractTest.cpp runs one suite against both):
//   SqliteStore    one SQLite database DIR/devsurf.db in WAL mode: the embedded default, for one
//                  daemon (store/SqliteStore.h).
//   PostgresStore  a PostgreSQL database shared by several daemons and workers (`devsurf serve
//                  --store postgresql://…`, issue 18; store/PostgresStore.h).
// openStore() picks one from a location string.
//
// Every mutating method returns only after its transaction has committed: an edit acknowledged
// after appendEdit()/appendEdits() returns is stored (how durably: see each backend).
//
// Jobs on a shared queue
// ----------------------
// A job runs under a lease: claimJob() takes the oldest queued job (or a running one whose lease
// expired: its worker died) for one owner (a node id) until nowMs + leaseMs and counts the
// attempt; the worker renews the lease while it solves (renewJobLease, which also stores progress
// and reports a cancellation asked for on any node); finishJob() writes the result only while
// the caller still holds that lease and attempt, so a result is written once even when a worker
// that lost its lease finishes later.
//
// Sessions held by one node
// -------------------------
// On a shared store a daemon serves a session only while it holds the session's lease
// (acquireSessionLease, renewed by renewSessionLeases); a session whose node died is taken over
// by the next node that acquires it after the lease ended, which replays the stored journal. A
// store told its owner (setSessionOwner) refuses edits and snapshots of sessions another owner
// leases (LeaseLostError), so a node that lost a lease cannot write over its successor.
//
// All methods of both backends are thread-safe.

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace devsurf::server::store {

// --- errors -------------------------------------------------------------------------------------

/// Every error of the store (open failures, SQLite errors, corrupt rows) derives from this.
class StoreError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A session or job that the operation needs does not exist.
class NotFoundError : public StoreError {
 public:
  using StoreError::StoreError;
};

/// appendEdits/saveSnapshot on a session another node leases (Store::setSessionOwner). Nothing
/// was written.
class LeaseLostError : public StoreError {
 public:
  using StoreError::StoreError;
};

/// createSession/putJob with an id that is already stored.
class AlreadyExistsError : public StoreError {
 public:
  using StoreError::StoreError;
};

/// appendEdit(s) with a seq other than lastSeq + 1. Nothing was written.
class SeqConflictError : public StoreError {
 public:
  SeqConflictError(const std::string& sessionId, std::int64_t expectedSeq, std::int64_t gotSeq);
  std::int64_t expectedSeq() const noexcept { return expected_; }
  std::int64_t gotSeq() const noexcept { return got_; }

 private:
  std::int64_t expected_, got_;
};

/// putJob with an idempotency key that another stored job already carries. The caller compares
/// existingFingerprint() with its request's fingerprint: equal → replay the existing job,
/// different → reject the request (key reused for another body).
class IdempotencyConflictError : public StoreError {
 public:
  IdempotencyConflictError(std::string key, std::string existingJobId,
                           std::string existingFingerprint);
  const std::string& key() const noexcept { return key_; }
  const std::string& existingJobId() const noexcept { return existingJobId_; }
  const std::string& existingFingerprint() const noexcept { return existingFingerprint_; }

 private:
  std::string key_, existingJobId_, existingFingerprint_;
};

// --- records ------------------------------------------------------------------------------------

/// Milliseconds since the Unix epoch (system clock); the default time stamp of edits.
std::int64_t wallClockMs();

/// An editing session as created. Immutable after createSession.
struct SessionRecord {
  std::string id;                 ///< primary key
  std::string editTokenHash;      ///< hash of the edit capability token (never the token)
  std::string viewTokenHash;      ///< hash of the view capability token
  std::string name;
  bool demo = false;
  nlohmann::json initialScene;    ///< the scene at seq 0
  std::int64_t createdMs = 0;     ///< stored as given
  /// Set (by quarantineSession) when a restart could not restore the session: why. Such a
  /// session is kept with everything it stored, never deleted by the daemon.
  std::optional<std::string> quarantine;
};

/// One accepted edit. Seqs are per session, start at 1 and have no gaps.
struct EditRecord {
  std::int64_t seq = 0;
  nlohmann::json edit;
  std::int64_t timeMs = 0;        ///< when it was accepted (ms since epoch)
};

/// The full scene after applying edits 1..seq to the initial scene, with what the session keeps
/// beside it (sessionState: null or an object of the session's choosing) and the revision of the
/// state participants were shown (a session checkpoints every state it shows; several snapshots
/// of one seq replace each other).
struct Snapshot {
  std::int64_t seq = 0;
  nlohmann::json scene;
  nlohmann::json sessionState;    ///< null when saved without one
  std::int64_t revision = 0;
};

/// What a restart needs to rebuild a session: start from snapshot->scene (or session.initialScene
/// when there is no snapshot) and apply editsAfterSnapshot in order. Invariant:
/// editsAfterSnapshot's seqs are exactly (snapshot ? snapshot->seq : 0) + 1 .. lastSeq.
struct RestoredSession {
  SessionRecord session;
  std::optional<Snapshot> snapshot;       ///< the newest snapshot
  std::vector<EditRecord> editsAfterSnapshot;
  std::int64_t lastSeq = 0;               ///< seq of the last acknowledged edit (0: none)
  /// Set when a stored row of the session does not parse (snapshot and edits are then
  /// incomplete): the session cannot be restored and should be quarantined.
  std::optional<std::string> loadError;
};

enum class JobState { Queued, Running, Succeeded, Failed, Cancelled };

/// "queued", "running", "succeeded", "failed", "cancelled" (the names stored and served).
std::string jobStateName(JobState state);
/// Inverse of jobStateName. @throws std::invalid_argument for any other string
JobState jobStateFromName(const std::string& name);
/// Succeeded, Failed and Cancelled.
bool isFinished(JobState state);

struct JobRecord {
  std::string id;                           ///< primary key
  JobState state = JobState::Queued;
  nlohmann::json scene;                     ///< the scene to solve (immutable)
  std::optional<std::string> idempotencyKey;  ///< unique among stored jobs when set (immutable)
  std::string idempotencyFingerprint;       ///< hash of the request body (immutable)
  std::optional<nlohmann::json> report;     ///< the solve report once succeeded
  std::optional<std::string> error;         ///< the message once failed
  std::int64_t createdMs = 0;               ///< immutable
  std::int64_t updatedMs = 0;
  int progressIteration = 0;
  int progressOf = 0;
  /// The node that runs it (state Running): set by claimJob, cleared when it finishes or is
  /// re-queued.
  std::optional<std::string> leaseOwner;
  std::int64_t leaseExpiresMs = 0;   ///< the lease ends then unless renewed (ms since epoch)
  int attempt = 0;                   ///< how many times the job was claimed
  bool cancelRequested = false;      ///< a cancellation asked for while it was running
};

// --- the store ----------------------------------------------------------------------------------

enum class Durability {
  Process,  ///< SQLite synchronous=NORMAL: survives process death, not power loss (default)
  Power,    ///< SQLite synchronous=FULL: survives power loss too, one fsync per commit
};

struct StoreOptions {
  Durability durability = Durability::Process;  ///< SQLite only (PostgreSQL: the server's settings)
  /// How long a statement waits for a lock held by another connection before failing.
  std::chrono::milliseconds busyTimeout{5000};
  /// Snapshots kept per session (≥ 1). With the default 2, saveSnapshot keeps the new and the
  /// previous snapshot and the edits after the previous one; older ones are pruned.
  int keepSnapshots = 2;
  /// PostgreSQL: connections kept open (≥ 1); each one serves one operation at a time.
  int connections = 4;
  /// PostgreSQL: lease times (claims, renewals, expiries) are read from the database server's
  /// clock, not from the callers' nowMs, so that nodes whose clocks disagree still agree on when a
  /// lease ends. Off only in tests that play with time.
  bool serverClock = true;
};

/// Facts about an open store, for logs and health endpoints.
struct StoreInfo {
  std::string backend;       ///< "sqlite" or "postgresql"
  std::string path;          ///< SQLite: DIR/devsurf.db; PostgreSQL: the URL without its password
  int schemaVersion = 0;
  std::string journalMode;   ///< SQLite: "wal"; PostgreSQL: empty
  std::string synchronous;   ///< SQLite: "NORMAL" or "FULL"; PostgreSQL: synchronous_commit
};

/// What renewJobLease found.
struct JobLeaseRenewal {
  bool held = false;             ///< false: the lease was lost (expired and taken, or job gone)
  bool cancelRequested = false;  ///< someone asked to cancel the job
};

class Store {
 public:
  /// The schema version both backends migrate to (SQLite: PRAGMA user_version; PostgreSQL: the
  /// table devsurf_schema). Opening an older database migrates it step by step, each step in its
  /// own transaction; a newer one is refused.
  static constexpr int kSchemaVersion = 4;

  virtual ~Store() = default;
  Store() = default;
  Store(const Store&) = delete;
  Store& operator=(const Store&) = delete;

  virtual StoreInfo info() const = 0;
  /// True when other processes share the store (PostgreSQL): a job marked running may be
  /// another node's, so a starting daemon re-queues only its own (releaseJobLeases).
  virtual bool shared() const = 0;

  // --- sessions ---

  /// @throws AlreadyExistsError if the id exists
  virtual void createSession(const SessionRecord& session) = 0;
  /// Removes the session with its edits and snapshots. @return false if it did not exist
  virtual bool deleteSession(const std::string& id) = 0;

  /// Appends one edit; stored when it returns. timeMs defaults to now.
  /// @throws SeqConflictError unless seq == lastSeq + 1, NotFoundError for an unknown session
  void appendEdit(const std::string& sessionId, std::int64_t seq, const nlohmann::json& edit,
                  std::optional<std::int64_t> timeMs = std::nullopt);
  /// Appends several edits in one transaction (coalesced drags): their seqs must be
  /// lastSeq+1, lastSeq+2, … in order. All or nothing; an empty batch is a no-op.
  /// @throws SeqConflictError, NotFoundError (nothing written)
  virtual void appendEdits(const std::string& sessionId, const std::vector<EditRecord>& edits) = 0;
  /// @return the seq of the last stored edit (0: none). @throws NotFoundError
  virtual std::int64_t lastSeq(const std::string& sessionId) const = 0;

  /// Stores the scene as it is after edit `seq` (0 ≤ seq ≤ lastSeq, not older than the newest
  /// snapshot; an equal seq replaces it). Then prunes per StoreOptions::keepSnapshots: snapshots
  /// older than the keepSnapshots-th newest, and edits with seq ≤ that snapshot's seq.
  /// @throws NotFoundError, StoreError for a seq outside that range
  void saveSnapshot(const std::string& sessionId, std::int64_t seq, const nlohmann::json& scene);
  /// The same with the session's own state and the revision (Snapshot::sessionState, revision).
  virtual void saveSnapshot(const std::string& sessionId, const Snapshot& snapshot) = 0;
  /// Marks a session that could not be restored (SessionRecord::quarantine = reason); it stays
  /// with its initial scene, snapshots and edits. @throws NotFoundError
  virtual void quarantineSession(const std::string& id, const std::string& reason) = 0;
  /// Clears the mark (the session was restored after all). @throws NotFoundError
  virtual void liftQuarantine(const std::string& id) = 0;

  /// Every session, oldest first (createdMs, then id), each read in one consistent transaction.
  virtual std::vector<RestoredSession> loadSessions() const = 0;
  virtual std::optional<RestoredSession> loadSession(const std::string& id) const = 0;

  /// This store writes for `owner` (a node id; empty = no fencing, the default): appendEdits and
  /// saveSnapshot throw LeaseLostError for a session whose lease another owner holds.
  void setSessionOwner(std::string owner) { sessionOwner_ = std::move(owner); }
  const std::string& sessionOwner() const { return sessionOwner_; }
  /// Takes or extends the lease of a session for `owner` until nowMs + leaseMs: when nobody holds
  /// it, `owner` already does, or the holder's lease ended before nowMs (a pending handover
  /// request is then cleared).
  /// @return false when another owner holds it. @throws NotFoundError
  virtual bool acquireSessionLease(const std::string& id, const std::string& owner, std::int64_t nowMs,
                                   std::int64_t leaseMs) = 0;
  /// Extends the session leases `owner` holds to nowMs + leaseMs, except those another node asked
  /// for (requestSessionHandover), which are released in the same transaction.
  /// @return the ids of the sessions `owner` still holds
  virtual std::vector<std::string> renewSessionLeases(const std::string& owner, std::int64_t nowMs,
                                                      std::int64_t leaseMs) = 0;
  /// Asks the holder of a session's lease to hand it over (its next renewal releases it): the
  /// proxy now routes the session to `requester`. No effect when nobody or `requester` holds it.
  virtual void requestSessionHandover(const std::string& id, const std::string& requester) = 0;
  /// Ends the leases `owner` holds now (a node that stops): others may take them at once, and
  /// they keep naming `owner`, so a restart under the same id takes back what nobody took
  /// meanwhile (sessionsLeasedBy). @return how many
  virtual int endSessionLeases(const std::string& owner) = 0;
  /// The sessions whose lease `owner` holds or held last (a node restarted under the same id takes
  /// them back at once), oldest first.
  virtual std::vector<std::string> sessionsLeasedBy(const std::string& owner) const = 0;
  /// The owner of a session's lease and when it ends (nullopt: none). @throws NotFoundError
  virtual std::optional<std::pair<std::string, std::int64_t>> sessionLease(const std::string& id) const = 0;

  // --- jobs ---

  /// Inserts a new job.
  /// @throws IdempotencyConflictError if job.idempotencyKey is set and already stored,
  ///         AlreadyExistsError if the id exists
  virtual void putJob(const JobRecord& job) = 0;
  virtual std::optional<JobRecord> jobByIdempotencyKey(const std::string& key) const = 0;
  /// Writes the mutable fields: state, report, error, updatedMs, progressIteration, progressOf
  /// (unconditionally: a worker's final write goes through finishJob).
  /// @throws NotFoundError
  virtual void updateJob(const JobRecord& job) = 0;
  virtual std::optional<JobRecord> job(const std::string& id) const = 0;
  /// Queued and Running jobs, oldest first (createdMs, then id).
  virtual std::vector<JobRecord> unfinishedJobs() const = 0;
  /// Number of jobs per state; every state is present (0 when none).
  virtual std::map<JobState, int> jobCounts() const = 0;
  /// Deletes Succeeded/Failed/Cancelled jobs with updatedMs < olderThanMs (their idempotency
  /// keys become free again). @return how many were deleted
  virtual int pruneFinishedJobs(std::int64_t olderThanMs) = 0;

  /// Lease methods take the caller's time as nowMs; PostgresStore uses its server's clock instead
  /// unless StoreOptions::serverClock is off.
  /// Claims the oldest queued job, or else the oldest running job whose lease ended before nowMs:
  /// it becomes Running, leased to `owner` until nowMs + leaseMs, attempt + 1, progress 0. Two
  /// callers never claim the same job (PostgreSQL: SELECT … FOR UPDATE SKIP LOCKED).
  /// @return the claimed job as stored after the claim, or nullopt when there is none
  virtual std::optional<JobRecord> claimJob(const std::string& owner, std::int64_t nowMs,
                                            std::int64_t leaseMs) = 0;
  /// Extends the lease of a running job that `owner` holds in `attempt` to nowMs + leaseMs and
  /// stores its progress.
  virtual JobLeaseRenewal renewJobLease(const std::string& id, const std::string& owner, int attempt,
                                        std::int64_t nowMs, std::int64_t leaseMs,
                                        int progressIteration, int progressOf) = 0;
  /// Writes a claimed job's final fields (state, report, error, updatedMs, progress) and clears
  /// its lease, only if it is still Running under `owner` and `attempt`.
  /// @return false when the lease was lost: nothing written (another attempt owns the job)
  virtual bool finishJob(const JobRecord& job, const std::string& owner, int attempt) = 0;
  /// A queued job becomes Cancelled at once; a running one is marked (cancelRequested) for its
  /// worker to stop, wherever it runs. @return the job's state after the call (Cancelled, Running
  /// or the finished state it already had). @throws NotFoundError
  virtual JobState requestJobCancel(const std::string& id, std::int64_t nowMs) = 0;
  /// Sets the running jobs leased to `owner` back to Queued (progress 0, lease cleared): a node
  /// that stops, or restarts under the same id. @return how many
  virtual int releaseJobLeases(const std::string& owner, std::int64_t nowMs) = 0;
  /// At the start of the only daemon of an embedded store: sets every Running job back to Queued
  /// (progressIteration = 0, updatedMs = nowMs, lease cleared). @return how many were re-queued
  virtual int requeueInterruptedJobs(std::int64_t nowMs) = 0;

 protected:
  /// Throws LeaseLostError when sessionOwner_ is set and `holder` (the session's lease owner, if
  /// any) is another owner.
  void checkSessionOwner(const std::string& sessionId, const std::optional<std::string>& holder) const;

 private:
  std::string sessionOwner_;
};

/// Opens the store a location names: "postgresql://…" or "postgres://…" (a libpq connection URI)
/// opens PostgresStore, anything else is a directory for SqliteStore.
/// @throws StoreError naming the location
std::unique_ptr<Store> openStore(const std::string& location, const StoreOptions& options = {});
/// True when openStore would open PostgreSQL for this location.
bool isPostgresLocation(const std::string& location);

}  // namespace devsurf::server::store
