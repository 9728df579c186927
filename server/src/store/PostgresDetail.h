#pragma once

// Private to server/src/store: the libpq helpers and PostgresStore::Impl (the connection pool)
// shared by PostgresStore.cpp (sessions, jobs) and PostgresStoreLeases.cpp (leases).

#include "devsurf/server/store/PostgresStore.h"

#include <libpq-fe.h>

#include <condition_variable>
#include <mutex>
#include <regex>
#include <utility>

namespace devsurf::server::store {

// Helpers of the PostgreSQL backend; named apart from SqliteDetail.h's (one unity batch), and not in an
// anonymous namespace because PostgresStore::Impl holds them.
namespace pg {

// kMigrations[v] takes a database from version v to v + 1: the same steps as SqliteStore's, in
// PostgreSQL's types. Append, never edit.
inline const char* const kMigrations[] = {
    // v0 → v1
    R"sql(
CREATE TABLE sessions (
  id              TEXT NOT NULL PRIMARY KEY,
  edit_token_hash TEXT NOT NULL,
  view_token_hash TEXT NOT NULL,
  name            TEXT NOT NULL,
  demo            BOOLEAN NOT NULL,
  initial_scene   TEXT NOT NULL,
  created_ms      BIGINT NOT NULL,
  last_seq        BIGINT NOT NULL DEFAULT 0 CHECK (last_seq >= 0)
);
CREATE TABLE edits (
  session_id TEXT NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  seq        BIGINT NOT NULL CHECK (seq >= 1),
  edit       TEXT NOT NULL,
  time_ms    BIGINT NOT NULL,
  PRIMARY KEY (session_id, seq)
);
CREATE TABLE snapshots (
  session_id TEXT NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  seq        BIGINT NOT NULL CHECK (seq >= 0),
  scene      TEXT NOT NULL,
  created_ms BIGINT NOT NULL,
  PRIMARY KEY (session_id, seq)
);
CREATE TABLE jobs (
  id                      TEXT NOT NULL PRIMARY KEY,
  state                   TEXT NOT NULL
                          CHECK (state IN ('queued','running','succeeded','failed','cancelled')),
  scene                   TEXT NOT NULL,
  idempotency_key         TEXT UNIQUE,
  idempotency_fingerprint TEXT NOT NULL,
  report                  TEXT,
  error                   TEXT,
  created_ms              BIGINT NOT NULL,
  updated_ms              BIGINT NOT NULL,
  progress_iteration      INTEGER NOT NULL DEFAULT 0,
  progress_of             INTEGER NOT NULL DEFAULT 0
);
CREATE INDEX jobs_by_state ON jobs (state, updated_ms);
)sql",
    // v1 → v2: checkpoints with the session's state and revision; quarantined sessions.
    R"sql(
ALTER TABLE snapshots ADD COLUMN session_state TEXT;
ALTER TABLE snapshots ADD COLUMN revision BIGINT NOT NULL DEFAULT 0;
ALTER TABLE sessions ADD COLUMN quarantine TEXT;
)sql",
    // v2 → v3: jobs under leases on a shared queue (issue 18).
    R"sql(
ALTER TABLE jobs ADD COLUMN lease_owner TEXT;
ALTER TABLE jobs ADD COLUMN lease_expires_ms BIGINT NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN attempt INTEGER NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN cancel_requested BOOLEAN NOT NULL DEFAULT FALSE;
CREATE INDEX jobs_to_claim ON jobs (created_ms, id) WHERE state IN ('queued', 'running');
)sql",
    // v3 → v4: sessions held by one node under a lease (issue 18).
    R"sql(
ALTER TABLE sessions ADD COLUMN lease_owner TEXT;
ALTER TABLE sessions ADD COLUMN lease_expires_ms BIGINT NOT NULL DEFAULT 0;
ALTER TABLE sessions ADD COLUMN handover_to TEXT;
CREATE INDEX sessions_by_lease_owner ON sessions (lease_owner);
)sql",
};
static_assert(sizeof(kMigrations) / sizeof(kMigrations[0]) == Store::kSchemaVersion,
              "one migration per schema version");

/// Any 64-bit number, the same in every devsurf process: the advisory lock of migrations.
constexpr long long kMigrationLock = 0x64657673757266LL;  // "devsurf"

inline const char* const kSessionColumns =
    "id, edit_token_hash, view_token_hash, name, demo, initial_scene, created_ms, last_seq, "
    "quarantine";
