#include "devsurf/server/store/PostgresStore.h"

#include "PostgresDetail.h"

#include <regex>

namespace devsurf::server::store {

std::string redactedUri(const std::string& uri) {
  // postgresql://user:secret@host → postgresql://user:***@host; password=secret → password=***
  std::string out = std::regex_replace(uri, std::regex(R"(^(postgres(?:ql)?://[^:@/?]*:)[^@/?]*@)"), "$1***@");
  return std::regex_replace(out, std::regex(R"(([?&]password=)[^&]*)"), "$1***");
}


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

int PostgresStore::requeueInterruptedJobs(std::int64_t nowMs) {
  Impl::Lease c = impl_->lend();
  return c
      ->exec("UPDATE jobs SET state = 'queued', progress_iteration = 0, updated_ms = $1, lease_owner = NULL, "
             "lease_expires_ms = 0, cancel_requested = FALSE WHERE state = 'running'",
             {pg::text(nowMs)})
      .affected();
}

}  // namespace devsurf::server::store
