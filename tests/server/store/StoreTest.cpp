#include "devsurf/server/store/Store.h"
#include "devsurf/server/store/SqliteStore.h"

#include <gtest/gtest.h>

#include "support/StoreBackends.h"
#include "support/TempDir.h"
#include <sqlite3.h>
#include <stdlib.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

namespace fs = std::filesystem;
using nlohmann::json;
using namespace devsurf::server::store;

namespace {

/// A fresh directory under the system temp dir, removed afterwards.
/// A fresh directory per test.
class TempDir : public devsurf::testing::TempDir {
 public:
  TempDir() : devsurf::testing::TempDir("devsurf-store") {}
};

/// Runs a single-value query directly on DIR/devsurf.db (bypassing the Store).
std::int64_t rawInt(const fs::path& dir, const std::string& sql) {
  sqlite3* db = nullptr;
  std::string file = (dir / SqliteStore::kFileName).string();
  if (sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr) != SQLITE_OK) {
    sqlite3_close(db);
    throw std::runtime_error("open " + file);
  }
  sqlite3_stmt* s = nullptr;
  std::int64_t v = -1;
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr) == SQLITE_OK &&
      sqlite3_step(s) == SQLITE_ROW) {
    v = sqlite3_column_int64(s, 0);
  }
  sqlite3_finalize(s);
  sqlite3_close(db);
  return v;
}

SessionRecord makeSession(const std::string& id, std::int64_t createdMs = 1000) {
  SessionRecord s;
  s.id = id;
  s.editTokenHash = "edit-hash-" + id;
  s.viewTokenHash = "view-hash-" + id;
  s.name = "Fläche ✓ " + id;
  s.demo = id.size() % 2 == 0;
  s.initialScene = json{{"id", id},
                        {"points", {0.1 + 0.2, M_PI, 1e-300, -2.5}},
                        {"nested", {{"a", nullptr}, {"b", true}}}};
  s.createdMs = createdMs;
  return s;
}

JobRecord makeJob(const std::string& id, std::optional<std::string> key = std::nullopt,
                  std::int64_t createdMs = 5000) {
  JobRecord j;
  j.id = id;
  j.state = JobState::Queued;
  j.scene = json{{"job", id}, {"iterations", 40}};
  j.idempotencyKey = std::move(key);
  j.idempotencyFingerprint = "fp-" + id;
  j.createdMs = createdMs;
  j.updatedMs = createdMs;
  return j;
}

json editFor(std::int64_t seq) { return json{{"op", "move"}, {"seq", seq}, {"dx", seq * 0.5}}; }

/// Asserts RestoredSession's invariant: edits are exactly snapshotSeq+1 .. lastSeq.
void expectContiguous(const RestoredSession& r) {
  std::int64_t expected = r.snapshot ? r.snapshot->seq + 1 : 1;
  for (const EditRecord& e : r.editsAfterSnapshot) {
    ASSERT_EQ(e.seq, expected) << "session " << r.session.id;
    ++expected;
  }
  EXPECT_EQ(expected - 1, r.lastSeq) << "session " << r.session.id;
}

/// The suites below run once per backend (StoreBackends.h): a fresh store location per test.
class BackendTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override { DEVSURF_REQUIRE_STORE(where); }
  devsurf::testing::StoreLocation where{GetParam()};
};
class StoreSessions : public BackendTest {};
class StoreJobs : public BackendTest {};
class StoreConcurrency : public BackendTest {};

std::string backendName(const ::testing::TestParamInfo<std::string>& info) { return info.param; }

}  // namespace

INSTANTIATE_TEST_SUITE_P(Backends, StoreSessions, ::testing::ValuesIn(devsurf::testing::storeBackends()), backendName);
INSTANTIATE_TEST_SUITE_P(Backends, StoreJobs, ::testing::ValuesIn(devsurf::testing::storeBackends()), backendName);
INSTANTIATE_TEST_SUITE_P(Backends, StoreConcurrency, ::testing::ValuesIn(devsurf::testing::storeBackends()), backendName);

// --- opening ------------------------------------------------------------------------------------