inline const char* const kJobColumns =
    "id, state, scene, idempotency_key, idempotency_fingerprint, report, error, created_ms, "
    "updated_ms, progress_iteration, progress_of, lease_owner, lease_expires_ms, attempt, "
    "cancel_requested";

inline std::string sql(const char* a, const char* b = "", const char* c = "") {
  return std::string(a) + b + c;
}

/// A text parameter or SQL NULL.
using Param = std::optional<std::string>;

inline Param text(std::int64_t v) { return std::to_string(v); }
inline Param text(int v) { return std::to_string(v); }
inline Param text(bool v) { return std::string(v ? "true" : "false"); }

/// One result of PQexecParams; cleared on destruction.
class Result {
 public:
  explicit Result(PGresult* r) : r_(r) {}
  ~Result() { PQclear(r_); }
  Result(Result&& o) noexcept : r_(std::exchange(o.r_, nullptr)) {}
  Result(const Result&) = delete;
  Result& operator=(const Result&) = delete;

  int rows() const { return PQntuples(r_); }
  int affected() const {
    const char* n = PQcmdTuples(r_);
    return n && *n ? std::stoi(n) : 0;
  }
  bool isNull(int row, int col) const { return PQgetisnull(r_, row, col) != 0; }
  std::string str(int row, int col) const {
    return std::string(PQgetvalue(r_, row, col), static_cast<std::size_t>(PQgetlength(r_, row, col)));
  }
  std::optional<std::string> optStr(int row, int col) const {
    if (isNull(row, col)) return std::nullopt;
    return str(row, col);
  }
  std::int64_t int64(int row, int col) const { return std::stoll(str(row, col)); }
  bool boolean(int row, int col) const { return str(row, col) == "t"; }
  PGresult* handle() const { return r_; }

 private:
  PGresult* r_;
};

/// A SQL error with its SQLSTATE (e.g. 23505 unique_violation).
class SqlError : public StoreError {
 public:
  SqlError(const std::string& message, std::string sqlState)
      : StoreError(message), sqlState_(std::move(sqlState)) {}
  const std::string& sqlState() const { return sqlState_; }

 private:
  std::string sqlState_;
};

inline std::string trimmed(const char* message) {
  std::string m = message ? message : "";
  while (!m.empty() && (m.back() == '\n' || m.back() == ' ')) m.pop_back();
  return m;
}

/// One libpq connection. Not thread-safe by itself: the pool lends it to one caller at a time.
class Connection {
 public:
  Connection(const std::string& uri, std::string label) : uri_(uri), label_(std::move(label)) {
    connect();
  }
  ~Connection() {
    if (conn_) PQfinish(conn_);
  }
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  /// Reconnects when the connection broke. @throws StoreUnavailableError
  void ensureOpen() {
    if (conn_ && PQstatus(conn_) == CONNECTION_OK) return;
    if (conn_) {
      PQreset(conn_);
      if (PQstatus(conn_) == CONNECTION_OK) return;
      const std::string why = trimmed(PQerrorMessage(conn_));
      throw StoreUnavailableError("devsurf store " + label_ + ": PostgreSQL is unavailable: " + why);
    }
    connect();
  }

  /// Runs one statement with text parameters ($1, $2, …).
  /// @throws SqlError (a StoreError) with the server's message, StoreUnavailableError when the
  ///         connection is lost
  Result exec(const std::string& statement, const std::vector<Param>& params = {}) {
    std::vector<const char*> values(params.size());
    for (std::size_t i = 0; i < params.size(); ++i) values[i] = params[i] ? params[i]->c_str() : nullptr;
    Result r(PQexecParams(conn_, statement.c_str(), static_cast<int>(params.size()), nullptr,
                          values.data(), nullptr, nullptr, 0));
    const ExecStatusType status = PQresultStatus(r.handle());
    if (status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK) return r;
    if (PQstatus(conn_) != CONNECTION_OK) {
      throw StoreUnavailableError("devsurf store " + label_ + ": the connection to PostgreSQL broke: " +
                                  trimmed(PQerrorMessage(conn_)));
    }
    const char* state = PQresultErrorField(r.handle(), PG_DIAG_SQLSTATE);
    throw SqlError("devsurf store " + label_ + ": " + firstLine(statement) + ": " +
                       trimmed(PQresultErrorMessage(r.handle())),
                   state ? state : "");
  }

