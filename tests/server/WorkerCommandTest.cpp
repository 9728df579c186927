// `devsurf worker` (issue 18): its arguments. A worker claiming and handing back jobs on a real
// PostgreSQL: tests/server/cluster/test_cluster_jobs.py.

#include <gtest/gtest.h>

#include "CliTesting.h"

namespace devsurf::server {
namespace {

using testing::runCommand;

TEST(WorkerCommand, NeedsTheSharedStoreAndSaysSo) {
  const auto none = runCommand({"worker"});
  EXPECT_EQ(none.code, 2);
  EXPECT_NE(none.err.find("--store: a worker needs the shared store"), std::string::npos) << none.err;
  const auto sqlite = runCommand({"worker", "--store", "/tmp/some-data-dir"});
  EXPECT_EQ(sqlite.code, 2);
  EXPECT_NE(sqlite.err.find("(got \"/tmp/some-data-dir\")"), std::string::npos) << sqlite.err;
}

TEST(WorkerCommand, BadFlagsAreRefusedNamingTheFlag) {
  const auto workers = runCommand({"worker", "--store", "postgresql:///x", "--job-workers", "0"});
  EXPECT_EQ(workers.code, 2);
  EXPECT_NE(workers.err.find("--job-workers: expected an integer from 1 to 256, got \"0\""), std::string::npos) << workers.err;
  const auto unknown = runCommand({"worker", "--store", "postgresql:///x", "--port", "80"});
  EXPECT_EQ(unknown.code, 2);
  EXPECT_NE(unknown.err.find("unknown option --port"), std::string::npos) << unknown.err;
}

TEST(WorkerCommand, AnUnreachableStoreIsAClearErrorNotAHang) {
  const auto run = runCommand({"worker", "--store", "postgresql://nobody@/nodb?host=/nonexistent-socket-dir&connect_timeout=2"});
  EXPECT_EQ(run.code, 1);
  EXPECT_NE(run.err.find("cannot connect to PostgreSQL"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("password"), std::string::npos);
}

TEST(WorkerCommand, HelpListsItsFlags) {
  const auto help = runCommand({"worker", "--help"});
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find("--store postgresql://"), std::string::npos);
  EXPECT_NE(runCommand({"help"}).out.find("worker --store postgresql://"), std::string::npos);
}

}  // namespace
}  // namespace devsurf::server