TEST(StoreOpen, CreatesDirectoryWalDatabaseAndSchema) {
  TempDir tmp;
  fs::path dir = tmp.path() / "nested" / "data";
  {
    SqliteStore store(dir.string());
    StoreInfo info = store.info();
    EXPECT_EQ(info.path, (dir / "devsurf.db").string());
    EXPECT_EQ(info.journalMode, "wal");
    EXPECT_EQ(info.synchronous, "NORMAL");
    EXPECT_EQ(info.schemaVersion, Store::kSchemaVersion);
  }
  EXPECT_TRUE(fs::is_regular_file(dir / "devsurf.db"));
  EXPECT_EQ(rawInt(dir, "PRAGMA user_version"), Store::kSchemaVersion);
  EXPECT_EQ(rawInt(dir, "SELECT count(*) FROM sqlite_schema WHERE type = 'table'"), 4);
}

TEST(StoreOpen, ADirectoryItCreatesIsPrivateAndSoIsTheDatabase) {
  TempDir tmp;
  const fs::path dir = tmp.path() / "private";
  { SqliteStore store(dir.string()); }
  EXPECT_EQ(fs::status(dir).permissions() & fs::perms::all, fs::perms::owner_all);
  for (const char* file : {"devsurf.db", "devsurf.db-wal", "devsurf.db-shm"}) {
    if (!fs::exists(dir / file)) continue;
    EXPECT_EQ(fs::status(dir / file).permissions() & (fs::perms::group_all | fs::perms::others_all), fs::perms::none)
        << file << " is readable by others";
  }
}

TEST(StoreOpen, PowerDurabilityUsesSynchronousFull) {
  TempDir tmp;
  SqliteStore store(tmp.str(), Durability::Power);
  EXPECT_EQ(store.info().synchronous, "FULL");
  EXPECT_EQ(store.info().journalMode, "wal");
}

TEST(StoreOpen, NonSqliteFileGivesClearError) {
  for (std::string garbage : {std::string(8192, 'x'), std::string("hello, not a database\n")}) {
    TempDir tmp;
    { std::ofstream(tmp.path() / "devsurf.db", std::ios::binary) << garbage; }
    try {
      SqliteStore store(tmp.str());
      FAIL() << "opening a non-SQLite file must throw";
    } catch (const std::runtime_error& e) {
      std::string what = e.what();
      EXPECT_NE(what.find((tmp.path() / "devsurf.db").string()), std::string::npos) << what;
      EXPECT_NE(what.find("not a database"), std::string::npos) << what;
    }
  }
}

TEST(StoreOpen, DirectoryThatIsAFileGivesClearError) {
  TempDir tmp;
  fs::path file = tmp.path() / "plainfile";
  { std::ofstream(file) << "x"; }
  try {
    SqliteStore store(file.string());
    FAIL() << "must throw";
  } catch (const StoreError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  }
}

TEST(StoreOpen, NewerSchemaIsRefused) {
  TempDir tmp;
  { SqliteStore store(tmp.str()); }
  rawInt(tmp.path(), "PRAGMA user_version = 99");
  try {
    SqliteStore store(tmp.str());
    FAIL() << "must throw";
  } catch (const StoreError& e) {
    EXPECT_NE(std::string(e.what()).find("newer"), std::string::npos) << e.what();
  }
}

// --- sessions -----------------------------------------------------------------------------------

TEST_P(StoreSessions, RoundTripAndDuplicateId) {
  auto storeOwner = where.open();
  Store& store = *storeOwner;
  SessionRecord s = makeSession("alpha");
  store.createSession(s);
  EXPECT_THROW(store.createSession(s), AlreadyExistsError);

  auto r = store.loadSession("alpha");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->session.id, s.id);
  EXPECT_EQ(r->session.editTokenHash, s.editTokenHash);
  EXPECT_EQ(r->session.viewTokenHash, s.viewTokenHash);
  EXPECT_EQ(r->session.name, s.name);
  EXPECT_EQ(r->session.demo, s.demo);
  EXPECT_EQ(r->session.initialScene, s.initialScene);  // doubles round-trip exactly
  EXPECT_EQ(r->session.createdMs, s.createdMs);
  EXPECT_FALSE(r->snapshot);
  EXPECT_TRUE(r->editsAfterSnapshot.empty());
  EXPECT_EQ(r->lastSeq, 0);
  EXPECT_EQ(store.lastSeq("alpha"), 0);

  EXPECT_FALSE(store.loadSession("missing"));
  EXPECT_THROW(store.lastSeq("missing"), NotFoundError);
}