  /// Runs SQL text that may hold several statements (migrations).
  void execScript(const std::string& script) {
    Result r(PQexec(conn_, script.c_str()));
    const ExecStatusType status = PQresultStatus(r.handle());
    if (status != PGRES_COMMAND_OK && status != PGRES_TUPLES_OK) {
      throw StoreError("devsurf store " + label_ + ": " + firstLine(script) + ": " +
                       trimmed(PQresultErrorMessage(r.handle())));
    }
  }

  /// After an exception inside a transaction: roll back if the connection still has one open.
  void rollbackIfOpen() {
    if (conn_ && PQstatus(conn_) == CONNECTION_OK && PQtransactionStatus(conn_) != PQTRANS_IDLE) {
      PQclear(PQexec(conn_, "ROLLBACK"));
    }
  }

 private:
  static std::string firstLine(const std::string& text) {
    const auto begin = text.find_first_not_of(" \n");
    if (begin == std::string::npos) return text;
    std::string line = text.substr(begin, text.find('\n', begin) - begin);
    return line.size() > 120 ? line.substr(0, 117) + "…" : line;
  }

  void connect() {
    // A server that does not answer fails a connection within 5 s (libpq waits forever by
    // default); a URI's own connect_timeout comes later and wins.
    const char* keywords[] = {"connect_timeout", "dbname", nullptr};
    const char* values[] = {"5", uri_.c_str(), nullptr};
    conn_ = PQconnectdbParams(keywords, values, /*expand_dbname=*/1);
    if (!conn_) throw StoreUnavailableError("devsurf store " + label_ + ": out of memory connecting");
    if (PQstatus(conn_) != CONNECTION_OK) {
      const std::string why = trimmed(PQerrorMessage(conn_));
      PQfinish(conn_);
      conn_ = nullptr;
      throw StoreUnavailableError("devsurf store " + label_ + ": cannot connect to PostgreSQL: " + why);
    }
    // Quiet NOTICEs (e.g. "relation … already exists, skipping") instead of libpq's stderr.
    PQsetNoticeProcessor(conn_, [](void*, const char*) {}, nullptr);
    Result r(PQexec(conn_, "SET client_encoding = 'UTF8'; SET client_min_messages = WARNING"));
  }

  std::string uri_, label_;
  PGconn* conn_ = nullptr;
};

/// BEGIN … COMMIT on a lent connection; rolls back when left without commit() (an exception).
class Transaction {
 public:
  Transaction(Connection& c, const char* begin = "BEGIN") : c_(c) { c_.exec(begin); }
  ~Transaction() {
    if (!done_) c_.rollbackIfOpen();
  }
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit() {
    c_.exec("COMMIT");
    done_ = true;
  }

 private:
  Connection& c_;
  bool done_ = false;
};

inline nlohmann::json parseStoredJson(const std::string& text, const std::string& what) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw StoreError("devsurf store: corrupt JSON in " + what + ": " + e.what());
  }
}

inline JobRecord readJobRow(const Result& r, int row) {
  JobRecord j;
  j.id = r.str(row, 0);
  j.state = jobStateFromName(r.str(row, 1));
  j.scene = parseStoredJson(r.str(row, 2), "scene of job " + j.id);
  j.idempotencyKey = r.optStr(row, 3);
  j.idempotencyFingerprint = r.str(row, 4);
  if (!r.isNull(row, 5)) j.report = parseStoredJson(r.str(row, 5), "report of job " + j.id);
  j.error = r.optStr(row, 6);
  j.createdMs = r.int64(row, 7);
  j.updatedMs = r.int64(row, 8);
  j.progressIteration = static_cast<int>(r.int64(row, 9));
  j.progressOf = static_cast<int>(r.int64(row, 10));
  j.leaseOwner = r.optStr(row, 11);
  j.leaseExpiresMs = r.int64(row, 12);
  j.attempt = static_cast<int>(r.int64(row, 13));
  j.cancelRequested = r.boolean(row, 14);
  return j;
}

}  // namespace pg

// --- the pool -------------------------------------------------------------------------------------

struct PostgresStore::Impl {
  std::string uri, label;
  StoreOptions options;
  std::mutex mutex;
  std::condition_variable available;
  std::vector<std::unique_ptr<pg::Connection>> idle;

  /// A connection lent to one call; back to the pool on destruction.
  class Lease {
   public:
    Lease(Impl& pool, std::unique_ptr<pg::Connection> c) : pool_(&pool), c_(std::move(c)) {}
    ~Lease() {
      if (!c_) return;
      c_->rollbackIfOpen();
      std::lock_guard<std::mutex> lock(pool_->mutex);
      pool_->idle.push_back(std::move(c_));
      pool_->available.notify_one();
    }
    Lease(Lease&& other) noexcept = default;
    Lease(const Lease&) = delete;
    Lease& operator=(const Lease&) = delete;
    Lease& operator=(Lease&&) = delete;
    pg::Connection& operator*() { return *c_; }
    pg::Connection* operator->() { return c_.get(); }

