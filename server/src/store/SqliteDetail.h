#pragma once

// Private to server/src/store: the SQLite helpers and SqliteStore::Impl shared by
// SqliteStore.cpp (sessions, jobs) and SqliteStoreLeases.cpp (leases).

#include "devsurf/server/store/SqliteStore.h"

#include <fcntl.h>
#include <unistd.h>

#include <sqlite3.h>

#include <filesystem>
#include <mutex>
#include <system_error>
#include <unordered_map>
#include <utility>

namespace devsurf::server::store {

// Helpers of the SQLite backend (not anonymous: SqliteStore::Impl holds them).
namespace sqlite {

// --- schema -------------------------------------------------------------------------------------

// kMigrations[v] takes a database from user_version v to v + 1. Append, never edit.
inline const char* const kMigrations[] = {
    // v0 → v1
    R"sql(
CREATE TABLE sessions (
  id              TEXT NOT NULL PRIMARY KEY,
  edit_token_hash TEXT NOT NULL,
  view_token_hash TEXT NOT NULL,
  name            TEXT NOT NULL,
  demo            INTEGER NOT NULL CHECK (demo IN (0, 1)),
  initial_scene   TEXT NOT NULL,
  created_ms      INTEGER NOT NULL,
  last_seq        INTEGER NOT NULL DEFAULT 0 CHECK (last_seq >= 0)
) STRICT;
CREATE TABLE edits (
  session_id TEXT NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  seq        INTEGER NOT NULL CHECK (seq >= 1),
  edit       TEXT NOT NULL,
  time_ms    INTEGER NOT NULL,
  PRIMARY KEY (session_id, seq)
) STRICT;
CREATE TABLE snapshots (
  session_id TEXT NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  seq        INTEGER NOT NULL CHECK (seq >= 0),
  scene      TEXT NOT NULL,
  created_ms INTEGER NOT NULL,
  PRIMARY KEY (session_id, seq)
) STRICT;
CREATE TABLE jobs (
  id                      TEXT NOT NULL PRIMARY KEY,
  state                   TEXT NOT NULL
                          CHECK (state IN ('queued','running','succeeded','failed','cancelled')),
  scene                   TEXT NOT NULL,
  idempotency_key         TEXT UNIQUE,
  idempotency_fingerprint TEXT NOT NULL,
  report                  TEXT,
  error                   TEXT,
  created_ms              INTEGER NOT NULL,
  updated_ms              INTEGER NOT NULL,
  progress_iteration      INTEGER NOT NULL DEFAULT 0,
  progress_of             INTEGER NOT NULL DEFAULT 0
) STRICT;
CREATE INDEX jobs_by_state ON jobs (state, updated_ms);
)sql",
    // v1 → v2: a snapshot carries the session's own state beside the scene and the revision of
    // what participants were shown (a checkpoint per shown state, issue 12); a session that could
    // not be restored is kept with the reason.
    R"sql(
ALTER TABLE snapshots ADD COLUMN session_state TEXT;
ALTER TABLE snapshots ADD COLUMN revision INTEGER NOT NULL DEFAULT 0;
ALTER TABLE sessions ADD COLUMN quarantine TEXT;
)sql",
    // v2 → v3: jobs run under leases on a shared queue (issue 18): the node that runs a job, until
    // when, how many times it was claimed, and a cancellation asked for while it runs.
    R"sql(
ALTER TABLE jobs ADD COLUMN lease_owner TEXT;
ALTER TABLE jobs ADD COLUMN lease_expires_ms INTEGER NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN attempt INTEGER NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN cancel_requested INTEGER NOT NULL DEFAULT 0 CHECK (cancel_requested IN (0, 1));
)sql",
    // v3 → v4: sessions held by one node under a lease (issue 18).
    R"sql(
ALTER TABLE sessions ADD COLUMN lease_owner TEXT;
ALTER TABLE sessions ADD COLUMN lease_expires_ms INTEGER NOT NULL DEFAULT 0;
ALTER TABLE sessions ADD COLUMN handover_to TEXT;
)sql",
};
static_assert(sizeof(kMigrations) / sizeof(kMigrations[0]) == Store::kSchemaVersion,
              "one migration per schema version");

