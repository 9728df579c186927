#pragma once

// Persistence of the devsurf daemon: editing sessions (edit log + snapshots) and batch jobs, in
// one SQLite database DIR/devsurf.db in WAL mode.
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
// All methods are thread-safe. A Store owns two connections: one writer (every mutating method,
// serialised by a mutex) and one reader (every const method, serialised by another mutex). In WAL
// mode the reader never waits for the writer, and it sees every transaction committed before the
// read started. Other processes may open the same file (busy_timeout applies), but the daemon is
// expected to be its only writer. WAL needs shared memory between connections, so DIR must be
// on a local file system (not NFS/SMB).
//
// Schema
// ------
// Versioned with PRAGMA user_version (Store::kSchemaVersion); opening an older database migrates
// it step by step, each step in its own transaction; a newer one is refused. Tables are STRICT
// (SQLite ≥ 3.37). JSON is stored as compact text, so the file can be inspected with sqlite3.

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
};

// --- the store ----------------------------------------------------------------------------------

enum class Durability {
  Process,  ///< synchronous=NORMAL: survives process death, not power loss (default)
  Power,    ///< synchronous=FULL: survives power loss too, one fsync per commit
};

struct StoreOptions {
  Durability durability = Durability::Process;
  /// How long a statement waits for a lock held by another connection before failing.
  std::chrono::milliseconds busyTimeout{5000};
  /// Snapshots kept per session (≥ 1). With the default 2, saveSnapshot keeps the new and the
  /// previous snapshot and the edits after the previous one; older ones are pruned.
  int keepSnapshots = 2;
};

/// Facts about an open store, for logs and health endpoints.
struct StoreInfo {
  std::string path;          ///< DIR/devsurf.db
  int schemaVersion = 0;     ///< PRAGMA user_version
  std::string journalMode;   ///< "wal"
  std::string synchronous;   ///< "NORMAL" or "FULL"
};

class Store {
 public:
  static constexpr int kSchemaVersion = 2;
  static constexpr const char* kFileName = "devsurf.db";

  /// Opens (creating the directory and the database if missing) DIR/devsurf.db, switches it to
  /// WAL, enables foreign keys, sets busy_timeout and migrates the schema.
  /// @throws StoreError (a std::runtime_error) naming the path and SQLite's message, e.g. for a
  ///         file that is not an SQLite database or a schema newer than kSchemaVersion
  explicit Store(const std::string& directory, Durability durability = Durability::Process);
  Store(const std::string& directory, const StoreOptions& options);
  ~Store();
  Store(const Store&) = delete;
  Store& operator=(const Store&) = delete;

  StoreInfo info() const;

  // --- sessions ---

  /// @throws AlreadyExistsError if the id exists
  void createSession(const SessionRecord& session);
  /// Removes the session with its edits and snapshots. @return false if it did not exist
  bool deleteSession(const std::string& id);

  /// Appends one edit; durable when it returns. timeMs defaults to now.
  /// @throws SeqConflictError unless seq == lastSeq + 1, NotFoundError for an unknown session
  void appendEdit(const std::string& sessionId, std::int64_t seq, const nlohmann::json& edit,
                  std::optional<std::int64_t> timeMs = std::nullopt);
  /// Appends several edits in one transaction (coalesced drags): their seqs must be
  /// lastSeq+1, lastSeq+2, … in order. All or nothing; an empty batch is a no-op.
  /// @throws SeqConflictError, NotFoundError (nothing written)
  void appendEdits(const std::string& sessionId, const std::vector<EditRecord>& edits);
  /// @return the seq of the last stored edit (0: none). @throws NotFoundError
  std::int64_t lastSeq(const std::string& sessionId) const;

  /// Stores the scene as it is after edit `seq` (0 ≤ seq ≤ lastSeq, not older than the newest
  /// snapshot; an equal seq replaces it). Then prunes per StoreOptions::keepSnapshots: snapshots
  /// older than the keepSnapshots-th newest, and edits with seq ≤ that snapshot's seq.
  /// @throws NotFoundError, StoreError for a seq outside that range
  void saveSnapshot(const std::string& sessionId, std::int64_t seq, const nlohmann::json& scene);
  /// The same with the session's own state and the revision (Snapshot::sessionState, revision).
  void saveSnapshot(const std::string& sessionId, const Snapshot& snapshot);
  /// Marks a session that could not be restored (SessionRecord::quarantine = reason); it stays
  /// with its initial scene, snapshots and edits. @throws NotFoundError
  void quarantineSession(const std::string& id, const std::string& reason);
  /// Clears the mark (the session was restored after all). @throws NotFoundError
  void liftQuarantine(const std::string& id);

  /// Every session, oldest first (createdMs, then id), each read in one consistent transaction.
  std::vector<RestoredSession> loadSessions() const;
  std::optional<RestoredSession> loadSession(const std::string& id) const;

  // --- jobs ---

  /// Inserts a new job.
  /// @throws IdempotencyConflictError if job.idempotencyKey is set and already stored,
  ///         AlreadyExistsError if the id exists
  void putJob(const JobRecord& job);
  std::optional<JobRecord> jobByIdempotencyKey(const std::string& key) const;
  /// Writes the mutable fields: state, report, error, updatedMs, progressIteration, progressOf.
  /// @throws NotFoundError
  void updateJob(const JobRecord& job);
  std::optional<JobRecord> job(const std::string& id) const;
  /// Queued and Running jobs, oldest first (createdMs, then id). Running ones were interrupted
  /// by a restart; see requeueInterruptedJobs.
  std::vector<JobRecord> unfinishedJobs() const;
  /// At startup: sets every Running job back to Queued (progressIteration = 0,
  /// updatedMs = nowMs).
  /// @return how many were re-queued
  int requeueInterruptedJobs(std::int64_t nowMs);
  /// Number of jobs per state; every state is present (0 when none).
  std::map<JobState, int> jobCounts() const;
  /// Deletes Succeeded/Failed/Cancelled jobs with updatedMs < olderThanMs (their idempotency
  /// keys become free again). @return how many were deleted
  int pruneFinishedJobs(std::int64_t olderThanMs);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace devsurf::server::store