   private:
    Impl* pool_;
    std::unique_ptr<pg::Connection> c_;
  };

  Lease lend() {
    std::unique_ptr<pg::Connection> c;
    {
      std::unique_lock<std::mutex> lock(mutex);
      available.wait(lock, [this]() { return !idle.empty(); });
      c = std::move(idle.back());
      idle.pop_back();
    }
    Lease lease(*this, std::move(c));
    lease->ensureOpen();  // throws StoreUnavailableError; the lease returns the connection
    return lease;
  }

  static std::optional<RestoredSession> readSession(pg::Connection& c, const std::string& id) {
    RestoredSession r;
    {
      pg::Result q = c.exec(pg::sql("SELECT ", pg::kSessionColumns, " FROM sessions WHERE id = $1"), {id});
      if (q.rows() == 0) return std::nullopt;
      SessionRecord& s = r.session;
      s.id = q.str(0, 0);
      s.editTokenHash = q.str(0, 1);
      s.viewTokenHash = q.str(0, 2);
      s.name = q.str(0, 3);
      s.demo = q.boolean(0, 4);
      s.createdMs = q.int64(0, 6);
      r.lastSeq = q.int64(0, 7);
      s.quarantine = q.optStr(0, 8);
      try {
        s.initialScene = pg::parseStoredJson(q.str(0, 5), "initial scene of session " + id);
      } catch (const StoreError& e) {
        r.loadError = e.what();
        return r;
      }
    }
    try {
      std::int64_t after = 0;
      pg::Result snap = c.exec(
          "SELECT seq, scene, session_state, revision FROM snapshots WHERE session_id = $1 "
          "ORDER BY seq DESC LIMIT 1",
          {id});
      if (snap.rows() > 0) {
        after = snap.int64(0, 0);
        Snapshot snapshot{after, pg::parseStoredJson(snap.str(0, 1), "snapshot of session " + id), nullptr, 0};
        if (!snap.isNull(0, 2))
          snapshot.sessionState = pg::parseStoredJson(snap.str(0, 2), "session state of session " + id);
        snapshot.revision = snap.int64(0, 3);
        r.snapshot = std::move(snapshot);
      }
      pg::Result edits = c.exec(
          "SELECT seq, edit, time_ms FROM edits WHERE session_id = $1 AND seq > $2 ORDER BY seq",
          {id, pg::text(after)});
      for (int i = 0; i < edits.rows(); ++i) {
        const std::int64_t seq = edits.int64(i, 0);
        r.editsAfterSnapshot.push_back(EditRecord{
            seq, pg::parseStoredJson(edits.str(i, 1), "edit " + std::to_string(seq) + " of session " + id),
            edits.int64(i, 2)});
      }
    } catch (const StoreUnavailableError&) {
      throw;
    } catch (const pg::SqlError&) {
      throw;
    } catch (const StoreError& e) {  // a row that does not parse: this session only
      r.loadError = e.what();
    }
    return r;
  }

  /// The time leases are measured in: the server's clock (StoreOptions::serverClock), else the
  /// caller's.
  std::int64_t leaseClock(pg::Connection& c, std::int64_t callerNowMs) const {
    if (!options.serverClock) return callerNowMs;
    return c.exec("SELECT (extract(epoch FROM clock_timestamp()) * 1000)::bigint").int64(0, 0);
  }

  /// last_seq of a session, its row locked until the caller's transaction ends.
  static std::int64_t lockedLastSeq(pg::Connection& c, const std::string& id,
                                    std::optional<std::string>* holder = nullptr) {
    pg::Result q = c.exec("SELECT last_seq, lease_owner FROM sessions WHERE id = $1 FOR UPDATE", {id});
    if (q.rows() == 0) throw NotFoundError("no session '" + id + "'");
    if (holder) *holder = q.optStr(0, 1);
    return q.int64(0, 0);
  }

  std::optional<JobRecord> jobWhere(const char* where, const std::string& value) {
    Lease c = lend();
    pg::Result q = c->exec(pg::sql("SELECT ", pg::kJobColumns, " FROM jobs WHERE ") + where, {value});
    if (q.rows() == 0) return std::nullopt;
    return pg::readJobRow(q, 0);
  }
};

}  // namespace devsurf::server::store