// --- small RAII layer over the SQLite C API -----------------------------------------------------

struct CloseDb {
  void operator()(sqlite3* db) const { sqlite3_close_v2(db); }
};
struct FinalizeStmt {
  void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
};

/// One sqlite3 connection with a cache of prepared statements. Not thread-safe by itself: each
/// is guarded by a mutex in Store::Impl.
class Connection {
 public:
  Connection(const std::string& path, int flags, const StoreOptions& options) : path_(path) {
    sqlite3* raw = nullptr;
    int rc = sqlite3_open_v2(path.c_str(), &raw, flags | SQLITE_OPEN_NOMUTEX, nullptr);
    db_.reset(raw);  // closed even when the open failed
    if (rc != SQLITE_OK) fail(rc, "cannot open");
    sqlite3_extended_result_codes(raw, 1);
    sqlite3_busy_timeout(raw, static_cast<int>(options.busyTimeout.count()));
  }

  sqlite3* handle() const { return db_.get(); }
  const std::string& path() const { return path_; }

  [[noreturn]] void fail(int rc, const std::string& context) const {
    const char* msg = db_ ? sqlite3_errmsg(db_.get()) : sqlite3_errstr(rc);
    throw StoreError("devsurf store " + path_ + ": " + context + ": " + msg + " (SQLite code " +
                     std::to_string(rc) + ")");
  }

  /// Runs SQL text that may hold several statements (migrations, pragmas with literals).
  void exec(const std::string& sql) {
    char* err = nullptr;
    int rc = sqlite3_exec(db_.get(), sql.c_str(), nullptr, nullptr, &err);
    if (rc != SQLITE_OK) {
      std::string msg = err ? err : sqlite3_errstr(rc);
      sqlite3_free(err);
      throw StoreError("devsurf store " + path_ + ": " + firstLine(sql) + ": " + msg +
                       " (SQLite code " + std::to_string(rc) + ")");
    }
  }

  sqlite3_stmt* prepared(const char* sql) {
    auto it = cache_.find(sql);
    if (it != cache_.end()) return it->second.get();
    sqlite3_stmt* raw = nullptr;
    int rc = sqlite3_prepare_v3(db_.get(), sql, -1, SQLITE_PREPARE_PERSISTENT, &raw, nullptr);
    std::unique_ptr<sqlite3_stmt, FinalizeStmt> stmt(raw);
    if (rc != SQLITE_OK) fail(rc, std::string("cannot prepare ") + sql);
    return cache_.emplace(sql, std::move(stmt)).first->second.get();
  }

  int changes() const { return sqlite3_changes(db_.get()); }

 private:
  static std::string firstLine(const std::string& sql) {
    auto begin = sql.find_first_not_of(" \n");
    if (begin == std::string::npos) return sql;
    return sql.substr(begin, sql.find('\n', begin) - begin);
  }

  std::string path_;
  std::unique_ptr<sqlite3, CloseDb> db_;  // declared before cache_: statements finalize first
  std::unordered_map<std::string, std::unique_ptr<sqlite3_stmt, FinalizeStmt>> cache_;
};

/// One use of a cached prepared statement: bind, step, read columns; reset on destruction.
class Query {
 public:
  Query(Connection& c, const char* sql) : c_(c), s_(c.prepared(sql)) {}
  ~Query() {
    sqlite3_reset(s_);
    sqlite3_clear_bindings(s_);
  }
  Query(const Query&) = delete;
  Query& operator=(const Query&) = delete;

  Query& bind(int i, std::int64_t v) { return check(sqlite3_bind_int64(s_, i, v)); }
  Query& bind(int i, int v) { return bind(i, static_cast<std::int64_t>(v)); }
  Query& bind(int i, bool v) { return bind(i, static_cast<std::int64_t>(v ? 1 : 0)); }
  Query& bind(int i, const std::string& v) {
    return check(sqlite3_bind_text64(s_, i, v.data(), v.size(), SQLITE_TRANSIENT, SQLITE_UTF8));
  }
  Query& bind(int i, const char* v) = delete;  // avoid the bool overload by accident
  Query& bind(int i, const std::optional<std::string>& v) {
    return v ? bind(i, *v) : check(sqlite3_bind_null(s_, i));
  }

