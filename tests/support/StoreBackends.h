#pragma once

// Shared test helper: a fresh store of either backend for one test (issue 18: the same tests run
// against SQLite and PostgreSQL).
//
// PostgreSQL tests need a server: DEVSURF_TEST_POSTGRES holds a libpq URI of a database the tests
// may create schemas in. CTest starts a private cluster for them (scripts/postgres-local.sh, the
// `postgres` fixture in tests/CMakeLists.txt) and sets the variable; run by hand without it, the
// PostgreSQL cases are skipped with a message saying so.

#include <libpq-fe.h>
#include <sqlite3.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "devsurf/server/store/PostgresStore.h"
#include "devsurf/server/store/SqliteStore.h"
#include "support/TempDir.h"

namespace devsurf::testing {

/// "sqlite" and "postgresql": the backends every store test runs against.
inline std::vector<std::string> storeBackends() { return {"sqlite", "postgresql"}; }

/// The URI of the test PostgreSQL database, or empty.
inline std::string testPostgresUri() {
  const char* uri = std::getenv("DEVSURF_TEST_POSTGRES");
  return uri ? uri : "";
}

/// One connection for statements the store does not offer (test set-up, corrupting rows).
class RawPostgres {
 public:
  explicit RawPostgres(const std::string& uri) : conn_(PQconnectdb(uri.c_str())) {
    if (PQstatus(conn_) != CONNECTION_OK) {
      const std::string why = PQerrorMessage(conn_);
      PQfinish(conn_);
      throw std::runtime_error("cannot connect to the test PostgreSQL (" + uri + "): " + why);
    }
    PQsetNoticeProcessor(conn_, [](void*, const char*) {}, nullptr);
  }
  ~RawPostgres() { PQfinish(conn_); }
  RawPostgres(const RawPostgres&) = delete;
  RawPostgres& operator=(const RawPostgres&) = delete;

  /// Runs SQL; @return the first column of the first row as an integer, or -1 without one.
  std::int64_t exec(const std::string& sql) {
    PGresult* r = PQexec(conn_, sql.c_str());
    const ExecStatusType status = PQresultStatus(r);
    if (status != PGRES_COMMAND_OK && status != PGRES_TUPLES_OK) {
      const std::string why = PQresultErrorMessage(r);
      PQclear(r);
      throw std::runtime_error(sql + ": " + why);
    }
    std::int64_t v = -1;
    if (status == PGRES_TUPLES_OK && PQntuples(r) > 0 && !PQgetisnull(r, 0, 0)) v = std::stoll(PQgetvalue(r, 0, 0));
    PQclear(r);
    return v;
  }

 private:
  PGconn* conn_;
};

/// A fresh, empty place for a store of one backend: a temporary directory (SQLite) or a schema of
/// its own in the test database (PostgreSQL), removed afterwards. Stores opened on it share it,
/// so closing and opening again is a restart.
class StoreLocation {
 public:
  explicit StoreLocation(std::string backend) : backend_(std::move(backend)) {
    if (backend_ == "sqlite") {
      dir_ = std::make_unique<TempDir>("devsurf-store");
      location_ = dir_->str();
      return;
    }
    base_ = testPostgresUri();
    if (base_.empty()) return;
    static std::atomic<int> counter{0};
    schema_ = "t" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
    RawPostgres(base_).exec("DROP SCHEMA IF EXISTS " + schema_ + " CASCADE; CREATE SCHEMA " + schema_);
    location_ = base_ + (base_.find('?') == std::string::npos ? "?" : "&") + "options=-csearch_path%3D" + schema_;
  }
  ~StoreLocation() {
    if (schema_.empty()) return;
    try {
      RawPostgres(base_).exec("DROP SCHEMA IF EXISTS " + schema_ + " CASCADE");
    } catch (const std::exception&) {  // the server went away: nothing to clean
    }
  }
  StoreLocation(const StoreLocation&) = delete;
  StoreLocation& operator=(const StoreLocation&) = delete;

  const std::string& backend() const { return backend_; }
  /// False for PostgreSQL without DEVSURF_TEST_POSTGRES.
  bool available() const { return !location_.empty(); }
  /// The directory or URI (what `devsurf serve --store` takes).
  const std::string& location() const { return location_; }

  /// A store on this location. The lease tests pass their own times (nowMs 1000, 6000, …), so
  /// PostgreSQL's lease clock is the callers' unless `serverClock`.
  std::unique_ptr<server::store::Store> open(server::store::StoreOptions options = {}, bool serverClock = false) const {
    if (!available()) throw std::logic_error("no test PostgreSQL (DEVSURF_TEST_POSTGRES)");
    options.serverClock = serverClock;
    return server::store::openStore(location_, options);
  }

  /// Runs one SQL statement on the stored tables behind the store's back (both backends speak it);
  /// @return the first column of the first row as an integer, or -1 without one.
  std::int64_t rawInt(const std::string& sql) const {
    if (backend_ == "postgresql") return RawPostgres(location_).exec(sql);
    sqlite3* db = nullptr;
    const std::string file = (dir_->path() / server::store::SqliteStore::kFileName).string();
    if (sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr) != SQLITE_OK) {
      sqlite3_close(db);
      throw std::runtime_error("open " + file);
    }
    sqlite3_stmt* s = nullptr;
    std::int64_t v = -1;
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr) != SQLITE_OK) {
      const std::string why = sqlite3_errmsg(db);
      sqlite3_close(db);
      throw std::runtime_error(sql + ": " + why);
    }
    if (sqlite3_step(s) == SQLITE_ROW) v = sqlite3_column_int64(s, 0);
    sqlite3_finalize(s);
    sqlite3_close(db);
    return v;
  }

 private:
  std::string backend_, base_, schema_, location_;
  std::unique_ptr<TempDir> dir_;
};

}  // namespace devsurf::testing

/// In a test parameterised by backend name: skips (with the reason) when the backend has no
/// server here.
#define DEVSURF_REQUIRE_STORE(location)                                                         \
  do {                                                                                          \
    if (!(location).available())                                                                \
      GTEST_SKIP() << "no PostgreSQL for tests: set DEVSURF_TEST_POSTGRES (CTest starts one)"; \
  } while (0)
