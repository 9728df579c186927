// Leases on a shared store (issue 18): jobs (claims, renewals, fenced results, cancellation) and
// sessions held by one node,
// the same against both backends; several stores on one location stand for several nodes.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "devsurf/server/store/Store.h"
#include "support/StoreBackends.h"

using nlohmann::json;
using namespace devsurf::server::store;

namespace {

class StoreJobLeases : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override { DEVSURF_REQUIRE_STORE(where); }
  devsurf::testing::StoreLocation where{GetParam()};
};

std::string leaseBackendName(const ::testing::TestParamInfo<std::string>& info) { return info.param; }

JobRecord queuedJob(const std::string& id, std::int64_t createdMs) {
  JobRecord j;
  j.id = id;
  j.state = JobState::Queued;
  j.scene = json{{"job", id}};
  j.idempotencyFingerprint = "fp-" + id;
  j.createdMs = j.updatedMs = createdMs;
  return j;
}

}  // namespace

INSTANTIATE_TEST_SUITE_P(Backends, StoreJobLeases, ::testing::ValuesIn(devsurf::testing::storeBackends()),
                         leaseBackendName);

TEST_P(StoreJobLeases, AClaimTakesTheOldestQueuedJobOnceAndCountsTheAttempt) {
  auto store = where.open();
  store->putJob(queuedJob("young", 200));
  store->putJob(queuedJob("old", 100));
  const auto first = store->claimJob("node-a", 1000, 5000);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->id, "old");
  EXPECT_EQ(first->state, JobState::Running);
  EXPECT_EQ(first->leaseOwner, std::optional<std::string>("node-a"));
  EXPECT_EQ(first->leaseExpiresMs, 6000);
  EXPECT_EQ(first->attempt, 1);
  const auto second = store->claimJob("node-b", 1001, 5000);
  ASSERT_TRUE(second);
  EXPECT_EQ(second->id, "young");
  EXPECT_FALSE(store->claimJob("node-c", 1002, 5000)) << "both are leased";
  EXPECT_EQ(store->jobCounts()[JobState::Running], 2);
}

TEST_P(StoreJobLeases, AnExpiredLeaseIsClaimedAgainAndOnlyTheNewAttemptMayWriteTheResult) {
  auto store = where.open();
  store->putJob(queuedJob("j", 100));
  const auto dead = store->claimJob("dead-node", 1000, 5000);
  ASSERT_TRUE(dead);
  EXPECT_FALSE(store->claimJob("node-b", 5999, 5000)) << "the lease still runs";
  const auto again = store->claimJob("node-b", 6001, 5000);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->attempt, 2);
  EXPECT_EQ(again->leaseOwner, std::optional<std::string>("node-b"));
  EXPECT_EQ(again->progressIteration, 0);

  JobRecord late = *dead;  // the first worker comes back and finishes: too late
  late.state = JobState::Succeeded;
  late.report = json{{"by", "dead-node"}};
  EXPECT_FALSE(store->finishJob(late, "dead-node", 1));
  EXPECT_FALSE(store->renewJobLease("j", "dead-node", 1, 6002, 5000, 3, 10).held);

  JobRecord done = *again;
  done.state = JobState::Succeeded;
  done.report = json{{"by", "node-b"}};
  done.updatedMs = 7000;
  EXPECT_TRUE(store->finishJob(done, "node-b", 2));
  EXPECT_FALSE(store->finishJob(done, "node-b", 2)) << "a result is written once";
  const auto stored = store->job("j");
  EXPECT_EQ(stored->state, JobState::Succeeded);
  EXPECT_EQ(*stored->report, (json{{"by", "node-b"}}));
  EXPECT_FALSE(stored->leaseOwner);
  EXPECT_FALSE(store->claimJob("node-c", 99999, 5000)) << "finished jobs are never claimed";
}

