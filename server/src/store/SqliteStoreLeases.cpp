// SqliteStore: leases of sessions and jobs (issue 18; store/Store.h).

#include "devsurf/server/store/SqliteStore.h"

#include "SqliteDetail.h"

namespace devsurf::server::store {

using namespace sqlite;  // NOLINT: the backend's own helpers (SqliteDetail.h)

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
