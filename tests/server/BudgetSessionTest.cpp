// Issue 12 "bounded resources" in a session: an edit over a resource limit or over the session's
// time budget is refused with an error naming the field; nothing is applied, nothing journalled,
// and the session keeps working.
#include "devsurf/server/Session.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include <unistd.h>

#include "devsurf/server/Tokens.h"
#include "server/SessionTesting.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
using testing::Inbox;
using testing::ManualExecutor;
using testing::MemoryJournal;

using BudgetEditor = testing::ExampleEditor;
using testing::exampleJson;

/// Resident memory of this process, bytes.
double residentBytes() {
  std::ifstream statm("/proc/self/statm");
  long size = 0, resident = 0;
  statm >> size >> resident;
  return static_cast<double>(resident) * static_cast<double>(::sysconf(_SC_PAGESIZE));
}

TEST(BudgetSession, TheRunawayQuasiStripEditIsRefusedByItsEstimateWithoutGrowingAndNothingIsJournalled) {
  BudgetEditor e("quasi-strip-twisted");
  const json before = e.session->sceneJson();
  const std::size_t journalled = e.journal.edits.size();
  const std::int64_t seq = e.session->seq();
  const double rss = residentBytes();
  // The outside tester's edit grew the daemon to 8.8 GB before std::bad_alloc.
  e.send({{"type", "set_params"}, {"op", "runaway"}, {"params", {{"mapping", {{"degree", 9}, {"coefficients", 10000}}}}}});
  const json err = e.inbox.last("error");
  ASSERT_FALSE(err.is_null());
  EXPECT_EQ(err["code"], "limit");
  EXPECT_EQ(err["path"], "params.mapping.coefficients");
  EXPECT_EQ(err["op"], "runaway");
  const std::string message = err["message"];
  EXPECT_EQ(message.rfind("set_params: params.mapping.coefficients: the model would need about ", 0), 0u) << message;
  EXPECT_NE(message.find("over the budget of 512 MiB"), std::string::npos) << message;
  EXPECT_LT(residentBytes() - rss, 64.0 * 1024 * 1024);  // refused before anything was allocated
  EXPECT_EQ(e.journal.edits.size(), journalled);
  EXPECT_EQ(e.session->seq(), seq);
  EXPECT_EQ(e.session->sceneJson(), before);
  // The session keeps working.
  e.send({{"type", "set_params"}, {"op", "ok"}, {"params", {{"samples", 120}}}});
  EXPECT_EQ(e.inbox.last("ack")["op"], "ok");
  EXPECT_EQ(e.session->sceneJson()["model"]["samples"], 120);
}

TEST(BudgetSession, AConicalRebuildOverTheSessionsTimeBudgetIsRefusedAndNothingIsApplied) {
  SessionSettings settings;
  settings.rebuildTimeBudgetMs = 3000.0;  // the hull builds and solves in ~0.3 s, 10 000 samples in ~45 s
  BudgetEditor e("conical-strip-hull", settings);
  const json before = e.session->sceneJson();
  const std::size_t journalled = e.journal.edits.size();
  // 10 000 samples a side (the schema's maximum) take tens of seconds to build.
  e.send({{"type", "set_params"}, {"op", 7}, {"params", {{"np", 10000}, {"nq", 10000}}}});
  const json err = e.inbox.last("error");
  ASSERT_FALSE(err.is_null());
  EXPECT_EQ(err["code"], "time_budget");
  EXPECT_EQ(err["path"], "params");
  const std::string message = err["message"];
  EXPECT_NE(message.find("this session's time budget of 3000 ms was exceeded"), std::string::npos) << message;
  EXPECT_NE(message.find("nothing was applied"), std::string::npos) << message;
  EXPECT_EQ(e.journal.edits.size(), journalled);
  EXPECT_EQ(e.session->sceneJson(), before);
  // np = 100 000 (which took over 30 s) is beyond the schema's maximum.
  e.send({{"type", "set_params"}, {"op", 8}, {"params", {{"np", 100000}}}});
  EXPECT_EQ(e.inbox.last("error")["path"], "params.np");
  EXPECT_EQ(e.inbox.last("error")["code"], "invalid");
  e.send({{"type", "set_params"}, {"op", 9}, {"params", {{"np", 40}}}});
  EXPECT_EQ(e.inbox.last("ack")["op"], 9);
}

TEST(BudgetSession, SetSolverOverTheIterationLimitIsRefusedNamingSolverIterations) {
  SessionSettings settings;
  settings.resources.maxIterations = 500;
  BudgetEditor e("strip-lifted-corner", settings);
  e.send({{"type", "set_solver"}, {"op", 1}, {"solver", {{"iterations", 501}}}});
  const json err = e.inbox.last("error");
  ASSERT_FALSE(err.is_null());
  EXPECT_EQ(err["code"], "limit");
  EXPECT_EQ(err["path"], "solver.iterations");
  EXPECT_TRUE(e.journal.edits.empty());
  e.send({{"type", "set_solver"}, {"op", 2}, {"solver", {{"iterations", 500}}}});
  EXPECT_EQ(e.inbox.last("ack")["op"], 2);
}

TEST(BudgetSession, AStructuralEditOverTheMemoryBudgetIsRefusedNamingTheFieldAndLeavesNoUndoStep) {
  SessionSettings settings;
  // Room for the strip as it is, not for 20 000 normal-spline control points.
  settings.resources.memoryBudgetBytes =
      proto::estimateResources(testing::exampleScene("strip-lifted-corner")).bytes + 1024.0 * 1024;
  BudgetEditor e("strip-lifted-corner", settings);
  e.send({{"type", "set_solver"}, {"op", 1}, {"solver", json::object()}, {"normals", {{"type", "spline"}, {"points", 20000}}}});
  const json err = e.inbox.last("error");
  ASSERT_FALSE(err.is_null());
  EXPECT_EQ(err["code"], "limit");
  EXPECT_EQ(err["path"], "model.normals.points");
  e.send({{"type", "undo"}, {"op", 2}});
  EXPECT_EQ(e.inbox.last("error")["message"], "undo: nothing to undo");
}

}  // namespace
}  // namespace devsurf::server

namespace devsurf::server {
namespace {

TEST(BudgetSession, ADragWhoseFirstContactRebuildRunsOutOfTimeIsAnsweredByItsOwnCodeNotInternal) {
  // The first drag of a point adds a temporary handle: a rebuild under the session's time budget.
  // Out of time there, the sender hears `time_budget` (the long hostile-client run saw `internal`).
  BudgetEditor e("composite-curved-fold");
  e.session->setRebuildTimeBudget(1e-6);
  const json before = e.session->sceneJson();
  e.send({{"type", "drag"}, {"op", 1}, {"target", {{"vertex", 0}}}, {"position", {0.1, 0.2, 0.3}}});
  const json error = e.inbox.last("error");
  ASSERT_FALSE(error.is_null());
  EXPECT_EQ(error["code"], "time_budget") << error.dump();
  EXPECT_EQ(e.session->sceneJson()["model"], before["model"]);
}

}  // namespace
}  // namespace devsurf::server