TEST_P(StoreJobLeases, ARenewalStoresProgressAndReportsACancellationAskedForElsewhere) {
  auto nodeA = where.open();
  auto nodeB = where.open();  // another daemon on the same store
  nodeA->putJob(queuedJob("j", 100));
  const auto claimed = nodeA->claimJob("a", 1000, 5000);
  ASSERT_TRUE(claimed);
  const JobLeaseRenewal r1 = nodeA->renewJobLease("j", "a", claimed->attempt, 4000, 5000, 7, 40);
  EXPECT_TRUE(r1.held);
  EXPECT_FALSE(r1.cancelRequested);
  const auto seenByB = nodeB->job("j");
  EXPECT_EQ(seenByB->progressIteration, 7);
  EXPECT_EQ(seenByB->progressOf, 40);
  EXPECT_EQ(seenByB->leaseExpiresMs, 9000);
  EXPECT_FALSE(nodeB->claimJob("b", 8000, 5000)) << "renewed until 9000";

  EXPECT_EQ(nodeB->requestJobCancel("j", 8100), JobState::Running);
  const JobLeaseRenewal r2 = nodeA->renewJobLease("j", "a", claimed->attempt, 8200, 5000, 8, 40);
  EXPECT_TRUE(r2.held);
  EXPECT_TRUE(r2.cancelRequested);
  JobRecord cancelled = *claimed;
  cancelled.state = JobState::Cancelled;
  EXPECT_TRUE(nodeA->finishJob(cancelled, "a", claimed->attempt));
  EXPECT_EQ(nodeB->job("j")->state, JobState::Cancelled);
  EXPECT_EQ(nodeB->requestJobCancel("j", 9000), JobState::Cancelled) << "finished: unchanged";
  EXPECT_THROW(nodeB->requestJobCancel("nope", 9000), NotFoundError);
}

TEST_P(StoreJobLeases, AQueuedJobIsCancelledAtOnceAndACancelledJobWhoseNodeDiedIsNotRunAgain) {
  auto store = where.open();
  store->putJob(queuedJob("queued", 100));
  store->putJob(queuedJob("orphan", 50));
  EXPECT_EQ(store->requestJobCancel("queued", 500), JobState::Cancelled);
  EXPECT_EQ(store->job("queued")->updatedMs, 500);
  ASSERT_TRUE(store->claimJob("dies", 1000, 1000));  // takes "orphan", then its node dies
  EXPECT_EQ(store->requestJobCancel("orphan", 1500), JobState::Running);
  EXPECT_FALSE(store->claimJob("b", 5000, 1000)) << "nothing left to run";
  EXPECT_EQ(store->job("orphan")->state, JobState::Cancelled);
}

TEST_P(StoreJobLeases, ANodeReleasesOnlyItsOwnRunningJobs) {
  auto store = where.open();
  for (int i = 0; i < 4; ++i) store->putJob(queuedJob("j" + std::to_string(i), 100 + i));
  ASSERT_TRUE(store->claimJob("a", 1000, 5000));
  ASSERT_TRUE(store->claimJob("b", 1000, 5000));
  ASSERT_TRUE(store->claimJob("a", 1000, 5000));
  EXPECT_EQ(store->releaseJobLeases("a", 1100), 2);
  const auto counts = store->jobCounts();
  EXPECT_EQ(counts.at(JobState::Queued), 3);
  EXPECT_EQ(counts.at(JobState::Running), 1);
  const auto next = store->claimJob("c", 1200, 5000);
  ASSERT_TRUE(next);
  EXPECT_EQ(next->id, "j0");
  EXPECT_EQ(next->attempt, 2);
}

