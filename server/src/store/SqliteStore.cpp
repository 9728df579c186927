#include "devsurf/server/store/SqliteStore.h"

#include "SqliteDetail.h"

#include <filesystem>
#include <system_error>

namespace devsurf::server::store {

using namespace sqlite;  // NOLINT: the backend's own helpers (SqliteDetail.h)


// --- Store --------------------------------------------------------------------------------------


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

}  // namespace devsurf::server::store