TEST_P(StoreSessions, EditsRestoreAfterReopen) {
  {
    auto storeOwner = where.open();
    Store& store = *storeOwner;
    store.createSession(makeSession("b", 2000));
    store.createSession(makeSession("a", 1000));
    for (std::int64_t seq = 1; seq <= 5; ++seq) store.appendEdit("a", seq, editFor(seq), 100 + seq);
    store.appendEdits("a", {{6, editFor(6), 106}, {7, editFor(7), 107}, {8, editFor(8), 108}});
    store.appendEdit("b", 1, editFor(1));
    store.appendEdits("b", {});  // no-op
  }
  auto storeOwner = where.open();
  Store& store = *storeOwner;
  auto all = store.loadSessions();
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].session.id, "a");  // oldest first
  EXPECT_EQ(all[1].session.id, "b");
  const RestoredSession& a = all[0];
  EXPECT_EQ(a.lastSeq, 8);
  ASSERT_EQ(a.editsAfterSnapshot.size(), 8u);
  for (std::int64_t seq = 1; seq <= 8; ++seq) {
    const EditRecord& e = a.editsAfterSnapshot[static_cast<std::size_t>(seq - 1)];
    EXPECT_EQ(e.seq, seq);
    EXPECT_EQ(e.edit, editFor(seq));
    EXPECT_EQ(e.timeMs, 100 + seq);
  }
  EXPECT_EQ(all[1].lastSeq, 1);
  EXPECT_GT(all[1].editsAfterSnapshot.at(0).timeMs, 1600000000000);  // defaulted to wall clock
  expectContiguous(all[0]);
  expectContiguous(all[1]);
}

TEST_P(StoreSessions, SeqGapsAndRepeatsAreRejected) {
  auto storeOwner = where.open();
  Store& store = *storeOwner;
  store.createSession(makeSession("s"));
  EXPECT_THROW(store.appendEdit("s", 2, editFor(2)), SeqConflictError);  // first must be 1
  store.appendEdit("s", 1, editFor(1));
  try {
    store.appendEdit("s", 3, editFor(3));
    FAIL() << "gap accepted";
  } catch (const SeqConflictError& e) {
    EXPECT_EQ(e.expectedSeq(), 2);
    EXPECT_EQ(e.gotSeq(), 3);
  }
  EXPECT_THROW(store.appendEdit("s", 1, editFor(1)), SeqConflictError);  // repeat
  // A batch with an internal gap, or starting wrong, writes nothing.
  EXPECT_THROW(store.appendEdits("s", {{2, editFor(2), 0}, {4, editFor(4), 0}}), SeqConflictError);
  EXPECT_THROW(store.appendEdits("s", {{3, editFor(3), 0}, {4, editFor(4), 0}}), SeqConflictError);
  EXPECT_EQ(store.lastSeq("s"), 1);
  EXPECT_EQ(where.rawInt("SELECT count(*) FROM edits"), 1);

  EXPECT_THROW(store.appendEdit("nope", 1, editFor(1)), NotFoundError);
  store.appendEdit("s", 2, editFor(2));
  EXPECT_EQ(store.loadSession("s")->lastSeq, 2);
}

TEST_P(StoreSessions, SnapshotsRestoreAndPrune) {
  {
    auto storeOwner = where.open();
    Store& store = *storeOwner;
    store.createSession(makeSession("s"));
    for (std::int64_t seq = 1; seq <= 10; ++seq) store.appendEdit("s", seq, editFor(seq));

    EXPECT_THROW(store.saveSnapshot("s", 11, json{{"at", 11}}), StoreError);  // beyond lastSeq
    EXPECT_THROW(store.saveSnapshot("x", 0, json{}), NotFoundError);

    store.saveSnapshot("s", 5, json{{"at", 5}});
    auto r = store.loadSession("s");
    ASSERT_TRUE(r && r->snapshot);
    EXPECT_EQ(r->snapshot->seq, 5);
    EXPECT_EQ(r->snapshot->scene, (json{{"at", 5}}));
    ASSERT_EQ(r->editsAfterSnapshot.size(), 5u);
    EXPECT_EQ(r->editsAfterSnapshot.front().seq, 6);
    expectContiguous(*r);
    // The first snapshot prunes nothing (the initial scene is the previous "snapshot").
    EXPECT_EQ(where.rawInt("SELECT count(*) FROM edits"), 10);

    store.saveSnapshot("s", 8, json{{"at", 8}});
    EXPECT_THROW(store.saveSnapshot("s", 7, json{{"at", 7}}), StoreError);  // older than newest
    // Keeps snapshots 5 and 8 and the edits after 5.
    EXPECT_EQ(where.rawInt("SELECT count(*) FROM snapshots"), 2);
    EXPECT_EQ(where.rawInt("SELECT min(seq) FROM edits"), 6);

    store.saveSnapshot("s", 10, json{{"at", 10}});
    store.saveSnapshot("s", 10, json{{"at", "10b"}});  // same seq replaces
    EXPECT_EQ(where.rawInt("SELECT count(*) FROM snapshots"), 2);
    EXPECT_EQ(where.rawInt("SELECT min(seq) FROM snapshots"), 8);
    EXPECT_EQ(where.rawInt("SELECT min(seq) FROM edits"), 9);
    store.appendEdit("s", 11, editFor(11));
  }
  auto storeOwner = where.open();
  Store& store = *storeOwner;
  auto r = store.loadSession("s");
  ASSERT_TRUE(r && r->snapshot);
  EXPECT_EQ(r->snapshot->seq, 10);
  EXPECT_EQ(r->snapshot->scene, (json{{"at", "10b"}}));
  ASSERT_EQ(r->editsAfterSnapshot.size(), 1u);
  EXPECT_EQ(r->editsAfterSnapshot[0].edit, editFor(11));
  EXPECT_EQ(r->lastSeq, 11);
  expectContiguous(*r);
  EXPECT_THROW(store.appendEdit("s", 11, editFor(11)), SeqConflictError);
  store.appendEdit("s", 12, editFor(12));
}