/// Four "nodes" (stores of their own on one location), two workers each, claim 120 jobs while
/// leases of a "dead" node end: every job is claimed and finished exactly once per attempt that
/// finishes, and every job ends with exactly one result.
TEST_P(StoreJobLeases, ConcurrentClaimsFromSeveralNodesRunEveryJobToOneResult) {
  constexpr int kJobs = 120;
  {
    auto setup = where.open();
    for (int i = 0; i < kJobs; ++i) setup->putJob(queuedJob("job" + std::to_string(1000 + i), i));
    // A node that claimed five jobs and died: their leases ended long ago.
    for (int i = 0; i < 5; ++i) ASSERT_TRUE(setup->claimJob("dead", 0, 1));
  }
  std::vector<std::unique_ptr<Store>> nodes;
  for (int n = 0; n < 4; ++n) nodes.push_back(where.open());
  std::mutex mutex;
  std::map<std::string, int> finishedBy;  // job → how many finishJob calls succeeded
  std::vector<std::thread> workers;
  for (int n = 0; n < 4; ++n) {
    for (int w = 0; w < 2; ++w) {
      workers.emplace_back([&nodes, &mutex, &finishedBy, n]() {
        Store& store = *nodes[static_cast<std::size_t>(n)];
        const std::string owner = "node" + std::to_string(n);
        for (;;) {
          const auto job = store.claimJob(owner, wallClockMs(), 60000);
          if (!job) return;
          JobRecord done = *job;
          done.state = JobState::Succeeded;
          done.report = json{{"by", owner}, {"attempt", job->attempt}};
          done.updatedMs = wallClockMs();
          if (store.finishJob(done, owner, job->attempt)) {
            std::lock_guard<std::mutex> lock(mutex);
            ++finishedBy[job->id];
          }
        }
      });
    }
  }
  for (std::thread& t : workers) t.join();
  ASSERT_EQ(finishedBy.size(), static_cast<std::size_t>(kJobs));
  for (const auto& [id, n] : finishedBy) EXPECT_EQ(n, 1) << id;
  const auto counts = nodes[0]->jobCounts();
  EXPECT_EQ(counts.at(JobState::Succeeded), kJobs);
  EXPECT_EQ(counts.at(JobState::Running), 0);
  EXPECT_EQ(counts.at(JobState::Queued), 0);
  int reclaimed = 0;
  for (int i = 0; i < kJobs; ++i) reclaimed += nodes[0]->job("job" + std::to_string(1000 + i))->attempt == 2;
  EXPECT_EQ(reclaimed, 5) << "the dead node's jobs ran a second time, the others once";
}

/// Sessions held by one node: a second node cannot take a live lease, takes it when it ends, and
/// from then on the first node's writes are refused with nothing stored.
TEST_P(StoreJobLeases, ASessionIsHeldByOneNodeUntilItsLeaseEndsAndTheLoserCannotWrite) {
  auto nodeA = where.open();
  auto nodeB = where.open();
  nodeA->setSessionOwner("a");
  nodeB->setSessionOwner("b");
  SessionRecord s;
  s.id = "shared";
  s.editTokenHash = "e";
  s.viewTokenHash = "v";
  s.name = "shared";
  s.initialScene = json{{"at", 0}};
  s.createdMs = 1;
  nodeA->createSession(s);
  EXPECT_FALSE(nodeA->sessionLease("shared"));
  EXPECT_THROW(nodeA->acquireSessionLease("nope", "a", 1000, 5000), NotFoundError);
  ASSERT_TRUE(nodeA->acquireSessionLease("shared", "a", 1000, 5000));
  EXPECT_TRUE(nodeA->acquireSessionLease("shared", "a", 1500, 5000)) << "the holder extends it";
  EXPECT_FALSE(nodeB->acquireSessionLease("shared", "b", 6000, 5000)) << "held until 6500";
  nodeA->appendEdit("shared", 1, json{{"by", "a"}});
  EXPECT_EQ(nodeA->renewSessionLeases("a", 6400, 5000), std::vector<std::string>{"shared"});
  EXPECT_FALSE(nodeB->acquireSessionLease("shared", "b", 11000, 5000)) << "renewed until 11400";

  ASSERT_TRUE(nodeB->acquireSessionLease("shared", "b", 11500, 5000));  // a died: b takes over
  EXPECT_EQ(nodeB->sessionLease("shared")->first, "b");
  EXPECT_THROW(nodeA->appendEdit("shared", 2, json{{"by", "a"}}), LeaseLostError);
  EXPECT_THROW(nodeA->saveSnapshot("shared", 1, json{{"by", "a"}}), LeaseLostError);
  EXPECT_TRUE(nodeA->renewSessionLeases("a", 11600, 5000).empty()) << "a learns it lost the session";
  nodeB->appendEdit("shared", 2, json{{"by", "b"}});
  const auto r = nodeB->loadSession("shared");
  ASSERT_EQ(r->editsAfterSnapshot.size(), 2u);
  EXPECT_EQ(r->editsAfterSnapshot[1].edit, (json{{"by", "b"}}));
  EXPECT_FALSE(r->snapshot);
  EXPECT_EQ(nodeB->endSessionLeases("b"), 1);
  EXPECT_EQ(nodeB->sessionLease("shared"), std::make_pair(std::string("b"), std::int64_t{0})) << "ended, b's name kept";
  EXPECT_EQ(nodeB->sessionsLeasedBy("b"), std::vector<std::string>{"shared"}) << "b restarting takes it back";
  EXPECT_TRUE(nodeA->acquireSessionLease("shared", "a", 11700, 5000)) << "ended: free for others at once";
  EXPECT_TRUE(nodeB->sessionsLeasedBy("b").empty());
}