  /// @return true when a row is available, false when done
  bool step() {
    int rc = sqlite3_step(s_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    c_.fail(rc, sqlite3_sql(s_));
  }
  /// Steps a statement that returns no rows (or whose rows are irrelevant).
  void run() {
    while (step()) {
    }
  }

  bool isNull(int col) const { return sqlite3_column_type(s_, col) == SQLITE_NULL; }
  std::int64_t int64(int col) const { return sqlite3_column_int64(s_, col); }
  std::string text(int col) const {
    auto p = reinterpret_cast<const char*>(sqlite3_column_text(s_, col));
    return p ? std::string(p, static_cast<std::size_t>(sqlite3_column_bytes(s_, col)))
             : std::string();
  }
  std::optional<std::string> optText(int col) const {
    if (isNull(col)) return std::nullopt;
    return text(col);
  }

 private:
  Query& check(int rc) {
    if (rc != SQLITE_OK) c_.fail(rc, std::string("cannot bind to ") + sqlite3_sql(s_));
    return *this;
  }

  Connection& c_;
  sqlite3_stmt* s_;
};

/// BEGIN … COMMIT; rolls back when left without commit() (an exception).
class Transaction {
 public:
  enum Kind { Read, Write };
  Transaction(Connection& c, Kind kind) : c_(c) {
    // Write transactions take the write lock up front (BEGIN IMMEDIATE) so that a
    // read-then-write never fails with SQLITE_BUSY half-way; busy_timeout applies to BEGIN.
    Query(c_, kind == Write ? "BEGIN IMMEDIATE" : "BEGIN").run();
  }
  ~Transaction() {
    if (!done_ && !sqlite3_get_autocommit(c_.handle())) {
      sqlite3_exec(c_.handle(), "ROLLBACK", nullptr, nullptr, nullptr);
    }
  }
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;

  void commit() {
    Query(c_, "COMMIT").run();
    done_ = true;
  }

 private:
  Connection& c_;
  bool done_ = false;
};

inline nlohmann::json parseJson(const std::string& text, const std::string& what) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw StoreError("devsurf store: corrupt JSON in " + what + ": " + e.what());
  }
}

inline std::string pragmaText(Connection& c, const char* sql) {
  Query q(c, sql);
  if (!q.step()) throw StoreError("devsurf store " + c.path() + ": " + sql + " returned no row");
  return q.text(0);
}

inline int userVersion(Connection& c) {
  Query q(c, "PRAGMA user_version");
  q.step();
  return static_cast<int>(q.int64(0));
}

inline void migrate(Connection& c) {
  for (;;) {
    int version = userVersion(c);
    if (version > Store::kSchemaVersion) {
      throw StoreError("devsurf store " + c.path() + ": schema version " +
                       std::to_string(version) + " is newer than this build supports (" +
                       std::to_string(Store::kSchemaVersion) + ")");
    }
    if (version == Store::kSchemaVersion) return;
    Transaction t(c, Transaction::Write);
    if (userVersion(c) != version) continue;  // another process migrated meanwhile
    c.exec(kMigrations[version]);
    c.exec("PRAGMA user_version = " + std::to_string(version + 1));
    t.commit();
  }
}

// Column lists shared by the SELECTs and the readers below.
#define DEVSURF_SESSION_COLUMNS \
  "id, edit_token_hash, view_token_hash, name, demo, initial_scene, created_ms, last_seq, quarantine"
#define DEVSURF_JOB_COLUMNS                                                                   \
  "id, state, scene, idempotency_key, idempotency_fingerprint, report, error, created_ms, " \
  "updated_ms, progress_iteration, progress_of, lease_owner, lease_expires_ms, attempt, "   \
  "cancel_requested"