TEST_P(StoreSessions, KeepSnapshotsOption) {
  StoreOptions options;
  options.keepSnapshots = 1;
  auto storeOwner = where.open(options);
  Store& store = *storeOwner;
  store.createSession(makeSession("s"));
  for (std::int64_t seq = 1; seq <= 4; ++seq) store.appendEdit("s", seq, editFor(seq));
  store.saveSnapshot("s", 3, json{{"at", 3}});
  EXPECT_EQ(where.rawInt("SELECT count(*) FROM edits"), 1);
  EXPECT_EQ(where.rawInt("SELECT count(*) FROM snapshots"), 1);
  auto r = store.loadSession("s");
  EXPECT_EQ(r->snapshot->seq, 3);
  expectContiguous(*r);
}

TEST_P(StoreSessions, DeleteCascadesToEditsAndSnapshots) {
  auto storeOwner = where.open();
  Store& store = *storeOwner;
  store.createSession(makeSession("gone"));
  store.createSession(makeSession("kept"));
  for (std::int64_t seq = 1; seq <= 6; ++seq) {
    store.appendEdit("gone", seq, editFor(seq));
    store.appendEdit("kept", seq, editFor(seq));
  }
  store.saveSnapshot("gone", 3, json{{"at", 3}});
  store.saveSnapshot("kept", 3, json{{"at", 3}});

  EXPECT_TRUE(store.deleteSession("gone"));
  EXPECT_FALSE(store.deleteSession("gone"));
  EXPECT_FALSE(store.loadSession("gone"));
  EXPECT_EQ(where.rawInt("SELECT count(*) FROM edits WHERE session_id = 'gone'"), 0);
  EXPECT_EQ(where.rawInt("SELECT count(*) FROM snapshots WHERE session_id = 'gone'"), 0);
  EXPECT_EQ(where.rawInt("SELECT count(*) FROM edits WHERE session_id = 'kept'"), 6);
  EXPECT_EQ(where.rawInt("SELECT count(*) FROM snapshots WHERE session_id = 'kept'"), 1);

  // The id can be reused and starts over.
  store.createSession(makeSession("gone"));
  auto r = store.loadSession("gone");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->lastSeq, 0);
  EXPECT_FALSE(r->snapshot);
  EXPECT_TRUE(r->editsAfterSnapshot.empty());
  store.appendEdit("gone", 1, editFor(1));
  EXPECT_EQ(store.loadSessions().size(), 2u);
}

