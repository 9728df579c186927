// What the stores sustain (issue 18, docs/scaling.md): acknowledged edits (one edit per
// transaction, as a session journals a drag message) and jobs (claim + finish) per second, for
// SQLite and for PostgreSQL. PostgreSQL runs need DEVSURF_BENCH_POSTGRES, a libpq URI of a
// database the bench may create a schema in (scripts/postgres-local.sh start DIR prints one);
// without it those runs are skipped.
//
//   DEVSURF_BENCH_POSTGRES=$(scripts/postgres-local.sh start /tmp/pg) build/bench/store_throughput
//
// Threads stand for sessions (or workers) writing at once, each through its own store (its own
// connections), as several daemons would.

#include <benchmark/benchmark.h>
#include <libpq-fe.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <string>

#include "devsurf/server/store/Store.h"

namespace {

using devsurf::server::store::JobRecord;
using devsurf::server::store::JobState;
using devsurf::server::store::SessionRecord;
using devsurf::server::store::Store;

/// One location per backend for the whole run: a directory, or a fresh schema.
std::string benchLocation(bool postgres) {
  static std::once_flag once;
  static std::string sqliteDir, pgUri;
  std::call_once(once, []() {
    sqliteDir = (std::filesystem::temp_directory_path() / ("devsurf-store-bench-" + std::to_string(::getpid()))).string();
    std::filesystem::remove_all(sqliteDir);
    if (const char* base = std::getenv("DEVSURF_BENCH_POSTGRES")) {
      const std::string schema = "bench" + std::to_string(::getpid());
      PGconn* c = PQconnectdb(base);
      if (PQstatus(c) == CONNECTION_OK) {
        PQclear(PQexec(c, ("DROP SCHEMA IF EXISTS " + schema + " CASCADE; CREATE SCHEMA " + schema).c_str()));
        const std::string b = base;
        pgUri = b + (b.find('?') == std::string::npos ? "?" : "&") + "options=-csearch_path%3D" + schema;
      }
      PQfinish(c);
    }
  });
  return postgres ? pgUri : sqliteDir;
}

/// A drag message's journal entry: about the size the daemon writes.
const nlohmann::json& dragEdit() {
  static const nlohmann::json edit = {{"type", "drag"}, {"target", {{"curve", "b"}, {"index", 6}}},
                                      {"position", {6.0, 1.0, 0.734}}, {"by", 3}};
  return edit;
}

void AcknowledgedEdits(benchmark::State& state) {
  const bool postgres = state.range(0) != 0;
  const std::string where = benchLocation(postgres);
  if (where.empty()) {
    state.SkipWithError("no DEVSURF_BENCH_POSTGRES");
    return;
  }
  static std::atomic<int> sessionCounter{0};
  std::unique_ptr<Store> store = devsurf::server::store::openStore(where);
  SessionRecord s;
  s.id = "s" + std::to_string(sessionCounter++) + "-" + std::to_string(state.thread_index());
  s.editTokenHash = s.viewTokenHash = "h";
  s.name = s.id;
  s.initialScene = nlohmann::json::object();
  s.createdMs = 1;
  store->createSession(s);
  std::int64_t seq = 0;
  for (auto _ : state) store->appendEdit(s.id, ++seq, dragEdit(), 1);
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(postgres ? "postgresql" : "sqlite");
}
BENCHMARK(AcknowledgedEdits)->Arg(0)->Arg(1)->Threads(1)->Threads(4)->UseRealTime()->Unit(benchmark::kMicrosecond);

void JobClaimAndFinish(benchmark::State& state) {
  const bool postgres = state.range(0) != 0;
  const std::string where = benchLocation(postgres);
  if (where.empty()) {
    state.SkipWithError("no DEVSURF_BENCH_POSTGRES");
    return;
  }
  std::unique_ptr<Store> store = devsurf::server::store::openStore(where);
  static std::atomic<int> jobCounter{0};
  const std::string owner = "node" + std::to_string(state.thread_index());
  for (auto _ : state) {
    state.PauseTiming();
    JobRecord j;
    j.id = "j" + std::to_string(jobCounter++);
    j.scene = {{"job", j.id}};
    j.idempotencyFingerprint = "fp";
    j.createdMs = j.updatedMs = devsurf::server::store::wallClockMs();
    store->putJob(j);
    state.ResumeTiming();
    auto claimed = store->claimJob(owner, devsurf::server::store::wallClockMs(), 60000);
    if (!claimed) continue;  // another thread took it: it finishes that one
    claimed->state = JobState::Succeeded;
    claimed->report = nlohmann::json{{"ok", true}};
    store->finishJob(*claimed, owner, claimed->attempt);
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(postgres ? "postgresql" : "sqlite");
}
BENCHMARK(JobClaimAndFinish)->Arg(0)->Arg(1)->Threads(1)->Threads(4)->UseRealTime()->Unit(benchmark::kMicrosecond);

/// A checkpoint: every state a session shows is stored first (up to ~33 per second while a
/// participant drags), after the edit that led to it. Arg 1: the scene,
/// examples/composite-pleated-sheet.json (8.9 KB), or a synthetic scene of 10 000 points (a large
/// design: its size is in the label).
void Checkpoints(benchmark::State& state) {
  const bool postgres = state.range(0) != 0;
  const std::string where = benchLocation(postgres);
  if (where.empty()) {
    state.SkipWithError("no DEVSURF_BENCH_POSTGRES");
    return;
  }
  nlohmann::json scene;
  if (state.range(1) == 0) {
    std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/composite-pleated-sheet.json");
    scene = nlohmann::json::parse(file);
  } else {
    nlohmann::json points = nlohmann::json::array();
    for (int i = 0; i < 10000; ++i) points.push_back({0.1234567890123 * i, -2.345678901234 * i, 3.45678901234 * i});
    scene = {{"model", {{"vertices", points}}}};
  }
  const std::size_t bytes = scene.dump().size();
  std::unique_ptr<Store> store = devsurf::server::store::openStore(where);
  static std::atomic<int> counter{0};
  SessionRecord s;
  s.id = "c" + std::to_string(counter++);
  s.editTokenHash = s.viewTokenHash = "h";
  s.name = s.id;
  s.initialScene = scene;
  s.createdMs = 1;
  store->createSession(s);
  std::int64_t seq = 0;
  for (auto _ : state) {
    store->appendEdit(s.id, ++seq, dragEdit(), 1);
    store->saveSnapshot(s.id, devsurf::server::store::Snapshot{seq, scene, nullptr, seq});
  }
  state.SetItemsProcessed(state.iterations());
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes));
  state.SetLabel(std::string(postgres ? "postgresql" : "sqlite") + ", " + std::to_string(bytes / 1024) + " KiB scene");
}
BENCHMARK(Checkpoints)->Args({0, 0})->Args({1, 0})->Args({0, 1})->Args({1, 1})->UseRealTime()->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