inline JobRecord readJob(const Query& q) {
  JobRecord j;
  j.id = q.text(0);
  j.state = jobStateFromName(q.text(1));
  j.scene = parseJson(q.text(2), "scene of job " + j.id);
  j.idempotencyKey = q.optText(3);
  j.idempotencyFingerprint = q.text(4);
  if (!q.isNull(5)) j.report = parseJson(q.text(5), "report of job " + j.id);
  j.error = q.optText(6);
  j.createdMs = q.int64(7);
  j.updatedMs = q.int64(8);
  j.progressIteration = static_cast<int>(q.int64(9));
  j.progressOf = static_cast<int>(q.int64(10));
  j.leaseOwner = q.optText(11);
  j.leaseExpiresMs = q.int64(12);
  j.attempt = static_cast<int>(q.int64(13));
  j.cancelRequested = q.int64(14) != 0;
  return j;
}

}  // namespace sqlite


// --- the store's state ------------------------------------------------------------------------

struct SqliteStore::Impl {
  StoreOptions options;
  std::string path;
  std::mutex writeMutex;
  std::unique_ptr<sqlite::Connection> writer;  // every mutating method
  std::mutex readMutex;
  std::unique_ptr<sqlite::Connection> reader;  // every const method

  // Reads one session inside the caller's read transaction on `c`.
  static std::optional<RestoredSession> readSession(sqlite::Connection& c, const std::string& id) {
    RestoredSession r;
    {
      sqlite::Query q(c, "SELECT " DEVSURF_SESSION_COLUMNS " FROM sessions WHERE id = ?");
      q.bind(1, id);
      if (!q.step()) return std::nullopt;
      SessionRecord& s = r.session;
      s.id = q.text(0);
      s.editTokenHash = q.text(1);
      s.viewTokenHash = q.text(2);
      s.name = q.text(3);
      s.demo = q.int64(4) != 0;
      s.createdMs = q.int64(6);
      r.lastSeq = q.int64(7);
      s.quarantine = q.optText(8);
      try {
        s.initialScene = sqlite::parseJson(q.text(5), "initial scene of session " + id);
      } catch (const StoreError& e) {
        r.loadError = e.what();  // quarantined by the caller; every other session is restored
        return r;
      }
    }
    // A row that does not parse makes this session unrestorable, not the store: the caller
    // quarantines it (loadError) and every other session is restored.
    try {
      std::int64_t after = 0;
      {
        sqlite::Query q(c,
                "SELECT seq, scene, session_state, revision FROM snapshots WHERE session_id = ? "
                "ORDER BY seq DESC LIMIT 1");
        q.bind(1, id);
        if (q.step()) {
          after = q.int64(0);
          Snapshot snapshot{after, sqlite::parseJson(q.text(1), "snapshot of session " + id), nullptr, 0};
          if (!q.isNull(2)) snapshot.sessionState = sqlite::parseJson(q.text(2), "session state of session " + id);
          snapshot.revision = q.int64(3);
          r.snapshot = std::move(snapshot);
        }
      }
      sqlite::Query q(c,
              "SELECT seq, edit, time_ms FROM edits WHERE session_id = ? AND seq > ? ORDER BY seq");
      q.bind(1, id).bind(2, after);
      while (q.step()) {
        std::int64_t seq = q.int64(0);
        r.editsAfterSnapshot.push_back(
            EditRecord{seq,
                       sqlite::parseJson(q.text(1), "edit " + std::to_string(seq) + " of session " + id),
                       q.int64(2)});
      }
    } catch (const StoreError& e) {
      r.loadError = e.what();
    }
    return r;
  }

  // Current last_seq of a session inside the caller's transaction. @throws NotFoundError
  static std::int64_t lastSeqOf(sqlite::Connection& c, const std::string& id,
                                std::optional<std::string>* holder = nullptr) {
    sqlite::Query q(c, "SELECT last_seq, lease_owner FROM sessions WHERE id = ?");
    q.bind(1, id);
    if (!q.step()) throw NotFoundError("no session '" + id + "'");
    if (holder) *holder = q.optText(1);
    return q.int64(0);
  }

  static std::optional<JobRecord> readJobWhere(sqlite::Connection& c, const char* sql,
                                               const std::string& value) {
    sqlite::Query q(c, sql);
    q.bind(1, value);
    if (!q.step()) return std::nullopt;
    return sqlite::readJob(q);
  }
};

}  // namespace devsurf::server::store