TEST_P(StoreSessions, CheckpointsKeepTheSessionStateAndRevisionAndReplaceEachOtherWithinASeq) {
  {
    auto storeOwner = where.open();
    Store& store = *storeOwner;
    store.createSession(makeSession("s"));
    for (std::int64_t seq = 1; seq <= 4; ++seq) store.appendEdit("s", seq, editFor(seq));
    store.saveSnapshot("s", Snapshot{4, json{{"at", "4a"}}, json{{"drag_iterations", 7}}, 11});
    store.saveSnapshot("s", Snapshot{4, json{{"at", "4b"}}, json{{"drag_iterations", 8}}, 12});  // the next state shown
    store.appendEdit("s", 5, editFor(5));
  }
  auto storeOwner = where.open();
  Store& store = *storeOwner;
  auto r = store.loadSession("s");
  ASSERT_TRUE(r && r->snapshot);
  EXPECT_EQ(r->snapshot->seq, 4);
  EXPECT_EQ(r->snapshot->scene, (json{{"at", "4b"}}));
  EXPECT_EQ(r->snapshot->sessionState, (json{{"drag_iterations", 8}}));
  EXPECT_EQ(r->snapshot->revision, 12);
  ASSERT_EQ(r->editsAfterSnapshot.size(), 1u);
  EXPECT_EQ(r->editsAfterSnapshot[0].seq, 5);
  EXPECT_FALSE(r->loadError);
  EXPECT_EQ(where.rawInt("SELECT count(*) FROM snapshots WHERE session_id = 's'"), 1);
}

TEST_P(StoreSessions, AQuarantinedSessionKeepsEveryRowAndItsReasonAcrossReopening) {
  {
    auto storeOwner = where.open();
    Store& store = *storeOwner;
    store.createSession(makeSession("q"));
    for (std::int64_t seq = 1; seq <= 3; ++seq) store.appendEdit("q", seq, editFor(seq));
    store.saveSnapshot("q", 2, json{{"at", 2}});
    store.quarantineSession("q", "model.fixed[0]: no control point 99");
    EXPECT_THROW(store.quarantineSession("nope", "x"), NotFoundError);
    EXPECT_THROW(store.liftQuarantine("nope"), NotFoundError);
  }
  auto storeOwner = where.open();
  Store& store = *storeOwner;
  auto r = store.loadSession("q");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->session.quarantine, std::optional<std::string>("model.fixed[0]: no control point 99"));
  ASSERT_TRUE(r->snapshot);
  EXPECT_EQ(r->editsAfterSnapshot.size(), 1u);
  EXPECT_EQ(where.rawInt("SELECT count(*) FROM edits WHERE session_id = 'q'"), 3);
  store.liftQuarantine("q");
  EXPECT_FALSE(store.loadSession("q")->session.quarantine);
}

TEST_P(StoreSessions, ARowThatDoesNotParseMakesOnlyItsSessionUnrestorable) {
  {
    auto storeOwner = where.open();
    Store& store = *storeOwner;
    for (const char* id : {"a", "b"}) {
      store.createSession(makeSession(id));
      store.appendEdit(id, 1, editFor(1));
      store.saveSnapshot(id, 1, json{{"at", 1}});
    }
  }
  where.rawInt("UPDATE snapshots SET scene = '{\"at\": ' WHERE session_id = 'a'");
  {
    auto storeOwner = where.open();
    Store& store = *storeOwner;
    store.createSession(makeSession("c"));
  }
  where.rawInt("UPDATE sessions SET initial_scene = 'nope' WHERE id = 'c'");
  auto storeOwner = where.open();
  Store& store = *storeOwner;
  const auto all = store.loadSessions();
  ASSERT_EQ(all.size(), 3u);
  for (const RestoredSession& r : all) {
    if (r.session.id == "a") {
      ASSERT_TRUE(r.loadError);
      EXPECT_NE(r.loadError->find("snapshot of session a"), std::string::npos) << *r.loadError;
    } else if (r.session.id == "c") {
      ASSERT_TRUE(r.loadError);
      EXPECT_NE(r.loadError->find("initial scene of session c"), std::string::npos) << *r.loadError;
      EXPECT_EQ(r.session.editTokenHash, "edit-hash-c");  // enough to let its owner reach it
    } else {
      EXPECT_FALSE(r.loadError);
      ASSERT_TRUE(r.snapshot);
      EXPECT_EQ(r.snapshot->scene, (json{{"at", 1}}));
    }
  }
}

