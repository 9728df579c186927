// PostgresStore: leases of sessions and jobs (issue 18; store/Store.h).

#include "devsurf/server/store/PostgresStore.h"

#include "PostgresDetail.h"

namespace devsurf::server::store {

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

// --- jobs under leases ----------------------------------------------------------------------------

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

}  // namespace devsurf::server::store
