#include "devsurf/server/store/PostgresStore.h"

#include <libpq-fe.h>

#include <condition_variable>
#include <mutex>
#include <regex>
#include <utility>

namespace devsurf::server::store {

// Helpers of this file only; named apart from SqliteStore.cpp's (one unity batch), and not in an
// anonymous namespace because PostgresStore::Impl holds them.
namespace pg {

// kMigrations[v] takes a database from version v to v + 1: the same steps as SqliteStore's, in
// PostgreSQL's types. Append, never edit.
const char* const kMigrations[] = {
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

const char* const kSessionColumns =
    "id, edit_token_hash, view_token_hash, name, demo, initial_scene, created_ms, last_seq, "
    "quarantine";
const char* const kJobColumns =
    "id, state, scene, idempotency_key, idempotency_fingerprint, report, error, created_ms, "
    "updated_ms, progress_iteration, progress_of, lease_owner, lease_expires_ms, attempt, "
    "cancel_requested";

std::string sql(const char* a, const char* b = "", const char* c = "") {
  return std::string(a) + b + c;
}

/// A text parameter or SQL NULL.
using Param = std::optional<std::string>;

Param text(std::int64_t v) { return std::to_string(v); }
Param text(int v) { return std::to_string(v); }
Param text(bool v) { return std::string(v ? "true" : "false"); }

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

std::string trimmed(const char* message) {
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

nlohmann::json parseStoredJson(const std::string& text, const std::string& what) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw StoreError("devsurf store: corrupt JSON in " + what + ": " + e.what());
  }
}

JobRecord readJobRow(const Result& r, int row) {
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

std::string redactedUri(const std::string& uri) {
  // postgresql://user:secret@host → postgresql://user:***@host; password=secret → password=***
  std::string out = std::regex_replace(uri, std::regex(R"(^(postgres(?:ql)?://[^:@/?]*:)[^@/?]*@)"), "$1***@");
  return std::regex_replace(out, std::regex(R"(([?&]password=)[^&]*)"), "$1***");
}

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

PostgresStore::PostgresStore(const std::string& uri, const StoreOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  d.uri = uri;
  d.label = redactedUri(uri);
  d.options = options;
  if (d.options.keepSnapshots < 1) d.options.keepSnapshots = 1;
  const int connections = std::max(1, d.options.connections);
  for (int i = 0; i < connections; ++i) d.idle.push_back(std::make_unique<pg::Connection>(uri, d.label));

  Impl::Lease c = d.lend();
  for (;;) {
    pg::Transaction t(*c);
    c->exec("SELECT pg_advisory_xact_lock($1)", {pg::text(static_cast<std::int64_t>(pg::kMigrationLock))});
    c->exec("CREATE TABLE IF NOT EXISTS devsurf_schema (version INTEGER NOT NULL)");
    pg::Result v = c->exec("SELECT version FROM devsurf_schema");
    int version = 0;
    if (v.rows() == 0) {
      c->exec("INSERT INTO devsurf_schema (version) VALUES (0)");
    } else {
      version = static_cast<int>(v.int64(0, 0));
    }
    if (version > kSchemaVersion) {
      throw StoreError("devsurf store " + d.label + ": schema version " + std::to_string(version) +
                       " is newer than this build supports (" + std::to_string(kSchemaVersion) + ")");
    }
    if (version == kSchemaVersion) {
      t.commit();
      return;
    }
    c->execScript(pg::kMigrations[version]);
    c->exec("UPDATE devsurf_schema SET version = $1", {pg::text(version + 1)});
    t.commit();
  }
}

PostgresStore::~PostgresStore() = default;

StoreInfo PostgresStore::info() const {
  Impl::Lease c = impl_->lend();
  StoreInfo i;
  i.backend = "postgresql";
  i.path = impl_->label;
  i.schemaVersion = static_cast<int>(c->exec("SELECT version FROM devsurf_schema").int64(0, 0));
  i.synchronous = c->exec("SHOW synchronous_commit").str(0, 0);
  return i;
}

// --- sessions -------------------------------------------------------------------------------------

void PostgresStore::createSession(const SessionRecord& s) {
  Impl::Lease c = impl_->lend();
  pg::Result r = c->exec(pg::sql("INSERT INTO sessions (", pg::kSessionColumns,
                                 ") VALUES ($1, $2, $3, $4, $5, $6, $7, 0, NULL) ON CONFLICT (id) DO NOTHING"),
                         {s.id, s.editTokenHash, s.viewTokenHash, s.name, pg::text(s.demo),
                          s.initialScene.dump(), pg::text(s.createdMs)});
  if (r.affected() == 0) throw AlreadyExistsError("session '" + s.id + "' already exists");
}

bool PostgresStore::deleteSession(const std::string& id) {
  Impl::Lease c = impl_->lend();
  return c->exec("DELETE FROM sessions WHERE id = $1", {id}).affected() > 0;
}

void PostgresStore::appendEdits(const std::string& sessionId, const std::vector<EditRecord>& edits) {
  if (edits.empty()) return;
  for (std::size_t i = 1; i < edits.size(); ++i) {
    if (edits[i].seq != edits[i - 1].seq + 1) throw SeqConflictError(sessionId, edits[i - 1].seq + 1, edits[i].seq);
  }
  std::vector<std::string> texts;
  texts.reserve(edits.size());
  for (const EditRecord& e : edits) texts.push_back(e.edit.dump());

  Impl::Lease c = impl_->lend();
  pg::Transaction t(*c);
  std::optional<std::string> holder;
  const std::int64_t last = Impl::lockedLastSeq(*c, sessionId, &holder);
  checkSessionOwner(sessionId, holder);
  if (edits.front().seq != last + 1) throw SeqConflictError(sessionId, last + 1, edits.front().seq);
  for (std::size_t i = 0; i < edits.size(); ++i) {
    c->exec("INSERT INTO edits (session_id, seq, edit, time_ms) VALUES ($1, $2, $3, $4)",
            {sessionId, pg::text(edits[i].seq), texts[i], pg::text(edits[i].timeMs)});
  }
  c->exec("UPDATE sessions SET last_seq = $1 WHERE id = $2", {pg::text(edits.back().seq), sessionId});
  t.commit();
}

std::int64_t PostgresStore::lastSeq(const std::string& sessionId) const {
  Impl::Lease c = impl_->lend();
  pg::Result q = c->exec("SELECT last_seq FROM sessions WHERE id = $1", {sessionId});
  if (q.rows() == 0) throw NotFoundError("no session '" + sessionId + "'");
  return q.int64(0, 0);
}

void PostgresStore::saveSnapshot(const std::string& sessionId, const Snapshot& snapshot) {
  const std::int64_t seq = snapshot.seq;
  const std::string scene = snapshot.scene.dump();
  pg::Param state;
  if (!snapshot.sessionState.is_null()) state = snapshot.sessionState.dump();
  const std::int64_t now = wallClockMs();

  Impl::Lease c = impl_->lend();
  pg::Transaction t(*c);
  std::optional<std::string> holder;
  const std::int64_t last = Impl::lockedLastSeq(*c, sessionId, &holder);
  checkSessionOwner(sessionId, holder);
  if (seq < 0 || seq > last) {
    throw StoreError("session '" + sessionId + "': snapshot seq " + std::to_string(seq) + " outside 0.." +
                     std::to_string(last));
  }
  {
    pg::Result q = c->exec("SELECT MAX(seq) FROM snapshots WHERE session_id = $1", {sessionId});
    if (!q.isNull(0, 0) && seq < q.int64(0, 0)) {
      throw StoreError("session '" + sessionId + "': snapshot seq " + std::to_string(seq) +
                       " is older than the stored snapshot at " + q.str(0, 0));
    }
  }
  c->exec(
      "INSERT INTO snapshots (session_id, seq, scene, created_ms, session_state, revision) "
      "VALUES ($1, $2, $3, $4, $5, $6) "
      "ON CONFLICT (session_id, seq) DO UPDATE SET scene = excluded.scene, "
      "created_ms = excluded.created_ms, session_state = excluded.session_state, "
      "revision = excluded.revision",
      {sessionId, pg::text(seq), scene, pg::text(now), state, pg::text(snapshot.revision)});
  pg::Result kept = c->exec(
      "SELECT seq FROM snapshots WHERE session_id = $1 ORDER BY seq DESC LIMIT 1 OFFSET $2",
      {sessionId, pg::text(impl_->options.keepSnapshots - 1)});
  if (kept.rows() > 0) {
    const std::string oldestKept = kept.str(0, 0);
    c->exec("DELETE FROM snapshots WHERE session_id = $1 AND seq < $2", {sessionId, oldestKept});
    c->exec("DELETE FROM edits WHERE session_id = $1 AND seq <= $2", {sessionId, oldestKept});
  }
  t.commit();
}

void PostgresStore::quarantineSession(const std::string& id, const std::string& reason) {
  Impl::Lease c = impl_->lend();
  if (c->exec("UPDATE sessions SET quarantine = $1 WHERE id = $2", {reason, id}).affected() == 0)
    throw NotFoundError("no session '" + id + "'");
}

void PostgresStore::liftQuarantine(const std::string& id) {
  Impl::Lease c = impl_->lend();
  if (c->exec("UPDATE sessions SET quarantine = NULL WHERE id = $1", {id}).affected() == 0)
    throw NotFoundError("no session '" + id + "'");
}

std::vector<RestoredSession> PostgresStore::loadSessions() const {
  Impl::Lease c = impl_->lend();
  pg::Transaction t(*c, "BEGIN ISOLATION LEVEL REPEATABLE READ READ ONLY");
  std::vector<std::string> ids;
  {
    pg::Result q = c->exec("SELECT id FROM sessions ORDER BY created_ms, id");
    for (int i = 0; i < q.rows(); ++i) ids.push_back(q.str(i, 0));
  }
  std::vector<RestoredSession> out;
  out.reserve(ids.size());
  for (const std::string& id : ids) {
    if (auto s = Impl::readSession(*c, id)) out.push_back(std::move(*s));
  }
  t.commit();
  return out;
}

std::optional<RestoredSession> PostgresStore::loadSession(const std::string& id) const {
  Impl::Lease c = impl_->lend();
  pg::Transaction t(*c, "BEGIN ISOLATION LEVEL REPEATABLE READ READ ONLY");
  auto s = Impl::readSession(*c, id);
  t.commit();
  return s;
}

// --- sessions under leases -------------------------------------------------------------------------

bool PostgresStore::acquireSessionLease(const std::string& id, const std::string& owner, std::int64_t nowMs,
                                        std::int64_t leaseMs) {
  Impl::Lease c = impl_->lend();
  nowMs = impl_->leaseClock(*c, nowMs);
  pg::Result q = c->exec(
      "UPDATE sessions SET lease_owner = $2, lease_expires_ms = $3 + $4, handover_to = NULL WHERE id = $1 AND "
      "(lease_owner IS NULL OR lease_owner = $2 OR lease_expires_ms < $3) RETURNING id",
      {id, owner, pg::text(nowMs), pg::text(leaseMs)});
  if (q.rows() > 0) return true;
  if (c->exec("SELECT 1 FROM sessions WHERE id = $1", {id}).rows() == 0) throw NotFoundError("no session '" + id + "'");
  return false;
}

std::vector<std::string> PostgresStore::renewSessionLeases(const std::string& owner, std::int64_t nowMs,
                                                           std::int64_t leaseMs) {
  Impl::Lease c = impl_->lend();
  nowMs = impl_->leaseClock(*c, nowMs);
  pg::Transaction t(*c);
  c->exec("UPDATE sessions SET lease_owner = NULL, lease_expires_ms = 0, handover_to = NULL "
          "WHERE lease_owner = $1 AND handover_to IS NOT NULL",
          {owner});
  pg::Result q = c->exec("UPDATE sessions SET lease_expires_ms = $2 WHERE lease_owner = $1 RETURNING id",
                         {owner, pg::text(nowMs + leaseMs)});
  std::vector<std::string> ids;
  for (int i = 0; i < q.rows(); ++i) ids.push_back(q.str(i, 0));
  t.commit();
  return ids;
}

void PostgresStore::requestSessionHandover(const std::string& id, const std::string& requester) {
  Impl::Lease c = impl_->lend();
  c->exec("UPDATE sessions SET handover_to = $2 WHERE id = $1 AND lease_owner IS NOT NULL AND lease_owner <> $2",
          {id, requester});
}

int PostgresStore::endSessionLeases(const std::string& owner) {
  Impl::Lease c = impl_->lend();
  return c
      ->exec("UPDATE sessions SET lease_expires_ms = 0, handover_to = NULL WHERE lease_owner = $1", {owner})
      .affected();
}

std::vector<std::string> PostgresStore::sessionsLeasedBy(const std::string& owner) const {
  Impl::Lease c = impl_->lend();
  pg::Result q = c->exec("SELECT id FROM sessions WHERE lease_owner = $1 ORDER BY created_ms, id", {owner});
  std::vector<std::string> ids;
  for (int i = 0; i < q.rows(); ++i) ids.push_back(q.str(i, 0));
  return ids;
}

std::optional<std::pair<std::string, std::int64_t>> PostgresStore::sessionLease(const std::string& id) const {
  Impl::Lease c = impl_->lend();
  pg::Result q = c->exec("SELECT lease_owner, lease_expires_ms FROM sessions WHERE id = $1", {id});
  if (q.rows() == 0) throw NotFoundError("no session '" + id + "'");
  if (q.isNull(0, 0)) return std::nullopt;
  return std::make_pair(q.str(0, 0), q.int64(0, 1));
}

// --- jobs -----------------------------------------------------------------------------------------

void PostgresStore::putJob(const JobRecord& j) {
  pg::Param report;
  if (j.report) report = j.report->dump();
  Impl::Lease c = impl_->lend();
  auto existingKey = [&c, &j]() {
    pg::Result q = c->exec("SELECT id, idempotency_fingerprint FROM jobs WHERE idempotency_key = $1",
                           {*j.idempotencyKey});
    if (q.rows() > 0) throw IdempotencyConflictError(*j.idempotencyKey, q.str(0, 0), q.str(0, 1));
  };
  if (j.idempotencyKey) existingKey();
  pg::Result r = c->exec(pg::sql("INSERT INTO jobs (", pg::kJobColumns,
                                 ") VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12, $13, $14, $15) "
                                 "ON CONFLICT DO NOTHING"),
                         {j.id, jobStateName(j.state), j.scene.dump(), j.idempotencyKey, j.idempotencyFingerprint,
                          report, j.error, pg::text(j.createdMs), pg::text(j.updatedMs),
                          pg::text(j.progressIteration), pg::text(j.progressOf), j.leaseOwner,
                          pg::text(j.leaseExpiresMs), pg::text(j.attempt), pg::text(j.cancelRequested)});
  if (r.affected() > 0) return;
  // Nothing inserted: the id exists, or a concurrent submission with the same key committed first.
  if (j.idempotencyKey) existingKey();
  throw AlreadyExistsError("job '" + j.id + "' already exists");
}

std::optional<JobRecord> PostgresStore::jobByIdempotencyKey(const std::string& key) const {
  return impl_->jobWhere("idempotency_key = $1", key);
}

void PostgresStore::updateJob(const JobRecord& j) {
  pg::Param report;
  if (j.report) report = j.report->dump();
  Impl::Lease c = impl_->lend();
  pg::Result r = c->exec(
      "UPDATE jobs SET state = $1, report = $2, error = $3, updated_ms = $4, progress_iteration = $5, "
      "progress_of = $6 WHERE id = $7",
      {jobStateName(j.state), report, j.error, pg::text(j.updatedMs), pg::text(j.progressIteration),
       pg::text(j.progressOf), j.id});
  if (r.affected() == 0) throw NotFoundError("no job '" + j.id + "'");
}

std::optional<JobRecord> PostgresStore::job(const std::string& id) const {
  return impl_->jobWhere("id = $1", id);
}

std::vector<JobRecord> PostgresStore::unfinishedJobs() const {
  Impl::Lease c = impl_->lend();
  pg::Result q = c->exec(pg::sql("SELECT ", pg::kJobColumns,
                                 " FROM jobs WHERE state IN ('queued', 'running') ORDER BY created_ms, id"));
  std::vector<JobRecord> out;
  for (int i = 0; i < q.rows(); ++i) out.push_back(pg::readJobRow(q, i));
  return out;
}

std::map<JobState, int> PostgresStore::jobCounts() const {
  std::map<JobState, int> counts{{JobState::Queued, 0},
                                 {JobState::Running, 0},
                                 {JobState::Succeeded, 0},
                                 {JobState::Failed, 0},
                                 {JobState::Cancelled, 0}};
  Impl::Lease c = impl_->lend();
  pg::Result q = c->exec("SELECT state, COUNT(*) FROM jobs GROUP BY state");
  for (int i = 0; i < q.rows(); ++i) counts[jobStateFromName(q.str(i, 0))] = static_cast<int>(q.int64(i, 1));
  return counts;
}

int PostgresStore::pruneFinishedJobs(std::int64_t olderThanMs) {
  Impl::Lease c = impl_->lend();
  return c
      ->exec("DELETE FROM jobs WHERE state IN ('succeeded', 'failed', 'cancelled') AND updated_ms < $1",
             {pg::text(olderThanMs)})
      .affected();
}

std::optional<JobRecord> PostgresStore::claimJob(const std::string& owner, std::int64_t nowMs,
                                                 std::int64_t leaseMs) {
  Impl::Lease c = impl_->lend();
  nowMs = impl_->leaseClock(*c, nowMs);
  // A job cancelled while its worker died is not run again.
  c->exec(
      "UPDATE jobs SET state = 'cancelled', lease_owner = NULL, lease_expires_ms = 0, updated_ms = $1 "
      "WHERE state = 'running' AND lease_expires_ms < $1 AND cancel_requested",
      {pg::text(nowMs)});
  // One statement: the candidate row is locked (others skip it) and claimed, or nothing is.
  pg::Result q = c->exec(
      pg::sql("WITH candidate AS ("
              "  SELECT id FROM jobs WHERE state = 'queued' OR (state = 'running' AND lease_expires_ms < $2)"
              "  ORDER BY state = 'running', created_ms, id LIMIT 1 FOR UPDATE SKIP LOCKED) "
              "UPDATE jobs SET state = 'running', lease_owner = $1, lease_expires_ms = $2 + $3, "
              "attempt = jobs.attempt + 1, progress_iteration = 0, updated_ms = $2 "
              "FROM candidate WHERE jobs.id = candidate.id RETURNING ",
              "jobs.id, jobs.state, jobs.scene, jobs.idempotency_key, jobs.idempotency_fingerprint, jobs.report, "
              "jobs.error, jobs.created_ms, jobs.updated_ms, jobs.progress_iteration, jobs.progress_of, "
              "jobs.lease_owner, jobs.lease_expires_ms, jobs.attempt, jobs.cancel_requested"),
      {owner, pg::text(nowMs), pg::text(leaseMs)});
  if (q.rows() == 0) return std::nullopt;
  return pg::readJobRow(q, 0);
}

JobLeaseRenewal PostgresStore::renewJobLease(const std::string& id, const std::string& owner, int attempt,
                                             std::int64_t nowMs, std::int64_t leaseMs, int progressIteration,
                                             int progressOf) {
  Impl::Lease c = impl_->lend();
  nowMs = impl_->leaseClock(*c, nowMs);
  pg::Result q = c->exec(
      "UPDATE jobs SET lease_expires_ms = $1, progress_iteration = $2, progress_of = $3 "
      "WHERE id = $4 AND state = 'running' AND lease_owner = $5 AND attempt = $6 RETURNING cancel_requested",
      {pg::text(nowMs + leaseMs), pg::text(progressIteration), pg::text(progressOf), id, owner, pg::text(attempt)});
  JobLeaseRenewal renewal;
  renewal.held = q.rows() > 0;
  renewal.cancelRequested = renewal.held && q.boolean(0, 0);
  return renewal;
}

bool PostgresStore::finishJob(const JobRecord& j, const std::string& owner, int attempt) {
  pg::Param report;
  if (j.report) report = j.report->dump();
  Impl::Lease c = impl_->lend();
  return c
             ->exec("UPDATE jobs SET state = $1, report = $2, error = $3, updated_ms = $4, progress_iteration = $5, "
                    "progress_of = $6, lease_owner = NULL, lease_expires_ms = 0 "
                    "WHERE id = $7 AND state = 'running' AND lease_owner = $8 AND attempt = $9",
                    {jobStateName(j.state), report, j.error, pg::text(j.updatedMs), pg::text(j.progressIteration),
                     pg::text(j.progressOf), j.id, owner, pg::text(attempt)})
             .affected() > 0;
}

JobState PostgresStore::requestJobCancel(const std::string& id, std::int64_t nowMs) {
  Impl::Lease c = impl_->lend();
  // SET reads the row as it was: a queued job ends cancelled, a running one is marked.
  pg::Result q = c->exec(
      "UPDATE jobs SET state = CASE WHEN state = 'queued' THEN 'cancelled' ELSE state END, "
      "cancel_requested = cancel_requested OR state = 'running', "
      "updated_ms = CASE WHEN state = 'queued' THEN $2 ELSE updated_ms END "
      "WHERE id = $1 RETURNING state",
      {id, pg::text(nowMs)});
  if (q.rows() == 0) throw NotFoundError("no job '" + id + "'");
  return jobStateFromName(q.str(0, 0));
}

int PostgresStore::releaseJobLeases(const std::string& owner, std::int64_t nowMs) {
  Impl::Lease c = impl_->lend();
  return c
      ->exec("UPDATE jobs SET state = 'queued', progress_iteration = 0, updated_ms = $1, lease_owner = NULL, "
             "lease_expires_ms = 0 WHERE state = 'running' AND lease_owner = $2",
             {pg::text(nowMs), owner})
      .affected();
}

int PostgresStore::requeueInterruptedJobs(std::int64_t nowMs) {
  Impl::Lease c = impl_->lend();
  return c
      ->exec("UPDATE jobs SET state = 'queued', progress_iteration = 0, updated_ms = $1, lease_owner = NULL, "
             "lease_expires_ms = 0, cancel_requested = FALSE WHERE state = 'running'",
             {pg::text(nowMs)})
      .affected();
}

}  // namespace devsurf::server::store