TEST(StoreOpen, AVersion1DatabaseMigratesKeepingItsSessions) {
  TempDir tmp;
  {
    sqlite3* db = nullptr;
    const std::string file = (tmp.path() / SqliteStore::kFileName).string();
    ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
    const char* v1 = R"sql(
CREATE TABLE sessions (id TEXT NOT NULL PRIMARY KEY, edit_token_hash TEXT NOT NULL, view_token_hash TEXT NOT NULL,
  name TEXT NOT NULL, demo INTEGER NOT NULL CHECK (demo IN (0, 1)), initial_scene TEXT NOT NULL,
  created_ms INTEGER NOT NULL, last_seq INTEGER NOT NULL DEFAULT 0 CHECK (last_seq >= 0)) STRICT;
CREATE TABLE edits (session_id TEXT NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  seq INTEGER NOT NULL CHECK (seq >= 1), edit TEXT NOT NULL, time_ms INTEGER NOT NULL, PRIMARY KEY (session_id, seq)) STRICT;
CREATE TABLE snapshots (session_id TEXT NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  seq INTEGER NOT NULL CHECK (seq >= 0), scene TEXT NOT NULL, created_ms INTEGER NOT NULL, PRIMARY KEY (session_id, seq)) STRICT;
CREATE TABLE jobs (id TEXT NOT NULL PRIMARY KEY, state TEXT NOT NULL
  CHECK (state IN ('queued','running','succeeded','failed','cancelled')), scene TEXT NOT NULL,
  idempotency_key TEXT UNIQUE, idempotency_fingerprint TEXT NOT NULL, report TEXT, error TEXT,
  created_ms INTEGER NOT NULL, updated_ms INTEGER NOT NULL, progress_iteration INTEGER NOT NULL DEFAULT 0,
  progress_of INTEGER NOT NULL DEFAULT 0) STRICT;
CREATE INDEX jobs_by_state ON jobs (state, updated_ms);
INSERT INTO sessions VALUES ('old', 'a9993e364706816aba3e25717850c26c9cd0d89d', 'v', 'old', 0, '{"x":1}', 5, 2);
INSERT INTO edits VALUES ('old', 2, '{"op":"move"}', 6);
INSERT INTO snapshots VALUES ('old', 1, '{"x":2}', 6);
PRAGMA user_version = 1;
)sql";
    ASSERT_EQ(sqlite3_exec(db, v1, nullptr, nullptr, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
    sqlite3_close(db);
  }
  SqliteStore store(tmp.str());
  EXPECT_EQ(store.info().schemaVersion, Store::kSchemaVersion);
  auto r = store.loadSession("old");
  ASSERT_TRUE(r && r->snapshot);
  EXPECT_EQ(r->session.editTokenHash, "a9993e364706816aba3e25717850c26c9cd0d89d");
  EXPECT_FALSE(r->session.quarantine);
  EXPECT_EQ(r->snapshot->scene, (json{{"x", 2}}));
  EXPECT_TRUE(r->snapshot->sessionState.is_null());
  EXPECT_EQ(r->snapshot->revision, 0);
  ASSERT_EQ(r->editsAfterSnapshot.size(), 1u);
  EXPECT_EQ(r->lastSeq, 2);
}

// --- jobs ---------------------------------------------------------------------------------------

TEST(StoreJobStates, NamesRoundTripAndFinishedOnesAreKnown) {
  for (JobState s : {JobState::Queued, JobState::Running, JobState::Succeeded, JobState::Failed,
                     JobState::Cancelled}) {
    EXPECT_EQ(jobStateFromName(jobStateName(s)), s);
  }
  EXPECT_EQ(jobStateName(JobState::Cancelled), "cancelled");
  EXPECT_THROW(jobStateFromName("done"), std::invalid_argument);
  EXPECT_TRUE(isFinished(JobState::Failed));
  EXPECT_FALSE(isFinished(JobState::Running));
}

TEST_P(StoreJobs, RoundTripUpdateAndReopen) {
  {
    auto storeOwner = where.open();
    Store& store = *storeOwner;
    JobRecord j = makeJob("j1", "key-1");
    store.putJob(j);
    EXPECT_THROW(store.putJob(makeJob("j1")), AlreadyExistsError);

    auto got = store.job("j1");
    ASSERT_TRUE(got);
    EXPECT_EQ(got->state, JobState::Queued);
    EXPECT_EQ(got->scene, j.scene);
    EXPECT_EQ(got->idempotencyKey, std::optional<std::string>("key-1"));
    EXPECT_EQ(got->idempotencyFingerprint, "fp-j1");
    EXPECT_FALSE(got->report);
    EXPECT_FALSE(got->error);
    EXPECT_EQ(got->createdMs, 5000);

    j.state = JobState::Running;
    j.progressIteration = 7;
    j.progressOf = 40;
    j.updatedMs = 6000;
    store.updateJob(j);
    j.state = JobState::Succeeded;
    j.report = json{{"energy", 1.25e-9}, {"iterations", 40}};
    j.progressIteration = 40;
    j.updatedMs = 7000;
    store.updateJob(j);
    EXPECT_THROW(store.updateJob(makeJob("missing")), NotFoundError);
  }
  auto storeOwner = where.open();
  Store& store = *storeOwner;
  auto got = store.job("j1");
  ASSERT_TRUE(got);
  EXPECT_EQ(got->state, JobState::Succeeded);
  ASSERT_TRUE(got->report);
  EXPECT_EQ(*got->report, (json{{"energy", 1.25e-9}, {"iterations", 40}}));
  EXPECT_EQ(got->progressIteration, 40);
  EXPECT_EQ(got->progressOf, 40);
  EXPECT_EQ(got->createdMs, 5000);
  EXPECT_EQ(got->updatedMs, 7000);
  EXPECT_FALSE(store.job("nope"));
}

TEST_P(StoreJobs, IdempotencyKeyConflict) {
  auto storeOwner = where.open();
  Store& store = *storeOwner;
  store.putJob(makeJob("first", "K"));
  try {
    store.putJob(makeJob("second", "K"));
    FAIL() << "duplicate idempotency key accepted";
  } catch (const IdempotencyConflictError& e) {
    EXPECT_EQ(e.key(), "K");
    EXPECT_EQ(e.existingJobId(), "first");
    EXPECT_EQ(e.existingFingerprint(), "fp-first");
  }
  EXPECT_FALSE(store.job("second"));
  auto byKey = store.jobByIdempotencyKey("K");
  ASSERT_TRUE(byKey);
  EXPECT_EQ(byKey->id, "first");
  EXPECT_FALSE(store.jobByIdempotencyKey("other"));
  // Jobs without a key never conflict with each other.
  store.putJob(makeJob("n1"));
  store.putJob(makeJob("n2"));
  EXPECT_EQ(store.jobCounts()[JobState::Queued], 3);
  // Pruning the finished job frees its key.
  JobRecord first = *store.job("first");
  first.state = JobState::Failed;
  first.error = "diverged";
  first.updatedMs = 10;
  store.updateJob(first);
  EXPECT_EQ(store.job("first")->error, std::optional<std::string>("diverged"));
  EXPECT_EQ(store.pruneFinishedJobs(11), 1);
  store.putJob(makeJob("third", "K"));
  EXPECT_EQ(store.jobByIdempotencyKey("K")->id, "third");
}

TEST_P(StoreJobs, UnfinishedRequeueCountsAndPrune) {
  {
    auto storeOwner = where.open();
    Store& store = *storeOwner;
    const JobState states[] = {JobState::Queued,    JobState::Running, JobState::Succeeded,
                               JobState::Failed,    JobState::Cancelled, JobState::Running,
                               JobState::Succeeded};
    int i = 0;
    for (JobState s : states) {
      JobRecord j = makeJob("job" + std::to_string(i), std::nullopt, 100 - i);  // reverse age
      store.putJob(j);
      j.state = s;
      j.progressIteration = 3;
      j.updatedMs = 1000 + 100 * i;
      store.updateJob(j);
      ++i;
    }
    auto counts = store.jobCounts();
    EXPECT_EQ(counts.size(), 5u);
    EXPECT_EQ(counts[JobState::Queued], 1);
    EXPECT_EQ(counts[JobState::Running], 2);
    EXPECT_EQ(counts[JobState::Succeeded], 2);
    EXPECT_EQ(counts[JobState::Failed], 1);
    EXPECT_EQ(counts[JobState::Cancelled], 1);
  }
  // "Restart": running jobs are found and re-queued.
  auto storeOwner = where.open();
  Store& store = *storeOwner;
  auto unfinished = store.unfinishedJobs();
  ASSERT_EQ(unfinished.size(), 3u);
  EXPECT_EQ(unfinished[0].id, "job5");  // oldest first
  EXPECT_EQ(unfinished[1].id, "job1");
  EXPECT_EQ(unfinished[2].id, "job0");
  EXPECT_EQ(store.requeueInterruptedJobs(9999), 2);
  for (const JobRecord& j : store.unfinishedJobs()) {
    EXPECT_EQ(j.state, JobState::Queued);
    if (j.id != "job0") {
      EXPECT_EQ(j.progressIteration, 0);
      EXPECT_EQ(j.updatedMs, 9999);
    }
  }
  // Finished jobs updated before 1500: job2 (1200), job3 (1300), job4 (1400); job6 (1600) stays.
  EXPECT_EQ(store.pruneFinishedJobs(1500), 3);
  auto counts = store.jobCounts();
  EXPECT_EQ(counts[JobState::Queued], 3);
  EXPECT_EQ(counts[JobState::Succeeded], 1);
  EXPECT_EQ(counts[JobState::Failed], 0);
  EXPECT_EQ(counts[JobState::Cancelled], 0);
  EXPECT_TRUE(store.job("job6"));
  EXPECT_FALSE(store.job("job2"));
}

// --- concurrency --------------------------------------------------------------------------------

TEST_P(StoreConcurrency, WritersOnDifferentSessionsWithReaders) {
  auto storeOwner = where.open();
  Store& store = *storeOwner;
  constexpr int kWriters = 6;
  constexpr std::int64_t kEdits = 300;
  for (int w = 0; w < kWriters; ++w) store.createSession(makeSession("s" + std::to_string(w)));

  std::atomic<bool> done{false};
  std::atomic<int> readerFailures{0}, reads{0};
  std::vector<std::thread> threads;
  for (int w = 0; w < kWriters; ++w) {
    threads.emplace_back([&, w] {
      std::string id = "s" + std::to_string(w);
      std::int64_t seq = 0;
      while (seq < kEdits) {
        if (seq % 4 == 3 && seq + 3 <= kEdits) {
          store.appendEdits(id, {{seq + 1, editFor(seq + 1), 1},
                                 {seq + 2, editFor(seq + 2), 1},
                                 {seq + 3, editFor(seq + 3), 1}});
          seq += 3;
        } else {
          ++seq;
          store.appendEdit(id, seq, editFor(seq));
        }
        if (seq % 50 == 0) store.saveSnapshot(id, seq, json{{"at", seq}});
      }
    });
  }
  for (int r = 0; r < 2; ++r) {
    threads.emplace_back([&] {
      do {
        for (const RestoredSession& s : store.loadSessions()) {
          std::int64_t expected = s.snapshot ? s.snapshot->seq + 1 : 1;
          for (const EditRecord& e : s.editsAfterSnapshot) {
            if (e.seq != expected++ || e.edit != editFor(e.seq)) ++readerFailures;
          }
          if (expected - 1 != s.lastSeq) ++readerFailures;
        }
        if (auto j = store.loadSession("s0"); !j) ++readerFailures;
        ++reads;
      } while (!done);
    });
  }
  for (int w = 0; w < kWriters; ++w) threads[static_cast<std::size_t>(w)].join();
  done = true;
  for (std::size_t i = kWriters; i < threads.size(); ++i) threads[i].join();

  EXPECT_EQ(readerFailures, 0);
  EXPECT_GT(reads, 0);
  auto all = store.loadSessions();
  ASSERT_EQ(all.size(), static_cast<std::size_t>(kWriters));
  for (const RestoredSession& s : all) {
    EXPECT_EQ(s.lastSeq, kEdits);
    ASSERT_TRUE(s.snapshot);
    EXPECT_EQ(s.snapshot->seq, kEdits);
    expectContiguous(s);
  }
}

TEST_P(StoreConcurrency, RacingAppendsToOneSessionNeverDuplicateOrSkip) {
  auto storeOwner = where.open();
  Store& store = *storeOwner;
  store.createSession(makeSession("shared"));
  constexpr int kThreads = 4;
  constexpr std::int64_t kTotal = 400;
  std::atomic<std::int64_t> accepted{0};
  std::vector<int> perThread(kThreads, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      while (accepted < kTotal) {
        std::int64_t next = store.lastSeq("shared") + 1;
        if (next > kTotal) break;
        try {
          store.appendEdit("shared", next, json{{"by", t}, {"seq", next}});
          ++perThread[static_cast<std::size_t>(t)];
          ++accepted;
        } catch (const SeqConflictError&) {
          // another thread took this seq
        }
      }
    });
  }
  for (auto& th : threads) th.join();
  auto r = store.loadSession("shared");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->lastSeq, kTotal);
  EXPECT_EQ(accepted, kTotal);
  int sum = 0;
  for (int n : perThread) sum += n;
  EXPECT_EQ(sum, kTotal);
  expectContiguous(*r);
  for (const EditRecord& e : r->editsAfterSnapshot) EXPECT_EQ(e.edit["seq"], e.seq);
}