/// A node the proxy now routes a session to asks its holder for it: the holder's next renewal
/// releases it (and no longer lists it), and the asker takes it at once.
TEST_P(StoreJobLeases, AHandoverRequestReleasesTheSessionAtTheHoldersNextRenewal) {
  auto store = where.open();
  SessionRecord s;
  s.id = "moving";
  s.editTokenHash = "e";
  s.viewTokenHash = "v";
  s.name = "moving";
  s.initialScene = json::object();
  s.createdMs = 1;
  store->createSession(s);
  ASSERT_TRUE(store->acquireSessionLease("moving", "x", 1000, 60000));
  store->requestSessionHandover("moving", "x");  // its own holder: no effect
  EXPECT_EQ(store->renewSessionLeases("x", 2000, 60000), std::vector<std::string>{"moving"});
  EXPECT_FALSE(store->acquireSessionLease("moving", "y", 3000, 60000));
  store->requestSessionHandover("moving", "y");
  EXPECT_FALSE(store->acquireSessionLease("moving", "y", 3100, 60000)) << "not before the holder renews";
  EXPECT_TRUE(store->renewSessionLeases("x", 3200, 60000).empty()) << "x gives it up";
  EXPECT_FALSE(store->sessionLease("moving"));
  ASSERT_TRUE(store->acquireSessionLease("moving", "y", 3300, 60000));
  EXPECT_EQ(store->renewSessionLeases("y", 3400, 60000), std::vector<std::string>{"moving"})
      << "the request was cleared when y took it";
}

/// Nodes whose clocks disagree still agree on leases: PostgreSQL measures them on the server's
/// clock. A node that believes it is year 2100 cannot take a lease another node took a moment
/// ago, and one that believes it is 1970 cannot make a lease end at once.
TEST_P(StoreJobLeases, OnPostgresqlLeasesRunOnTheServersClockNotTheNodes) {
  if (GetParam() != "postgresql") GTEST_SKIP() << "SQLite is one process on one machine: one clock";
  auto fast = where.open({}, /*serverClock=*/true);
  auto slow = where.open({}, /*serverClock=*/true);
  SessionRecord s;
  s.id = "clocks";
  s.editTokenHash = s.viewTokenHash = "h";
  s.name = "clocks";
  s.initialScene = json::object();
  s.createdMs = 1;
  fast->createSession(s);
  const std::int64_t year2100 = 4102444800000;
  ASSERT_TRUE(slow->acquireSessionLease("clocks", "slow", /*nowMs=*/0, 60000));
  EXPECT_FALSE(fast->acquireSessionLease("clocks", "fast", year2100, 60000));
  const auto lease = fast->sessionLease("clocks");
  EXPECT_NEAR(static_cast<double>(lease->second), static_cast<double>(wallClockMs() + 60000), 10000.0)
      << "the expiry is the server's now + the lease";
  fast->putJob(queuedJob("job", 1));
  ASSERT_TRUE(slow->claimJob("slow", 0, 60000));
  EXPECT_FALSE(fast->claimJob("fast", year2100, 60000)) << "the job's lease has not ended on the server";
}
