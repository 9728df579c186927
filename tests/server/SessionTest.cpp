#include "devsurf/server/Session.h"

#include "devsurf/proto/Geometry.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/server/SceneSolver.h"
#include "devsurf/server/Tokens.h"
#include "server/SessionTesting.h"

#include <utility>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>

namespace devsurf::server {
namespace {

using nlohmann::json;
using testing::Inbox;
using testing::ManualExecutor;
using testing::MemoryJournal;

proto::Scene liftedCornerScene() {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/strip-lifted-corner.json");
  json doc = json::parse(file);
  doc["model"].erase("handles");
  return proto::sceneFromJson(doc);
}

std::shared_ptr<Session> makeSession(ManualExecutor& ex, SessionJournal* journal = nullptr) {
  return std::make_shared<Session>("s1", liftedCornerScene(), Session::Tokens{tokenHash("edit-token"), tokenHash("view-token")},
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

/// A store that fails (disk full, I/O error) on the next append or checkpoint.
struct FlakyJournal : MemoryJournal {
  bool failAppend = false, failCheckpoint = false;  ///< the next one fails
  bool failCheckpoints = false;                      ///< every one fails
  void appendEdit(const std::string& s, std::int64_t seq, const json& edit) override {
    if (std::exchange(failAppend, false)) throw std::runtime_error("disk full");
    MemoryJournal::appendEdit(s, seq, edit);
  }
  void saveCheckpoint(const std::string& s, const SessionCheckpoint& c) override {
    if (std::exchange(failCheckpoint, false) || failCheckpoints) throw std::runtime_error("disk full");
    MemoryJournal::saveCheckpoint(s, c);
  }
};

/// A session restored as the daemon restores one: built from a checkpoint's scene, told the scene
/// it was created with (the lifted corner), then restore() with the edits journalled after it.
std::shared_ptr<Session> restoredFrom(ManualExecutor& ex, const SessionCheckpoint& checkpoint,
                                      const std::vector<std::pair<std::int64_t, json>>& editsAfter,
                                      std::int64_t lastSeq) {
  auto restored = std::make_shared<Session>("s1", proto::sceneFromJson(checkpoint.scene),
                                            Session::Tokens{tokenHash("edit-token"), tokenHash("view-token")},
                                            SessionSettings{}, ex.scheduler(), nullptr, nullptr);
  restored->setInitialScene(liftedCornerScene());
  restored->restore(checkpoint.state, checkpoint.revision, editsAfter, lastSeq);
  return restored;
}

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

TEST(Session, AParticipantThatLeavesMidDragReleasesItsHandle) {
  JoinedEditor e;
  auto& [ex, journal, s, inbox, pid] = e;
  Inbox other;
  const int watcher = s->join(Role::Edit, "watcher", other.sink());
  ex.runAll();
  for (int k = 1; k <= 3; ++k) {
    s->post(pid, drag(k, 0.3 * k));
    ex.runAll();
  }
  other.messages.clear();
  s->leave(pid);  // the tab closed before drag_end
  ex.runAll();
  // The others see the release: an edit drag_end, the release solve ending in solved.
  const json edit = other.last("edit");
  ASSERT_FALSE(edit.is_null());
  EXPECT_EQ(edit["edit"]["type"], "drag_end");
  ASSERT_FALSE(other.last("solved").is_null());
  EXPECT_EQ(journal.edits.back().second["type"], "drag_end");
  EXPECT_EQ(journal.snapshots.count(s->seq()), 1u) << "the release is snapshotted";
  const json scene = s->sceneJson();
  EXPECT_FALSE(scene["model"].contains("handles"));
  // The point is free: the watcher drags another point and the first one is not pulled back.
  const double z = scene["model"]["b"]["points"][6][2].get<double>();
  s->post(watcher, {{"type", "drag"}, {"op", 1}, {"target", {{"curve", "b"}, {"index", 3}}}, {"position", {3.0, 1.0, 0.2}}});
  s->post(watcher, {{"type", "drag_end"}, {"op", 2}, {"target", {{"curve", "b"}, {"index", 3}}}});
  ex.runAll();
  EXPECT_FALSE(s->sceneJson()["model"].contains("handles"));
  EXPECT_NE(s->sceneJson()["model"]["b"]["points"][6][2].get<double>(), 0.9) << "not pulled to the old pointer";
  EXPECT_GT(std::abs(z), 0.0);
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

TEST(Session, ACompositeSwitchesToNormalSplinesAndAMouseDragStaysDevelopable) {
  testing::ExampleEditor e("composite-curved-fold");
  const double vectorUnknowns = e.session->metricsJson()["unknowns"].get<double>();
  e.send({{"type", "set_solver"}, {"op", 1}, {"solver", {{"normal_splines", true}}}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.ofType("error")[0].dump();
  EXPECT_EQ(e.session->sceneJson()["solver"]["normal_splines"], true);
  EXPECT_LT(e.session->metricsJson()["unknowns"].get<double>(), 0.75 * vectorUnknowns);
  // A drag as a mouse sends it: the free corner (vertex 2) lifted in 30 small moves, then released.
  const json start = e.session->sceneJson()["model"]["vertices"][2];
  for (int k = 1; k <= 30; ++k)
    e.send({{"type", "drag"}, {"op", 1 + k}, {"target", {{"vertex", 2}}},
            {"position", {start[0].get<double>(), start[1].get<double>(), start[2].get<double>() + 0.02 * k}}});
  e.send({{"type", "drag_end"}, {"op", 40}, {"target", {{"vertex", 2}}}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.ofType("error")[0].dump();
  const json metrics = e.session->metricsJson();
  EXPECT_LT(metrics["warp_angle_max_deg"].get<double>(), 0.05);
  EXPECT_LT(metrics["crease_fold_residual_max"].get<double>(), 1e-3);
  EXPECT_GT(e.session->sceneJson()["model"]["vertices"][2][2].get<double>(), start[2].get<double>() + 0.3);
  // A restart from the last checkpoint keeps the splines and the shape.
  ASSERT_FALSE(e.journal.checkpoints.empty());
  const SessionCheckpoint& last = e.journal.checkpoints.back();
  ManualExecutor ex2;
  auto restored = std::make_shared<Session>("r1", proto::sceneFromJson(last.scene),
                                            Session::Tokens{tokenHash("edit-token"), tokenHash("view-token")},
                                            SessionSettings{}, ex2.scheduler(), nullptr, nullptr);
  restored->restore(last.state, last.revision, {}, last.seq);
  EXPECT_EQ(restored->sceneJson()["solver"]["normal_splines"], true);
  EXPECT_EQ(restored->metricsJson()["unknowns"], e.session->metricsJson()["unknowns"]);
  EXPECT_NEAR(restored->sceneJson()["model"]["vertices"][2][2].get<double>(),
              e.session->sceneJson()["model"]["vertices"][2][2].get<double>(), 1e-12);
  // The strip sessions' "normals" does not apply; the error says what does.
  e.send({{"type", "set_solver"}, {"op", 41}, {"solver", json::object()}, {"normals", {{"type", "spline"}}}});
  ASSERT_EQ(e.inbox.ofType("error").size(), 1u);
  EXPECT_EQ(e.inbox.ofType("error")[0]["path"], "normals");
  EXPECT_NE(e.inbox.ofType("error")[0]["message"].get<std::string>().find("normal_splines"), std::string::npos);
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

TEST(Session, ARestartRestoresTheLastStateShownExactly) {
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
  // Every state shown was checkpointed first, and the release's result is the last checkpoint.
  ASSERT_FALSE(journal.checkpoints.empty());
  const SessionCheckpoint& last = journal.checkpoints.back();
  EXPECT_EQ(last.seq, s->seq());
  EXPECT_EQ(last.revision, inbox.last("solved")["revision"]);
  ManualExecutor ex2;
  auto restored = restoredFrom(ex2, last, journal.editsAfterLastCheckpoint(), journal.edits.back().first);
  EXPECT_EQ(restored->seq(), s->seq());
  EXPECT_EQ(restored->revision(), s->revision());
  EXPECT_EQ(restored->sceneJson(), s->sceneJson());  // bit for bit: the checkpoint's numbers as stored
}

TEST(Session, EveryMessageThatShowsAStateFollowsItsCheckpoint) {
  ManualExecutor ex;
  MemoryJournal journal;
  auto s = makeSession(ex, &journal);
  // Checked as each message arrives: the checkpoint of its revision is already stored.
  int shown = 0;
  std::vector<std::string> problems;
  MessageSink sink = [&journal, &shown, &problems](std::string text, Delivery, const std::string&) {
    const json m = json::parse(text);
    const std::string type = m["type"];
    if (type != "state" && type != "iterate" && type != "update" && type != "solved") return;
    ++shown;
    const std::int64_t revision = m["revision"];
    const auto it = std::find_if(journal.checkpoints.begin(), journal.checkpoints.end(),
                                 [revision](const SessionCheckpoint& c) { return c.revision == revision; });
    if (revision > 0 && it == journal.checkpoints.end()) {
      problems.push_back(type + " of revision " + std::to_string(revision) + " went out before its checkpoint");
      return;
    }
    if (revision > 0 && it->seq != m["seq"].get<std::int64_t>()) problems.push_back(type + ": seq differs from its checkpoint's");
    if (revision > 0 && m.contains("scene") && it->scene != m["scene"]) problems.push_back(type + ": scene differs");
  };
  const int pid = s->join(Role::Edit, "", sink);
  ex.runAll();
  for (int k = 1; k <= 5; ++k) {
    s->post(pid, drag(k, 0.3 * k));
    ex.runAll();
  }
  s->post(pid, {{"type", "drag_end"}, {"op", 9}, {"target", {{"curve", "b"}, {"index", 6}}}});
  s->post(pid, {{"type", "set_fixed"}, {"op", 10}, {"target", {{"curve", "a"}, {"index", 2}}}, {"fixed", true}});
  ex.runAll();
  Inbox late;  // a newcomer after unshown work: its state is a stored one too
  s->join(Role::View, "", late.sink());
  ex.runAll();
  EXPECT_TRUE(problems.empty()) << problems.front();
  EXPECT_GT(shown, 5);
  std::int64_t previous = 0;
  for (const SessionCheckpoint& c : journal.checkpoints) {
    EXPECT_GT(c.revision, previous) << "revisions grow by checkpoint";
    previous = c.revision;
  }
  EXPECT_EQ(late.last("state")["revision"], journal.checkpoints.back().revision);
}

TEST(Session, ARestartInTheMiddleOfADragRestoresTheLastIterateWithoutTheDragHandle) {
  JoinedEditor e;
  auto& [ex, journal, s, inbox, pid] = e;
  for (int k = 1; k <= 4; ++k) {
    s->post(pid, drag(k, 0.35 * k));
    ex.runAll();
  }
  // Killed here: no drag_end. The last iterate shown is the last checkpoint.
  const json lastIterate = inbox.last("iterate");
  const SessionCheckpoint& last = journal.checkpoints.back();
  ASSERT_EQ(last.revision, lastIterate["revision"]);
  ManualExecutor ex2;
  auto restored = restoredFrom(ex2, last, journal.editsAfterLastCheckpoint(), journal.edits.back().first);
  EXPECT_EQ(restored->seq(), s->seq());
  EXPECT_EQ(restored->sceneJson()["model"]["b"], last.scene["model"]["b"]);
  // The drag's temporary handle ended with its participant: a new one joins with none.
  Inbox fresh;
  restored->join(Role::Edit, "later", fresh.sink());
  ex2.runAll();
  const json state = fresh.last("state");
  for (const json& h : state["constraints"]["handles"]) EXPECT_FALSE(h["temporary"].get<bool>()) << h;
}

TEST(Session, AnEditTheJournalCannotStoreIsNeitherAcknowledgedNorShownAndTheNextOneFollowsOn) {
  ManualExecutor ex;
  FlakyJournal journal;
  auto s = makeSession(ex, &journal);
  Inbox inbox;
  const int pid = s->join(Role::Edit, "", inbox.sink());
  ex.runAll();
  const json before = s->sceneJson();
  journal.failAppend = true;
  s->post(pid, {{"type", "set_fixed"}, {"op", 1}, {"target", {{"curve", "a"}, {"index", 3}}}, {"fixed", true}});
  ex.runAll();
  EXPECT_TRUE(inbox.ofType("ack").empty());
  EXPECT_EQ(inbox.last("error")["code"], "internal");
  EXPECT_EQ(s->seq(), 0);
  EXPECT_EQ(s->sceneJson(), before);
  s->post(pid, {{"type", "set_fixed"}, {"op", 2}, {"target", {{"curve", "a"}, {"index", 4}}}, {"fixed", true}});
  ex.runAll();
  ASSERT_EQ(inbox.ofType("ack").size(), 1u);
  EXPECT_EQ(inbox.last("ack")["seq"], 1);
  ASSERT_EQ(journal.edits.size(), 1u);
  EXPECT_EQ(journal.edits[0].first, 1);
  // A checkpoint that cannot be written: the acknowledged edit stays in the model, unshown (REST
  // readers keep the last stored state) until the next checkpoint shows it with what follows.
  const json shown = s->sceneJson();
  journal.failCheckpoint = true;
  const std::size_t updates = inbox.ofType("update").size();
  s->post(pid, {{"type", "set_fixed"}, {"op", 3}, {"target", {{"curve", "a"}, {"index", 5}}}, {"fixed", true}});
  ex.runAll();
  EXPECT_EQ(inbox.ofType("update").size(), updates);
  EXPECT_EQ(inbox.last("error")["code"], "internal");
  EXPECT_EQ(s->sceneJson(), shown);
  s->post(pid, {{"type", "set_fixed"}, {"op", 4}, {"target", {{"curve", "a"}, {"index", 6}}}, {"fixed", true}});
  ex.runAll();
  ASSERT_EQ(inbox.ofType("update").size(), updates + 1);
  const json fixed = inbox.last("update")["scene"]["model"]["fixed"];
  for (int index : {4, 5, 6}) EXPECT_NE(std::find(fixed.begin(), fixed.end(), json{{"curve", "a"}, {"index", index}}), fixed.end()) << index;
  EXPECT_EQ(journal.checkpoints.back().scene, s->sceneJson());
}

TEST(Session, AfterARestartResetStillReturnsToTheSceneTheSessionWasCreatedWith) {
  JoinedEditor e;
  auto& [ex, journal, s, inbox, pid] = e;
  const json initial = s->sceneJson();
  s->post(pid, drag(1, 1.2));
  s->post(pid, {{"type", "drag_end"}, {"op", 2}, {"target", {{"curve", "b"}, {"index", 6}}}});
  ex.runAll();
  const SessionCheckpoint& last = journal.checkpoints.back();
  ManualExecutor ex2;
  auto restored = restoredFrom(ex2, last, {}, s->seq());
  Inbox in2;
  const int p2 = restored->join(Role::Edit, "", in2.sink());
  ex2.runAll();
  restored->post(p2, {{"type", "reset"}, {"op", 3}});
  ex2.runAll();
  EXPECT_EQ(restored->sceneJson()["model"]["b"], initial["model"]["b"]);
}

TEST(Session, MetricsComeBackAfterARestartAsTheyWereShown) {
  JoinedEditor e;
  auto& [ex, journal, s, inbox, pid] = e;
  s->post(pid, drag(1, 1.2));
  s->post(pid, {{"type", "drag_end"}, {"op", 2}, {"target", {{"curve", "b"}, {"index", 6}}}});
  ex.runAll();
  const SessionCheckpoint& last = journal.checkpoints.back();
  ManualExecutor ex2;
  auto restored = restoredFrom(ex2, last, {}, s->seq());
  EXPECT_EQ(restored->metricsJson(), s->metricsJson());
  EXPECT_GT(s->metricsJson().value("displacement_max_b", 0.0), 0.1) << s->metricsJson().dump();
}

TEST(Session, EditsJournalledAfterTheLastCheckpointRestoreToWhatTheSessionHad) {
  ManualExecutor ex;
  FlakyJournal journal;
  auto s = makeSession(ex, &journal);
  Inbox inbox;
  const int pid = s->join(Role::Edit, "", inbox.sink());
  ex.runAll();
  s->post(pid, drag(1, 1.0));
  s->post(pid, {{"type", "drag_end"}, {"op", 2}, {"target", {{"curve", "b"}, {"index", 6}}}});
  ex.runAll();
  const SessionCheckpoint good = journal.checkpoints.back();
  // From here the store takes edits but no checkpoint: every structural edit stays unshown.
  journal.failCheckpoints = true;
  const std::vector<json> edits = {
      {{"type", "set_fixed"}, {"op", 3}, {"target", {{"curve", "a"}, {"index", 3}}}, {"fixed", true}},
      {{"type", "add_handle"}, {"op", 4}, {"target", {{"curve", "a"}, {"index", 5}}}, {"position", {5.0, 0.0, 0.3}}},
      {{"type", "undo"}, {"op", 5}},
      {{"type", "redo"}, {"op", 6}},
      {{"type", "set_solver"}, {"op", 7}, {"solver", {{"fairness", 0.02}}}, {"drag_iterations", 5}},
      {{"type", "reset"}, {"op", 8}},
      {{"type", "undo"}, {"op", 9}}};
  for (const json& m : edits) {
    s->post(pid, m);
    ex.runAll();
  }
  ASSERT_EQ(inbox.ofType("ack").size(), 2u + edits.size());
  journal.failCheckpoints = false;
  s->post(pid, {{"type", "set_fixed"}, {"op", 10}, {"target", {{"curve", "a"}, {"index", 4}}}, {"fixed", true}});
  ex.runAll();
  const json live = s->sceneJson();  // shown at last: everything above applied
  std::vector<std::pair<std::int64_t, json>> after;
  for (const auto& edit : journal.edits)
    if (edit.first > good.seq) after.push_back(edit);
  ManualExecutor ex2;
  auto restored = restoredFrom(ex2, good, after, s->seq());
  const json back = restored->sceneJson();
  EXPECT_EQ(back["model"]["fixed"], live["model"]["fixed"]);
  EXPECT_EQ(back["model"]["handles"].size(), live["model"]["handles"].size());
  EXPECT_EQ(back["solver"], live["solver"]);
  const auto a = live["model"]["b"]["points"], b = back["model"]["b"]["points"];
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[i][c].get<double>(), b[i][c].get<double>(), 1e-12);
}

TEST(Session, AnAcknowledgedEditThatWasNotShownSurvivesALaterJournalFailure) {
  ManualExecutor ex;
  FlakyJournal journal;
  auto s = makeSession(ex, &journal);
  Inbox inbox;
  const int pid = s->join(Role::Edit, "", inbox.sink());
  ex.runAll();
  journal.failCheckpoint = true;  // seq 1 is acknowledged, its state not stored: unshown
  s->post(pid, {{"type", "set_fixed"}, {"op", 1}, {"target", {{"curve", "a"}, {"index", 3}}}, {"fixed", true}});
  ex.runAll();
  journal.failAppend = true;  // the next edit cannot be journalled: not acknowledged
  s->post(pid, {{"type", "set_fixed"}, {"op", 2}, {"target", {{"curve", "a"}, {"index", 4}}}, {"fixed", true}});
  ex.runAll();
  s->post(pid, {{"type", "set_fixed"}, {"op", 3}, {"target", {{"curve", "a"}, {"index", 5}}}, {"fixed", true}});
  ex.runAll();
  const json fixed = s->sceneJson()["model"]["fixed"];
  auto has = [&fixed](int index) { return std::find(fixed.begin(), fixed.end(), json{{"curve", "a"}, {"index", index}}) != fixed.end(); };
  EXPECT_TRUE(has(3)) << "the acknowledged, unshown edit was lost: " << fixed;
  EXPECT_FALSE(has(4)) << "an edit that was never journalled is in the state";
  EXPECT_TRUE(has(5));
  EXPECT_EQ(journal.checkpoints.back().seq, 2);
}

TEST(Session, EveryDragEndIsAnsweredBySolvedEvenWhenAnotherParticipantsWorkInterruptsIt) {
  for (const bool otherDrags : {true, false}) {
    JoinedEditor e;
    auto& [ex, journal, s, inbox, pid] = e;
    Inbox other;
    const int b = s->join(Role::Edit, "bob", other.sink());
    ex.runAll();
    s->post(pid, drag(1, 1.0));
    ex.runAll();
    // A releases while B's work is already queued: the release is interrupted at once.
    s->post(pid, {{"type", "drag_end"}, {"op", 2}, {"target", {{"curve", "b"}, {"index", 6}}}});
    if (otherDrags)
      s->post(b, {{"type", "drag"}, {"op", 3}, {"target", {{"curve", "b"}, {"index", 3}}}, {"position", {3.0, 1.0, 0.3}}});
    else
      s->post(b, {{"type", "set_fixed"}, {"op", 3}, {"target", {{"curve", "a"}, {"index", 3}}}, {"fixed", true}});
    ex.runAll();
    if (otherDrags) {
      EXPECT_TRUE(inbox.ofType("solved").empty()) << "B's drag is still on: its release answers for both";
      s->post(b, {{"type", "drag_end"}, {"op", 4}, {"target", {{"curve", "b"}, {"index", 3}}}});
      ex.runAll();
    }
    ASSERT_FALSE(inbox.ofType("solved").empty()) << (otherDrags ? "after B's drag" : "after B's edit");
    EXPECT_EQ(inbox.last("solved")["seq"], s->seq());
    EXPECT_TRUE(inbox.last("solved")["quality"]["met"].get<bool>()) << inbox.last("solved").dump();
  }
}

// ---- composite sessions ----

/// examples/composite-curved-fold.json without its handle: a flat 2 × 2 sheet split by one curved
/// crease (edge 0, S, "fold") into two strips; vertices 0, 1, 4, 5 fixed; a development.
proto::Scene curvedFoldScene() {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/composite-curved-fold.json");
  json doc = json::parse(file);
  doc["model"].erase("handles");
  return proto::sceneFromJson(doc);
}

std::shared_ptr<Session> makeCompositeSession(ManualExecutor& ex, SessionJournal* journal = nullptr) {
  return std::make_shared<Session>("c1", curvedFoldScene(), Session::Tokens{tokenHash("edit-token"), tokenHash("view-token")},
                                   SessionSettings{}, ex.scheduler(), journal, nullptr);
}

struct JoinedCompositeEditor {
  ManualExecutor ex;
  MemoryJournal journal;
  std::shared_ptr<Session> session = makeCompositeSession(ex, &journal);
  Inbox inbox;
  int pid = session->join(Role::Edit, "", inbox.sink());
  JoinedCompositeEditor() { ex.runAll(); }
  void send(const json& message) {
    session->post(pid, message);
    ex.runAll();
  }
};

json dragVertex3(int op, double z) {
  return {{"type", "drag"}, {"op", op}, {"target", {{"vertex", 3}}}, {"position", {2.0, 2.0, z}}};
}

TEST(CompositeSession, JoinSendsCompositeGeometryWithCreasesPointsAndDevelopment) {
  JoinedCompositeEditor e;
  const json& state = e.inbox.messages.at(0);
  ASSERT_EQ(state["type"], "state");
  EXPECT_EQ(state["scene"]["model"]["kind"], "composite");
  const json& g = state["geometry"];
  EXPECT_EQ(g["kind"], "composite");
  const Eigen::MatrixXd vertices = proto::decodeFloat32Array(g["surface"]["vertices"]);
  EXPECT_GT(vertices.rows(), 0);
  EXPECT_EQ(g["surface"]["quads"]["shape"][1], 4);
  EXPECT_EQ(proto::decodeFloat32Array(g["surface"]["face_flatness"]).rows(), vertices.rows());
  EXPECT_EQ(proto::decodeFloat32Array(g["surface"]["vertex_curvature"]).rows(), vertices.rows());
  ASSERT_EQ(g["edges"].size(), 7u);
  EXPECT_EQ(g["edges"][0]["crease"], "fold");
  EXPECT_TRUE(g["edges"][0]["interior"].get<bool>());
  EXPECT_TRUE(g["edges"][0].contains("fold_angle_deg"));
  EXPECT_EQ(g["edges"][0]["control_points"]["shape"][0], 6);
  EXPECT_EQ(g["edges"][1]["assignment"], "B");
  // 6 vertices, then the interior control points of the three S edges (4 each).
  EXPECT_EQ(g["points"]["refs"]["shape"][0], 6 + 3 * 4);
  ASSERT_TRUE(g["development"].is_object());
  EXPECT_GT(g["development"]["triangles"]["shape"][0].get<int>(), 0);
  EXPECT_EQ(g["development"]["assignment"].get<std::string>().size(), g["development"]["edges"]["shape"][0].get<std::size_t>());
  EXPECT_EQ(state["constraints"]["fixed"].size(), 4u);
  EXPECT_EQ(state["constraints"]["fixed"][0], (json{{"vertex", 0}}));
}

TEST(CompositeSession, DraggingAVertexStreamsIteratesAndReleaseSolvesToSmallResiduals) {
  JoinedCompositeEditor e;
  for (int k = 1; k <= 4; ++k) e.send(dragVertex3(k, 0.2 * k));
  e.send({{"type", "drag_end"}, {"op", 99}, {"target", {{"vertex", 3}}}, {"iterations", 30}});
  EXPECT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.ofType("error")[0].dump();
  EXPECT_EQ(e.inbox.ofType("ack").size(), 5u);
  const auto iterates = e.inbox.ofType("iterate");
  ASSERT_GE(iterates.size(), 5u);
  EXPECT_EQ(iterates.back()["geometry"]["kind"], "composite");
  EXPECT_TRUE(iterates.back()["residuals"].contains("crease_fold"));
  const auto solved = e.inbox.ofType("solved");
  ASSERT_EQ(solved.size(), 1u);
  EXPECT_LT(solved[0]["metrics"]["face_flatness_max"].get<double>(), 1e-3);
  EXPECT_LT(solved[0]["metrics"]["crease_fold_residual_max"].get<double>(), 1e-3);
  // The vertex followed the drag, and the temporary handle is gone from the scene.
  const json scene = e.session->sceneJson();
  EXPECT_GT(scene["model"]["vertices"][3][2].get<double>(), 0.3);
  EXPECT_FALSE(scene["model"].contains("handles"));
}

TEST(CompositeSession, JoinAndUndoShowTheVerdictOfTheStateTheyShowNotTheLastSolves) {
  // A status line kept the verdict of a solve that an undo had taken back. Each state the
  // session shows carries its own verdict, recomputed here by a solver built from the scene shown.
  const auto verdictOf = [](const json& scene) { return SceneSolver(proto::sceneFromJson(scene)).quality().toJson(); };
  const auto sameChecks = [](const json& a, const json& b) {
    if (a["checks"].size() != b["checks"].size()) return false;
    for (std::size_t k = 0; k < a["checks"].size(); ++k) {
      const double x = a["checks"][k]["value"].get<double>(), y = b["checks"][k]["value"].get<double>();
      if (a["checks"][k]["metric"] != b["checks"][k]["metric"] || std::abs(x - y) > 1e-6 * std::max({1.0, std::abs(x), std::abs(y)}))
        return false;
    }
    return true;
  };
  JoinedCompositeEditor e;
  const json joined = e.inbox.last("state");
  ASSERT_TRUE(joined.contains("quality"));
  EXPECT_TRUE(sameChecks(joined["quality"], verdictOf(joined["scene"]))) << joined["quality"].dump();
  for (int k = 1; k <= 4; ++k) e.send(dragVertex3(k, 0.25 * k));
  e.send({{"type", "drag_end"}, {"op", 99}, {"target", {{"vertex", 3}}}, {"iterations", 30}});
  const json solved = e.inbox.last("solved");
  ASSERT_TRUE(solved.is_object());
  e.send({{"type", "undo"}, {"op", 100}});
  const json update = e.inbox.last("update");
  ASSERT_TRUE(update.contains("quality"));
  EXPECT_TRUE(sameChecks(update["quality"], verdictOf(update["scene"]))) << update["quality"].dump();
  // The undo restored another state: the last solve's verdict would not have matched it.
  EXPECT_FALSE(sameChecks(solved["quality"], update["quality"]));
}

TEST(CompositeSession, TheLetGoOfARefusedDragIsAcknowledgedAndSolvesMovesAndJournalsNothing) {
  // A position typed far outside the design (the web app sends a drag there and its drag_end):
  // the drag is refused naming the position, and its let-go must not run a release.
  JoinedCompositeEditor e;
  const json before = e.session->sceneJson();
  const std::size_t edits = e.journal.edits.size();
  const json seq = e.inbox.last("state")["seq"];
  e.inbox.messages.clear();
  e.send({{"type", "drag"}, {"op", 1}, {"target", {{"vertex", 3}}}, {"position", {1e6, 2.0, 0.0}}});
  ASSERT_EQ(e.inbox.ofType("error").size(), 1u);
  EXPECT_EQ(e.inbox.last("error")["path"], "position");
  e.send({{"type", "drag_end"}, {"op", 2}, {"target", {{"vertex", 3}}}});
  ASSERT_EQ(e.inbox.ofType("ack").size(), 1u) << "the let-go is answered";
  EXPECT_EQ(e.inbox.last("ack")["op"], 2);
  EXPECT_EQ(e.inbox.last("ack")["seq"], seq) << "no edit";
  EXPECT_TRUE(e.inbox.ofType("solved").empty());
  EXPECT_TRUE(e.inbox.ofType("iterate").empty());
  EXPECT_EQ(e.journal.edits.size(), edits);
  EXPECT_EQ(e.session->sceneJson()["model"]["vertices"], before["model"]["vertices"]);
  // An accepted drag of the same vertex is released as always.
  e.send(dragVertex3(3, 0.4));
  e.send({{"type", "drag_end"}, {"op", 4}, {"target", {{"vertex", 3}}}, {"iterations", 30}});
  EXPECT_EQ(e.inbox.ofType("solved").size(), 1u);
  EXPECT_EQ(e.journal.edits.size(), edits + 2);
}

TEST(CompositeSession, ItsThumbnailIsAPngThatFollowsTheDesign) {
  JoinedCompositeEditor e;
  const ExportedFile before = e.session->thumbnail();
  EXPECT_EQ(before.mediaType, "image/png");
  EXPECT_EQ(before.content.substr(1, 3), "PNG");
  EXPECT_EQ(e.session->thumbnail().content, before.content) << "the same revision draws the same picture";
  for (int k = 1; k <= 4; ++k) e.send(dragVertex3(k, 0.2 * k));
  e.send({{"type", "drag_end"}, {"op", 99}, {"target", {{"vertex", 3}}}, {"iterations", 30}});
  ASSERT_EQ(e.inbox.ofType("solved").size(), 1u);
  EXPECT_NE(e.session->thumbnail().content, before.content) << "a new revision draws the new surface";
}

TEST(CompositeSession, ControlPointsOfSplineEdgesCanBeDraggedAndTheirEndsAreTheVertices) {
  JoinedCompositeEditor e;
  e.send({{"type", "drag"}, {"op", 1}, {"target", {{"edge", 3}, {"index", 2}}}, {"position", {2.1, 0.8, 0.3}}});
  e.send({{"type", "drag_end"}, {"op", 2}, {"target", {{"edge", 3}, {"index", 2}}}});
  EXPECT_TRUE(e.inbox.ofType("error").empty());
  EXPECT_GT(e.session->sceneJson()["model"]["edges"][3]["points"][1][2].get<double>(), 0.05);
  // {"edge": 3, "index": 0} is vertex 2 (edge 3 runs from vertex 2 to vertex 3).
  e.send({{"type", "set_fixed"}, {"op", 3}, {"target", {{"edge", 3}, {"index", 0}}}, {"fixed", true}});
  const json fixed = e.session->sceneJson()["model"]["fixed"];
  EXPECT_NE(std::find(fixed.begin(), fixed.end(), json{{"vertex", 2}}), fixed.end());
}

TEST(CompositeSession, SwitchingACreaseTypeIsAStructuralEditWithUndoAndRedo) {
  JoinedCompositeEditor e;
  e.send({{"type", "set_crease"}, {"op", 1}, {"edge", 0}, {"crease", "smooth"}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.ofType("error")[0].dump();
  EXPECT_EQ(e.session->sceneJson()["model"]["edges"][0]["crease"], "smooth");
  const auto updates = e.inbox.ofType("update");
  ASSERT_EQ(updates.size(), 1u);
  EXPECT_EQ(updates[0]["geometry"]["edges"][0]["crease"], "smooth");
  EXPECT_EQ(updates[0]["undo"]["available"], 1);
  e.send({{"type", "set_crease"}, {"op", 2}, {"edge", 0}, {"crease", "none"}});
  EXPECT_FALSE(e.session->sceneJson()["model"]["edges"][0].contains("crease"));
  e.send({{"type", "undo"}, {"op", 3}});
  EXPECT_EQ(e.session->sceneJson()["model"]["edges"][0]["crease"], "smooth");
  e.send({{"type", "undo"}, {"op", 4}});
  EXPECT_EQ(e.session->sceneJson()["model"]["edges"][0]["crease"], "fold");
  e.send({{"type", "redo"}, {"op", 5}});
  EXPECT_EQ(e.session->sceneJson()["model"]["edges"][0]["crease"], "smooth");
  // Every update carries the verdict of the state it shows (a status line kept the last solve's
  // verdict after an undo had taken that state back): the composite's checks, met when all are.
  const auto allUpdates = e.inbox.ofType("update");
  ASSERT_EQ(allUpdates.size(), 5u);
  for (const json& u : allUpdates) {
    ASSERT_TRUE(u.contains("quality")) << u.dump().substr(0, 200);
    const json& checks = u["quality"]["checks"];
    ASSERT_FALSE(checks.empty());
    bool all = true;
    for (const json& c : checks) all = all && c["ok"].get<bool>();
    EXPECT_EQ(u["quality"]["met"].get<bool>(), all);
  }
  ASSERT_EQ(e.journal.edits.size(), 5u);
  EXPECT_EQ(e.journal.edits[0].second["type"], "set_crease");
  // The journal alone (no checkpoint) restores the same scene: structural edits are applied,
  // undo and redo carry the scene they produced.
  ManualExecutor ex2;
  auto restored = makeCompositeSession(ex2);
  restored->restore(nullptr, 0, e.journal.edits, e.journal.edits.back().first);
  EXPECT_EQ(restored->sceneJson()["model"]["edges"], e.session->sceneJson()["model"]["edges"]);
}

TEST(CompositeSession, BadReferencesAndOpsOfTheOtherKindGetErrorsNamingTheField) {
  JoinedCompositeEditor e;
  const json before = e.session->sceneJson();
  const std::vector<json> messages = {
      {{"type", "drag"}, {"op", 1}, {"target", {{"vertex", 6}}}, {"position", {0, 0, 0}}},
      {{"type", "drag"}, {"op", 2}, {"target", {{"edge", 9}, {"index", 1}}}, {"position", {0, 0, 0}}},
      {{"type", "drag"}, {"op", 3}, {"target", {{"edge", 1}, {"index", 1}}}, {"position", {0, 0, 0}}},
      {{"type", "set_fixed"}, {"op", 4}, {"target", {{"edge", 0}, {"index", 6}}}, {"fixed", true}},
      {{"type", "drag"}, {"op", 5}, {"target", {{"curve", "a"}, {"index", 1}}}, {"position", {0, 0, 0}}},
      {{"type", "set_crease"}, {"op", 6}, {"edge", 7}, {"crease", "fold"}},
      {{"type", "set_crease"}, {"op", 7}, {"edge", 3}, {"crease", "smooth"}},
      {{"type", "set_solver"}, {"op", 8}, {"solver", json::object()}, {"normals", {{"type", "vectors"}}}},
      {{"type", "remove_handle"}, {"op", 9}, {"target", {{"vertex", 2}}}},
  };
  for (const json& m : messages) e.send(m);
  const auto errors = e.inbox.ofType("error");
  ASSERT_EQ(errors.size(), messages.size());
  const std::vector<std::string> paths = {"target.vertex", "target.edge", "target.edge", "target.index", "target",
                                          "edge", "edge", "normals", "target"};
  for (std::size_t i = 0; i < paths.size(); ++i) {
    EXPECT_EQ(errors[i]["path"], paths[i]) << errors[i].dump();
    EXPECT_EQ(errors[i]["op"], messages[i]["op"]);
    EXPECT_EQ(errors[i]["message"].get<std::string>().rfind(messages[i]["type"].get<std::string>() + ": ", 0), 0u)
        << "the message names the op: " << errors[i].dump();
  }
  EXPECT_EQ(e.session->sceneJson(), before);
  EXPECT_EQ(e.session->seq(), 0);
}

TEST(CompositeSession, StripSessionsRejectSetCreaseAndCompositeTargetsNamingTheOp) {
  JoinedEditor e;
  e.send({{"type", "set_crease"}, {"op", 1}, {"edge", 0}, {"crease", "fold"}});
  e.send({{"type", "drag"}, {"op", 2}, {"target", {{"vertex", 0}}}, {"position", {0, 0, 0}}});
  const auto errors = e.inbox.ofType("error");
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0]["path"], "type");
  EXPECT_NE(errors[0]["message"].get<std::string>().find("set_crease"), std::string::npos);
  EXPECT_EQ(errors[1]["path"], "target");
  EXPECT_NE(errors[1]["message"].get<std::string>().find("strip"), std::string::npos);
}

TEST(CompositeSession, ExportsObjFoldAndSvgAndRefusesFormatsThatDoNotApply) {
  JoinedCompositeEditor e;
  const ExportedFile obj = e.session->exportAs("obj");
  EXPECT_EQ(obj.mediaType, "model/obj");
  EXPECT_NE(obj.content.find("\nf "), std::string::npos);
  const ExportedFile fold = e.session->exportAs("fold");
  const json doc = json::parse(fold.content);
  EXPECT_EQ(doc["file_spec"], 1.2);
  EXPECT_FALSE(doc["edges_assignment"].empty());
  const ExportedFile svg = e.session->exportAs("svg");
  EXPECT_EQ(svg.mediaType, "image/svg+xml");
  EXPECT_NE(svg.content.find("<svg"), std::string::npos);
  EXPECT_EQ(e.session->exportAs("step").mediaType, "model/step");
  EXPECT_EQ(e.session->exportAs("dxf").mediaType, "image/vnd.dxf");
  EXPECT_THROW(e.session->exportAs("dwg"), ExportUnavailable);
  JoinedEditor strip;
  EXPECT_THROW(strip.session->exportAs("fold"), ExportUnavailable);
  EXPECT_NE(strip.session->exportAs("svg").content.find("flat pattern"), std::string::npos);
  EXPECT_NE(strip.session->exportAs("obj").content.find("\nf "), std::string::npos);
}

/// The curved-fold sheet with its development pinned to the mirror image of its corners: every
/// face of the development turns clockwise, which no crease pattern accepts.
proto::Scene mirroredDevelopmentScene() {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/composite-curved-fold.json");
  json doc = json::parse(file);
  json corners = json::array();
  for (int v : {0, 2, 3, 5}) {
    const json& p = doc["model"]["vertices"][static_cast<std::size_t>(v)];
    corners.push_back({{"vertex", v}, {"at", {-p[0].get<double>(), p[1].get<double>()}}});
  }
  doc["model"]["development"] = {{"samples", 4}, {"domain", {{"corners", corners}}}};
  return proto::sceneFromJson(doc);
}

TEST(CompositeSession, AStateWhoseCreasePatternIsInvalidExportsAsExportFailedNamingFormatAndReason) {
  ManualExecutor ex;
  auto session = std::make_shared<Session>("m1", mirroredDevelopmentScene(),
                                           Session::Tokens{tokenHash("edit-token"), tokenHash("view-token")},
                                           SessionSettings{}, ex.scheduler(), nullptr, nullptr);
  for (const std::string format : {"fold", "svg"}) {
    try {
      session->exportAs(format);
      ADD_FAILURE() << format << " exported a clockwise development";
    } catch (const ExportFailed& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind("format: " + format + ":", 0), 0u) << message;
      EXPECT_NE(message.find("counter-clockwise"), std::string::npos) << message;
    }
  }
  // The surface itself still exports.
  EXPECT_NE(session->exportAs("obj").content.find("\nf "), std::string::npos);
}

}  // namespace
}  // namespace devsurf::server
