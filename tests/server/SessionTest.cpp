#include "devsurf/server/Session.h"

#include "devsurf/server/Tokens.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>

namespace devsurf::server {
namespace {

using nlohmann::json;

/// Work runs when the test says so (a manual executor), so interleavings are explicit.
struct ManualExecutor {
  std::vector<std::function<void()>> tasks;
  Session::Scheduler scheduler() {
    return [this](std::function<void()> f) { tasks.push_back(std::move(f)); };
  }
  void runAll() {
    while (!tasks.empty()) {
      auto t = std::move(tasks.front());
      tasks.erase(tasks.begin());
      t();
    }
  }
};

struct Inbox {
  std::vector<json> messages;
  MessageSink sink() {
    return [this](std::string text, Delivery, const std::string&) { messages.push_back(json::parse(text)); };
  }
  std::vector<json> ofType(const std::string& type) const {
    std::vector<json> out;
    for (const json& m : messages)
      if (m["type"] == type) out.push_back(m);
    return out;
  }
};

struct MemoryJournal : SessionJournal {
  std::vector<std::pair<std::int64_t, json>> edits;
  std::map<std::int64_t, json> snapshots;
  void appendEdit(const std::string&, std::int64_t seq, const json& edit) override { edits.emplace_back(seq, edit); }
  void saveSnapshot(const std::string&, std::int64_t seq, const json& scene) override { snapshots[seq] = scene; }
};

proto::Scene liftedCornerScene() {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/strip-lifted-corner.json");
  json doc = json::parse(file);
  doc["model"].erase("handles");
  return proto::sceneFromJson(doc);
}

std::shared_ptr<Session> makeSession(ManualExecutor& ex, SessionJournal* journal = nullptr) {
  return std::make_shared<Session>("s1", liftedCornerScene(), Session::Tokens{sha1Hex("edit-token"), sha1Hex("view-token")},
                                   SessionSettings{}, ex.scheduler(), journal, nullptr);
}

/// A session with one joined editor whose state has arrived.
struct JoinedEditor {
  ManualExecutor ex;
  MemoryJournal journal;
  std::shared_ptr<Session> session = makeSession(ex, &journal);
  Inbox inbox;
  int pid = session->join(Role::Edit, "", inbox.sink());
  JoinedEditor() { ex.runAll(); }
  void send(const json& message) {
    session->post(pid, message);
    ex.runAll();
  }
};

json drag(int op, double z) {
  return {{"type", "drag"}, {"op", op}, {"target", {{"curve", "b"}, {"index", 6}}}, {"position", {6.0, 1.0, z}}};
}

TEST(Session, TokensGrantEditOrViewRoles) {
  ManualExecutor ex;
  auto s = makeSession(ex);
  EXPECT_EQ(s->authenticate("edit-token"), Role::Edit);
  EXPECT_EQ(s->authenticate("view-token"), Role::View);
  EXPECT_EQ(s->authenticate("edit-tokeN"), Role::None);
  EXPECT_EQ(s->authenticate(""), Role::None);
}

TEST(Session, JoinSendsTheFullStateThenPresence) {
  ManualExecutor ex;
  auto s = makeSession(ex);
  Inbox inbox;
  const int pid = s->join(Role::Edit, "ada", inbox.sink());
  ex.runAll();
  ASSERT_GE(inbox.messages.size(), 2u);
  const json& state = inbox.messages[0];
  EXPECT_EQ(state["type"], "state");
  EXPECT_EQ(state["you"], pid);
  EXPECT_EQ(state["role"], "edit");
  EXPECT_EQ(state["scene"]["model"]["kind"], "strip");
  EXPECT_TRUE(state["geometry"]["surface"].contains("vertices"));
  EXPECT_EQ(state["participants"][0]["name"], "ada");
  EXPECT_EQ(inbox.messages[1]["type"], "presence");
}

TEST(Session, DragStreamsIteratesAndDragEndSolvesToDevelopability) {
  JoinedEditor e;
  auto& [ex, journal, s, inbox, pid] = e;
  for (int k = 1; k <= 6; ++k) {
    s->post(pid, drag(k, 0.3 * k));
    ex.runAll();
  }
  s->post(pid, {{"type", "drag_end"}, {"op", 99}, {"target", {{"curve", "b"}, {"index", 6}}}});
  ex.runAll();
  const auto acks = inbox.ofType("ack");
  ASSERT_EQ(acks.size(), 7u);
  for (std::size_t i = 0; i < acks.size(); ++i) EXPECT_EQ(acks[i]["seq"], static_cast<int>(i) + 1);
  const auto iterates = inbox.ofType("iterate");
  ASSERT_GE(iterates.size(), 7u);  // one per drag, then the release iterations (may converge early)
  for (std::size_t i = 1; i < iterates.size(); ++i) EXPECT_GE(iterates[i]["seq"], iterates[i - 1]["seq"]);
  const auto solved = inbox.ofType("solved");
  ASSERT_EQ(solved.size(), 1u);
  EXPECT_LT(solved[0]["metrics"]["warp_angle_max_deg"].get<double>(), 0.05);
  EXPECT_EQ(solved[0]["seq"], 7);
  // The temporary drag handle is gone, the point stays near where it was released.
  const json scene = s->sceneJson();
  EXPECT_FALSE(scene["model"].contains("handles"));
  EXPECT_NEAR(scene["model"]["b"]["points"][6][2].get<double>(), 1.8, 0.05);
  EXPECT_EQ(journal.edits.size(), 7u);
  EXPECT_EQ(journal.edits.back().second["type"], "drag_end");
}

TEST(Session, DragsQueuedWhileBusyAreCoalescedLatestWins) {
  JoinedEditor e;
  auto& [ex, journal, s, inbox, pid] = e;
  for (int k = 1; k <= 5; ++k) s->post(pid, drag(k, 0.1 * k));  // nothing runs in between
  ex.runAll();
  const auto acks = inbox.ofType("ack");
  ASSERT_EQ(acks.size(), 5u);  // every op is acknowledged …
  for (const json& a : acks) EXPECT_EQ(a["seq"], 1);  // … by the one edit that applied the latest
  EXPECT_EQ(s->seq(), 1);
}

TEST(Session, ViewersWatchButCannotEdit) {
  ManualExecutor ex;
  auto s = makeSession(ex);
  Inbox editor, viewer;
  const int e = s->join(Role::Edit, "", editor.sink());
  const int v = s->join(Role::View, "", viewer.sink());
  ex.runAll();
  s->post(v, drag(1, 1.0));
  ex.runAll();
  ASSERT_EQ(viewer.ofType("error").size(), 1u);
  EXPECT_EQ(viewer.ofType("error")[0]["code"], "forbidden");
  EXPECT_EQ(viewer.ofType("error")[0]["op"], 1);
  s->post(e, drag(2, 1.0));
  ex.runAll();
  EXPECT_EQ(viewer.ofType("edit").size(), 1u);  // the editor's edit reaches the viewer
  EXPECT_FALSE(viewer.ofType("iterate").empty());
  EXPECT_TRUE(editor.ofType("edit").empty());  // the editor gets an ack instead
}

TEST(Session, UndoRedoAndResetRestoreScenes) {
  JoinedEditor e;
  auto& [ex, journal, s, inbox, pid] = e;
  const json initial = s->sceneJson();
  s->post(pid, {{"type", "set_fixed"}, {"op", 1}, {"target", {{"curve", "a"}, {"index", 6}}}, {"fixed", true}});
  ex.runAll();
  EXPECT_EQ(s->sceneJson()["model"]["fixed"].size(), 5u);
  s->post(pid, {{"type", "undo"}, {"op", 2}});
  ex.runAll();
  EXPECT_EQ(s->sceneJson()["model"]["fixed"].size(), 4u);
  s->post(pid, {{"type", "redo"}, {"op", 3}});
  ex.runAll();
  EXPECT_EQ(s->sceneJson()["model"]["fixed"].size(), 5u);
  s->post(pid, {{"type", "reset"}, {"op", 4}});
  ex.runAll();
  EXPECT_EQ(s->sceneJson(), initial);
  s->post(pid, {{"type", "redo"}, {"op", 5}});
  ex.runAll();
  ASSERT_EQ(inbox.ofType("error").size(), 1u);
  EXPECT_EQ(inbox.ofType("error")[0]["code"], "conflict");
}

TEST(Session, NormalRepresentationCanSwitchToASplineAndBack) {
  JoinedEditor e;
  e.send({{"type", "set_solver"}, {"op", 1}, {"solver", json::object()},
          {"normals", {{"type", "spline"}, {"degree", 3}, {"points", 6}}}});
  EXPECT_EQ(e.session->sceneJson()["model"]["normals"]["type"], "spline");
  EXPECT_EQ(e.session->sceneJson()["model"]["normals"]["points"], 6);
  e.send({{"type", "set_solver"}, {"op", 2}, {"solver", json::object()}, {"normals", {{"type", "spline"}, {"points", 1000}}}});
  ASSERT_EQ(e.inbox.ofType("error").size(), 1u);
  EXPECT_EQ(e.inbox.ofType("error")[0]["path"], "model.normals.points");
  e.send({{"type", "set_solver"}, {"op", 3}, {"solver", json::object()}, {"normals", {{"type", "vectors"}}}});
  EXPECT_EQ(e.session->sceneJson()["model"]["normals"]["type"], "vectors");
}

TEST(Session, RejectedEditsNameTheFieldAndChangeNothing) {
  JoinedEditor e;
  auto& [ex, journal, s, inbox, pid] = e;
  const json before = s->sceneJson();
  s->post(pid, {{"type", "drag"}, {"op", "x"}, {"target", {{"curve", "a"}, {"index", 70}}}, {"position", {0, 0, 0}}});
  s->post(pid, {{"type", "remove_handle"}, {"op", "y"}, {"target", {{"curve", "a"}, {"index", 2}}}});
  s->post(pid, {{"type", "set_solver"}, {"op", "z"}, {"solver", {{"linear_solver", "magic"}}}});
  ex.runAll();
  const auto errors = inbox.ofType("error");
  ASSERT_EQ(errors.size(), 3u);
  EXPECT_EQ(errors[0]["path"], "target.index");
  EXPECT_EQ(errors[1]["path"], "target");
  EXPECT_EQ(errors[2]["path"], "solver.linear_solver");
  EXPECT_EQ(s->sceneJson(), before);
  EXPECT_EQ(s->seq(), 0);
}

TEST(Session, ReplayingTheJournalRestoresTheScene) {
  JoinedEditor e;
  auto& [ex, journal, s, inbox, pid] = e;
  s->post(pid, {{"type", "add_handle"}, {"op", 1}, {"target", {{"curve", "a"}, {"index", 6}}}, {"position", {5.5, 0, 1.0}}});
  ex.runAll();
  for (int k = 1; k <= 3; ++k) {
    s->post(pid, drag(k + 1, 0.4 * k));
    ex.runAll();
  }
  s->post(pid, {{"type", "drag_end"}, {"op", 9}, {"target", {{"curve", "b"}, {"index", 6}}}});
  ex.runAll();
  ManualExecutor ex2;
  auto restored = makeSession(ex2);
  restored->replay(journal.edits, journal.edits.back().first);
  EXPECT_EQ(restored->seq(), s->seq());
  const json a = s->sceneJson(), b = restored->sceneJson();
  EXPECT_EQ(a["model"]["handles"], b["model"]["handles"]);
  for (int i = 0; i < 7; ++i)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(a["model"]["b"]["points"][i][c].get<double>(), b["model"]["b"]["points"][i][c].get<double>(), 1e-9);
}

}  // namespace
}  // namespace devsurf::server

namespace devsurf::server {
namespace {

TEST(Tokens, AreRandom128BitHexAndHashStably) {
  const std::string a = randomToken(), b = randomToken();
  EXPECT_EQ(a.size(), 32u);
  EXPECT_NE(a, b);
  EXPECT_EQ(a.find_first_not_of("0123456789abcdef"), std::string::npos);
  EXPECT_EQ(sha1Hex("abc"), "a9993e364706816aba3e25717850c26c9cd0d89d");  // FIPS 180-1 test vector
  EXPECT_TRUE(constantTimeEquals("x1", "x1"));
  EXPECT_FALSE(constantTimeEquals("x1", "x2"));
  EXPECT_FALSE(constantTimeEquals("x1", "x12"));
}

}  // namespace
}  // namespace devsurf::server
