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

// Helpers of this file only (not anonymous: SqliteStore::Impl holds them).
namespace sqlite {

// --- schema -------------------------------------------------------------------------------------

// kMigrations[v] takes a database from user_version v to v + 1. Append, never edit.
const char* const kMigrations[] = {
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

nlohmann::json parseJson(const std::string& text, const std::string& what) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw StoreError("devsurf store: corrupt JSON in " + what + ": " + e.what());
  }
}

std::string pragmaText(Connection& c, const char* sql) {
  Query q(c, sql);
  if (!q.step()) throw StoreError("devsurf store " + c.path() + ": " + sql + " returned no row");
  return q.text(0);
}

int userVersion(Connection& c) {
  Query q(c, "PRAGMA user_version");
  q.step();
  return static_cast<int>(q.int64(0));
}

void migrate(Connection& c) {
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

JobRecord readJob(const Query& q) {
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

using namespace sqlite;  // NOLINT: this file's own helpers

// --- Store --------------------------------------------------------------------------------------

struct SqliteStore::Impl {
  StoreOptions options;
  std::string path;
  std::mutex writeMutex;
  std::unique_ptr<Connection> writer;  // every mutating method
  std::mutex readMutex;
  std::unique_ptr<Connection> reader;  // every const method

  // Reads one session inside the caller's read transaction on `c`.
  static std::optional<RestoredSession> readSession(Connection& c, const std::string& id) {
    RestoredSession r;
    {
      Query q(c, "SELECT " DEVSURF_SESSION_COLUMNS " FROM sessions WHERE id = ?");
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
        s.initialScene = parseJson(q.text(5), "initial scene of session " + id);
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
        Query q(c,
                "SELECT seq, scene, session_state, revision FROM snapshots WHERE session_id = ? "
                "ORDER BY seq DESC LIMIT 1");
        q.bind(1, id);
        if (q.step()) {
          after = q.int64(0);
          Snapshot snapshot{after, parseJson(q.text(1), "snapshot of session " + id), nullptr, 0};
          if (!q.isNull(2)) snapshot.sessionState = parseJson(q.text(2), "session state of session " + id);
          snapshot.revision = q.int64(3);
          r.snapshot = std::move(snapshot);
        }
      }
      Query q(c,
              "SELECT seq, edit, time_ms FROM edits WHERE session_id = ? AND seq > ? ORDER BY seq");
      q.bind(1, id).bind(2, after);
      while (q.step()) {
        std::int64_t seq = q.int64(0);
        r.editsAfterSnapshot.push_back(
            EditRecord{seq,
                       parseJson(q.text(1), "edit " + std::to_string(seq) + " of session " + id),
                       q.int64(2)});
      }
    } catch (const StoreError& e) {
      r.loadError = e.what();
    }
    return r;
  }

  // Current last_seq of a session inside the caller's transaction. @throws NotFoundError
  static std::int64_t lastSeqOf(Connection& c, const std::string& id,
                                std::optional<std::string>* holder = nullptr) {
    Query q(c, "SELECT last_seq, lease_owner FROM sessions WHERE id = ?");
    q.bind(1, id);
    if (!q.step()) throw NotFoundError("no session '" + id + "'");
    if (holder) *holder = q.optText(1);
    return q.int64(0);
  }

  static std::optional<JobRecord> readJobWhere(Connection& c, const char* sql,
                                               const std::string& value) {
    Query q(c, sql);
    q.bind(1, value);
    if (!q.step()) return std::nullopt;
    return readJob(q);
  }
};

SqliteStore::SqliteStore(const std::string& directory, Durability durability)
    : SqliteStore(directory, StoreOptions{durability}) {}

SqliteStore::SqliteStore(const std::string& directory, const StoreOptions& options)
    : impl_(std::make_unique<Impl>()) {
  namespace fs = std::filesystem;
  Impl& d = *impl_;
  d.options = options;
  if (d.options.keepSnapshots < 1) d.options.keepSnapshots = 1;
  d.path = (fs::path(directory) / kFileName).string();

  std::error_code ec;
  const bool created = fs::create_directories(directory, ec);
  if (ec || !fs::is_directory(directory)) {
    throw StoreError("devsurf store: cannot create data directory " + directory + ": " +
                     (ec ? ec.message() : std::string("not a directory")));
  }
  // Private: the store holds token hashes and every user's designs. A directory the daemon creates
  // is 0700; the database file is created 0600 (SQLite gives its -wal and -shm files the same).
  if (created) fs::permissions(directory, fs::perms::owner_all, fs::perm_options::replace, ec);
  if (!fs::exists(d.path)) {
    const int fd = ::open(d.path.c_str(), O_CREAT | O_WRONLY | O_CLOEXEC, 0600);
    if (fd >= 0) ::close(fd);
  }

  d.writer = std::make_unique<Connection>(d.path, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE,
                                          d.options);
  Connection& w = *d.writer;
  // The first statement reads the file header: a non-SQLite file fails here with
  // "file is not a database".
  std::string mode = pragmaText(w, "PRAGMA journal_mode = WAL");
  if (mode != "wal") {
    throw StoreError("devsurf store " + d.path + ": cannot enable WAL (journal_mode is " + mode +
                     ")");
  }
  w.exec(d.options.durability == Durability::Power ? "PRAGMA synchronous = FULL"
                                                   : "PRAGMA synchronous = NORMAL");
  w.exec("PRAGMA foreign_keys = ON");
  w.exec("PRAGMA journal_size_limit = 67108864");  // truncate the WAL to 64 MiB after checkpoints
  migrate(w);

  d.reader = std::make_unique<Connection>(d.path, SQLITE_OPEN_READWRITE, d.options);
  d.reader->exec("PRAGMA foreign_keys = ON");
  d.reader->exec("PRAGMA query_only = ON");
}

SqliteStore::~SqliteStore() = default;

StoreInfo SqliteStore::info() const {
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  StoreInfo i;
  i.backend = "sqlite";
  i.path = impl_->path;
  i.schemaVersion = userVersion(w);
  i.journalMode = pragmaText(w, "PRAGMA journal_mode");
  std::string sync = pragmaText(w, "PRAGMA synchronous");
  static const char* const names[] = {"OFF", "NORMAL", "FULL", "EXTRA"};
  int s = std::stoi(sync);
  i.synchronous = s >= 0 && s < 4 ? names[s] : sync;
  return i;
}

// --- sessions -----------------------------------------------------------------------------------

void SqliteStore::createSession(const SessionRecord& s) {
  std::string scene = s.initialScene.dump();
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Query q(w,
          "INSERT INTO sessions (" DEVSURF_SESSION_COLUMNS
          ") VALUES (?, ?, ?, ?, ?, ?, ?, 0, NULL) ON CONFLICT (id) DO NOTHING");
  q.bind(1, s.id).bind(2, s.editTokenHash).bind(3, s.viewTokenHash).bind(4, s.name);
  q.bind(5, s.demo).bind(6, scene).bind(7, s.createdMs);
  q.run();
  if (w.changes() == 0) throw AlreadyExistsError("session '" + s.id + "' already exists");
}

bool SqliteStore::deleteSession(const std::string& id) {
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Query q(w, "DELETE FROM sessions WHERE id = ?");  // edits, snapshots: ON DELETE CASCADE
  q.bind(1, id).run();
  return w.changes() > 0;
}

void SqliteStore::appendEdits(const std::string& sessionId, const std::vector<EditRecord>& edits) {
  if (edits.empty()) return;
  for (std::size_t i = 1; i < edits.size(); ++i) {
    if (edits[i].seq != edits[i - 1].seq + 1) {
      throw SeqConflictError(sessionId, edits[i - 1].seq + 1, edits[i].seq);
    }
  }
  std::vector<std::string> texts;  // serialised before taking the write lock
  texts.reserve(edits.size());
  for (const EditRecord& e : edits) texts.push_back(e.edit.dump());

  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Transaction t(w, Transaction::Write);
  std::optional<std::string> holder;
  std::int64_t last = Impl::lastSeqOf(w, sessionId, &holder);
  checkSessionOwner(sessionId, holder);
  if (edits.front().seq != last + 1) throw SeqConflictError(sessionId, last + 1, edits.front().seq);
  for (std::size_t i = 0; i < edits.size(); ++i) {
    Query q(w, "INSERT INTO edits (session_id, seq, edit, time_ms) VALUES (?, ?, ?, ?)");
    q.bind(1, sessionId).bind(2, edits[i].seq).bind(3, texts[i]).bind(4, edits[i].timeMs).run();
  }
  Query q(w, "UPDATE sessions SET last_seq = ? WHERE id = ?");
  q.bind(1, edits.back().seq).bind(2, sessionId).run();
  t.commit();
}

std::int64_t SqliteStore::lastSeq(const std::string& sessionId) const {
  std::lock_guard<std::mutex> lock(impl_->readMutex);
  return Impl::lastSeqOf(*impl_->reader, sessionId);
}

void SqliteStore::saveSnapshot(const std::string& sessionId, const Snapshot& snapshot) {
  const std::int64_t seq = snapshot.seq;
  std::string text = snapshot.scene.dump();
  std::optional<std::string> state;
  if (!snapshot.sessionState.is_null()) state = snapshot.sessionState.dump();
  std::int64_t now = wallClockMs();
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Transaction t(w, Transaction::Write);
  std::optional<std::string> holder;
  std::int64_t last = Impl::lastSeqOf(w, sessionId, &holder);
  checkSessionOwner(sessionId, holder);
  if (seq < 0 || seq > last) {
    throw StoreError("session '" + sessionId + "': snapshot seq " + std::to_string(seq) +
                     " outside 0.." + std::to_string(last));
  }
  {
    Query q(w, "SELECT MAX(seq) FROM snapshots WHERE session_id = ?");
    q.bind(1, sessionId);
    if (q.step() && !q.isNull(0) && seq < q.int64(0)) {
      throw StoreError("session '" + sessionId + "': snapshot seq " + std::to_string(seq) +
                       " is older than the stored snapshot at " + std::to_string(q.int64(0)));
    }
  }
  {
    Query q(w,
            "INSERT INTO snapshots (session_id, seq, scene, created_ms, session_state, revision) "
            "VALUES (?, ?, ?, ?, ?, ?) "
            "ON CONFLICT (session_id, seq) DO UPDATE SET scene = excluded.scene, "
            "created_ms = excluded.created_ms, session_state = excluded.session_state, "
            "revision = excluded.revision");
    q.bind(1, sessionId).bind(2, seq).bind(3, text).bind(4, now).bind(5, state).bind(6, snapshot.revision).run();
  }
  std::optional<std::int64_t> oldestKept;
  {
    Query q(w,
            "SELECT seq FROM snapshots WHERE session_id = ? ORDER BY seq DESC LIMIT 1 OFFSET ?");
    q.bind(1, sessionId).bind(2, impl_->options.keepSnapshots - 1);
    if (q.step()) oldestKept = q.int64(0);
  }
  if (oldestKept) {
    Query(w, "DELETE FROM snapshots WHERE session_id = ? AND seq < ?")
        .bind(1, sessionId)
        .bind(2, *oldestKept)
        .run();
    Query(w, "DELETE FROM edits WHERE session_id = ? AND seq <= ?")
        .bind(1, sessionId)
        .bind(2, *oldestKept)
        .run();
  }
  t.commit();
}

void SqliteStore::liftQuarantine(const std::string& id) {
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Query q(w, "UPDATE sessions SET quarantine = NULL WHERE id = ?");
  q.bind(1, id).run();
  if (w.changes() == 0) throw NotFoundError("no session '" + id + "'");
}

void SqliteStore::quarantineSession(const std::string& id, const std::string& reason) {
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Query q(w, "UPDATE sessions SET quarantine = ? WHERE id = ?");
  q.bind(1, reason).bind(2, id).run();
  if (w.changes() == 0) throw NotFoundError("no session '" + id + "'");
}

std::vector<RestoredSession> SqliteStore::loadSessions() const {
  std::lock_guard<std::mutex> lock(impl_->readMutex);
  Connection& r = *impl_->reader;
  Transaction t(r, Transaction::Read);
  std::vector<std::string> ids;
  {
    Query q(r, "SELECT id FROM sessions ORDER BY created_ms, id");
    while (q.step()) ids.push_back(q.text(0));
  }
  std::vector<RestoredSession> out;
  out.reserve(ids.size());
  for (const std::string& id : ids) {
    if (auto s = Impl::readSession(r, id)) out.push_back(std::move(*s));
  }
  t.commit();
  return out;
}

std::optional<RestoredSession> SqliteStore::loadSession(const std::string& id) const {
  std::lock_guard<std::mutex> lock(impl_->readMutex);
  Connection& r = *impl_->reader;
  Transaction t(r, Transaction::Read);
  auto s = Impl::readSession(r, id);
  t.commit();
  return s;
}

// --- jobs ---------------------------------------------------------------------------------------

void SqliteStore::putJob(const JobRecord& j) {
  std::string scene = j.scene.dump();
  std::optional<std::string> report;
  if (j.report) report = j.report->dump();
  std::string state = jobStateName(j.state);

  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Transaction t(w, Transaction::Write);
  if (j.idempotencyKey) {
    Query q(w, "SELECT id, idempotency_fingerprint FROM jobs WHERE idempotency_key = ?");
    q.bind(1, *j.idempotencyKey);
    if (q.step()) throw IdempotencyConflictError(*j.idempotencyKey, q.text(0), q.text(1));
  }
  Query q(w,
          "INSERT INTO jobs (" DEVSURF_JOB_COLUMNS
          ") VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?) ON CONFLICT DO NOTHING");
  q.bind(1, j.id).bind(2, state).bind(3, scene).bind(4, j.idempotencyKey);
  q.bind(5, j.idempotencyFingerprint).bind(6, report).bind(7, j.error);
  q.bind(8, j.createdMs).bind(9, j.updatedMs).bind(10, j.progressIteration).bind(11, j.progressOf);
  q.bind(12, j.leaseOwner).bind(13, j.leaseExpiresMs).bind(14, j.attempt).bind(15, j.cancelRequested);
  q.run();
  if (w.changes() == 0) throw AlreadyExistsError("job '" + j.id + "' already exists");
  t.commit();
}

std::optional<JobRecord> SqliteStore::jobByIdempotencyKey(const std::string& key) const {
  std::lock_guard<std::mutex> lock(impl_->readMutex);
  return Impl::readJobWhere(*impl_->reader,
                            "SELECT " DEVSURF_JOB_COLUMNS " FROM jobs WHERE idempotency_key = ?",
                            key);
}

void SqliteStore::updateJob(const JobRecord& j) {
  std::optional<std::string> report;
  if (j.report) report = j.report->dump();
  std::string state = jobStateName(j.state);

  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Query q(w,
          "UPDATE jobs SET state = ?, report = ?, error = ?, updated_ms = ?, "
          "progress_iteration = ?, progress_of = ? WHERE id = ?");
  q.bind(1, state).bind(2, report).bind(3, j.error).bind(4, j.updatedMs);
  q.bind(5, j.progressIteration).bind(6, j.progressOf).bind(7, j.id);
  q.run();
  if (w.changes() == 0) throw NotFoundError("no job '" + j.id + "'");
}

std::optional<JobRecord> SqliteStore::job(const std::string& id) const {
  std::lock_guard<std::mutex> lock(impl_->readMutex);
  return Impl::readJobWhere(*impl_->reader,
                            "SELECT " DEVSURF_JOB_COLUMNS " FROM jobs WHERE id = ?", id);
}

std::vector<JobRecord> SqliteStore::unfinishedJobs() const {
  std::lock_guard<std::mutex> lock(impl_->readMutex);
  Query q(*impl_->reader, "SELECT " DEVSURF_JOB_COLUMNS
                          " FROM jobs WHERE state IN ('queued', 'running') "
                          "ORDER BY created_ms, id");
  std::vector<JobRecord> out;
  while (q.step()) out.push_back(readJob(q));
  return out;
}

int SqliteStore::requeueInterruptedJobs(std::int64_t nowMs) {
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Query(w,
        "UPDATE jobs SET state = 'queued', progress_iteration = 0, updated_ms = ?, "
        "lease_owner = NULL, lease_expires_ms = 0, cancel_requested = 0 WHERE state = 'running'")
      .bind(1, nowMs)
      .run();
  return w.changes();
}

std::map<JobState, int> SqliteStore::jobCounts() const {
  std::map<JobState, int> counts{{JobState::Queued, 0},
                                 {JobState::Running, 0},
                                 {JobState::Succeeded, 0},
                                 {JobState::Failed, 0},
                                 {JobState::Cancelled, 0}};
  std::lock_guard<std::mutex> lock(impl_->readMutex);
  Query q(*impl_->reader, "SELECT state, COUNT(*) FROM jobs GROUP BY state");
  while (q.step()) counts[jobStateFromName(q.text(0))] = static_cast<int>(q.int64(1));
  return counts;
}

int SqliteStore::pruneFinishedJobs(std::int64_t olderThanMs) {
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Query(w,
        "DELETE FROM jobs WHERE state IN ('succeeded', 'failed', 'cancelled') "
        "AND updated_ms < ?")
      .bind(1, olderThanMs)
      .run();
  return w.changes();
}

// --- sessions under leases -------------------------------------------------------------------------

bool SqliteStore::acquireSessionLease(const std::string& id, const std::string& owner, std::int64_t nowMs,
                                      std::int64_t leaseMs) {
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Transaction t(w, Transaction::Write);
  Impl::lastSeqOf(w, id);  // NotFoundError
  Query(w,
        "UPDATE sessions SET lease_owner = ?, lease_expires_ms = ?, handover_to = NULL WHERE id = ? AND "
        "(lease_owner IS NULL OR lease_owner = ? OR lease_expires_ms < ?)")
      .bind(1, owner)
      .bind(2, nowMs + leaseMs)
      .bind(3, id)
      .bind(4, owner)
      .bind(5, nowMs)
      .run();
  const bool held = w.changes() > 0;
  t.commit();
  return held;
}

std::vector<std::string> SqliteStore::renewSessionLeases(const std::string& owner, std::int64_t nowMs,
                                                         std::int64_t leaseMs) {
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Transaction t(w, Transaction::Write);
  Query(w,
        "UPDATE sessions SET lease_owner = NULL, lease_expires_ms = 0, handover_to = NULL "
        "WHERE lease_owner = ? AND handover_to IS NOT NULL")
      .bind(1, owner)
      .run();
  std::vector<std::string> ids;
  {
    Query q(w, "UPDATE sessions SET lease_expires_ms = ? WHERE lease_owner = ? RETURNING id");
    q.bind(1, nowMs + leaseMs).bind(2, owner);
    while (q.step()) ids.push_back(q.text(0));
  }
  t.commit();
  return ids;
}

void SqliteStore::requestSessionHandover(const std::string& id, const std::string& requester) {
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Query(w, "UPDATE sessions SET handover_to = ? WHERE id = ? AND lease_owner IS NOT NULL AND lease_owner <> ?")
      .bind(1, requester)
      .bind(2, id)
      .bind(3, requester)
      .run();
}

int SqliteStore::endSessionLeases(const std::string& owner) {
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Query(w, "UPDATE sessions SET lease_expires_ms = 0, handover_to = NULL WHERE lease_owner = ?").bind(1, owner).run();
  return w.changes();
}

std::vector<std::string> SqliteStore::sessionsLeasedBy(const std::string& owner) const {
  std::lock_guard<std::mutex> lock(impl_->readMutex);
  Query q(*impl_->reader, "SELECT id FROM sessions WHERE lease_owner = ? ORDER BY created_ms, id");
  q.bind(1, owner);
  std::vector<std::string> ids;
  while (q.step()) ids.push_back(q.text(0));
  return ids;
}

std::optional<std::pair<std::string, std::int64_t>> SqliteStore::sessionLease(const std::string& id) const {
  std::lock_guard<std::mutex> lock(impl_->readMutex);
  Query q(*impl_->reader, "SELECT lease_owner, lease_expires_ms FROM sessions WHERE id = ?");
  q.bind(1, id);
  if (!q.step()) throw NotFoundError("no session '" + id + "'");
  if (q.isNull(0)) return std::nullopt;
  return std::make_pair(q.text(0), q.int64(1));
}

// --- jobs under leases ------------------------------------------------------------------------------

std::optional<JobRecord> SqliteStore::claimJob(const std::string& owner, std::int64_t nowMs,
                                               std::int64_t leaseMs) {
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Transaction t(w, Transaction::Write);  // the write lock: no other claim runs meanwhile
  // A job cancelled while its worker died is not run again.
  Query(w,
        "UPDATE jobs SET state = 'cancelled', lease_owner = NULL, lease_expires_ms = 0, "
        "updated_ms = ? WHERE state = 'running' AND lease_expires_ms < ? AND cancel_requested = 1")
      .bind(1, nowMs)
      .bind(2, nowMs)
      .run();
  std::optional<std::string> id;
  {
    Query q(w,
            "SELECT id FROM jobs WHERE state = 'queued' OR (state = 'running' AND "
            "lease_expires_ms < ?) ORDER BY state = 'running', created_ms, id LIMIT 1");
    q.bind(1, nowMs);
    if (q.step()) id = q.text(0);
  }
  if (!id) {
    t.commit();  // the cancellations above
    return std::nullopt;
  }
  Query(w,
        "UPDATE jobs SET state = 'running', lease_owner = ?, lease_expires_ms = ?, "
        "attempt = attempt + 1, progress_iteration = 0, updated_ms = ? WHERE id = ?")
      .bind(1, owner)
      .bind(2, nowMs + leaseMs)
      .bind(3, nowMs)
      .bind(4, *id)
      .run();
  std::optional<JobRecord> claimed =
      Impl::readJobWhere(w, "SELECT " DEVSURF_JOB_COLUMNS " FROM jobs WHERE id = ?", *id);
  t.commit();
  return claimed;
}

JobLeaseRenewal SqliteStore::renewJobLease(const std::string& id, const std::string& owner,
                                           int attempt, std::int64_t nowMs, std::int64_t leaseMs,
                                           int progressIteration, int progressOf) {
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Transaction t(w, Transaction::Write);
  Query(w,
        "UPDATE jobs SET lease_expires_ms = ?, progress_iteration = ?, progress_of = ? "
        "WHERE id = ? AND state = 'running' AND lease_owner = ? AND attempt = ?")
      .bind(1, nowMs + leaseMs)
      .bind(2, progressIteration)
      .bind(3, progressOf)
      .bind(4, id)
      .bind(5, owner)
      .bind(6, attempt)
      .run();
  JobLeaseRenewal renewal;
  renewal.held = w.changes() > 0;
  if (renewal.held) {
    Query q(w, "SELECT cancel_requested FROM jobs WHERE id = ?");
    q.bind(1, id);
    renewal.cancelRequested = q.step() && q.int64(0) != 0;
  }
  t.commit();
  return renewal;
}

bool SqliteStore::finishJob(const JobRecord& j, const std::string& owner, int attempt) {
  std::optional<std::string> report;
  if (j.report) report = j.report->dump();
  std::string state = jobStateName(j.state);
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Query q(w,
          "UPDATE jobs SET state = ?, report = ?, error = ?, updated_ms = ?, "
          "progress_iteration = ?, progress_of = ?, lease_owner = NULL, lease_expires_ms = 0 "
          "WHERE id = ? AND state = 'running' AND lease_owner = ? AND attempt = ?");
  q.bind(1, state).bind(2, report).bind(3, j.error).bind(4, j.updatedMs);
  q.bind(5, j.progressIteration).bind(6, j.progressOf).bind(7, j.id).bind(8, owner).bind(9, attempt);
  q.run();
  return w.changes() > 0;
}

JobState SqliteStore::requestJobCancel(const std::string& id, std::int64_t nowMs) {
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Transaction t(w, Transaction::Write);
  std::string state;
  {
    Query q(w, "SELECT state FROM jobs WHERE id = ?");
    q.bind(1, id);
    if (!q.step()) throw NotFoundError("no job '" + id + "'");
    state = q.text(0);
  }
  JobState after = jobStateFromName(state);
  if (after == JobState::Queued) {
    Query(w, "UPDATE jobs SET state = 'cancelled', updated_ms = ? WHERE id = ?")
        .bind(1, nowMs)
        .bind(2, id)
        .run();
    after = JobState::Cancelled;
  } else if (after == JobState::Running) {
    Query(w, "UPDATE jobs SET cancel_requested = 1 WHERE id = ?").bind(1, id).run();
  }
  t.commit();
  return after;
}

int SqliteStore::releaseJobLeases(const std::string& owner, std::int64_t nowMs) {
  std::lock_guard<std::mutex> lock(impl_->writeMutex);
  Connection& w = *impl_->writer;
  Query(w,
        "UPDATE jobs SET state = 'queued', progress_iteration = 0, updated_ms = ?, "
        "lease_owner = NULL, lease_expires_ms = 0 WHERE state = 'running' AND lease_owner = ?")
      .bind(1, nowMs)
      .bind(2, owner)
      .run();
  return w.changes();
}

}  // namespace devsurf::server::store

#undef DEVSURF_SESSION_COLUMNS
#undef DEVSURF_JOB_COLUMNS
