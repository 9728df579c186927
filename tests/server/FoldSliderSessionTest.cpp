// The fold slider in a session (issue 16, item 2): "fold" messages stream iterates like a drag,
// "fold_end" settles, the first fold of a design takes its fold angles as 100 %, undo and the
// journal keep it.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "devsurf/server/CreasePatternImport.h"
#include "server/SessionTesting.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
using testing::ExampleEditor;
using testing::Inbox;
using testing::ManualExecutor;

json foldMessage(int op, double amount) { return {{"type", "fold"}, {"op", op}, {"amount", amount}}; }

std::string firstErrorOf(const Inbox& inbox) {
  const auto errors = inbox.ofType("error");
  return errors.empty() ? std::string() : errors[0].dump();
}

/// A FOLD file imported as `devsurf import` does.
proto::Scene importedFoldScene(const std::string& foldText) {
  CreasePatternImportRequest request;
  request.format = "fold";
  return importCreasePattern(foldText, request).scene;
}

std::string foldExampleFile(const std::string& file) {
  std::ifstream in(std::string(DEVSURF_SOURCE_DIR) + "/tests/data/fold/" + file);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(FoldSliderSession, ACurvedCreasePresetUnfoldsAlongTheSliderAndUndoGoesBackToItsDesign) {
  ExampleEditor e("composite-two-creases");
  e.send({{"type", "solve"}, {"op", 1}, {"iterations", 40}});  // the preset's handles fold it
  const json designed = e.session->sceneJson();
  ASSERT_FALSE(designed["model"].contains("fold_angles"));
  const std::size_t iteratesBefore = e.inbox.ofType("iterate").size();
  int op = 10;
  for (double amount = 0.95; amount > 0.39; amount -= 0.05) e.send(foldMessage(op++, amount));  // a slider dragged down
  e.send({{"type", "fold_end"}, {"op", op++}, {"iterations", 60}});
  ASSERT_EQ(firstErrorOf(e.inbox), "");
  EXPECT_GT(e.inbox.ofType("iterate").size(), iteratesBefore + 5);  // streamed like a drag
  const json scene = e.session->sceneJson();
  ASSERT_TRUE(scene["model"].contains("fold_angles"));
  EXPECT_NEAR(scene["model"]["fold_amount"].get<double>(), 0.4, 1e-9);
  const json metrics = e.inbox.last("solved")["metrics"];
  EXPECT_NEAR(metrics["fold_amount"].get<double>(), 0.4, 1e-9);
  double designedMax = 0.0;
  for (const json& t : scene["model"]["fold_angles"]) designedMax = std::max(designedMax, std::abs(t["angle"].get<double>()));
  EXPECT_LT(metrics["fold_angle_error_max_deg"].get<double>(), 0.05 * designedMax + 1.0);
  EXPECT_LT(metrics["crease_fold_residual_max"].get<double>(), 1e-3);
  EXPECT_LT(metrics["development_length_error"].get<double>(), 1e-3);
  // One gesture, one undo step (the capture of the targets included): back to the designed state.
  e.send({{"type", "undo"}, {"op", op++}});
  const json undone = e.session->sceneJson();
  EXPECT_FALSE(undone["model"].contains("fold_angles"));
  EXPECT_EQ(undone["model"]["vertices"], designed["model"]["vertices"]);
}

TEST(FoldSliderSession, TheFirstFoldSendsTheSceneWithoutTheHandlesItLetGoOfAndTheUndoStep) {
  ExampleEditor e("composite-two-creases");
  e.send({{"type", "solve"}, {"op", 1}, {"iterations", 40}});
  ASSERT_FALSE(e.session->sceneJson()["model"]["handles"].empty());
  const std::size_t updatesBefore = e.inbox.ofType("update").size();
  e.send(foldMessage(2, 0.8));
  ASSERT_EQ(firstErrorOf(e.inbox), "");
  const auto updates = e.inbox.ofType("update");
  ASSERT_EQ(updates.size(), updatesBefore + 1) << "the clients learn the design's new scene";
  const json update = updates.back();
  EXPECT_TRUE(!update["scene"]["model"].contains("handles") || update["scene"]["model"]["handles"].empty())
      << "the fold targets took over from the handles: a client must not keep drawing them";
  EXPECT_TRUE(update["scene"]["model"].contains("fold_angles"));
  EXPECT_GE(update["undo"]["available"].get<int>(), 2) << "the solve and the fold";
  // The next fold of the gesture is no new capture: no further update.
  e.send(foldMessage(3, 0.7));
  EXPECT_EQ(e.inbox.ofType("update").size(), updatesBefore + 1);
  e.send({{"type", "fold_end"}, {"op", 4}});
  e.send({{"type", "undo"}, {"op", 5}});
  EXPECT_FALSE(e.session->sceneJson()["model"]["handles"].empty()) << "undo brings the handles back";
}

TEST(FoldSliderSession, LettingGoOfTheSliderAfterARefusedFoldSolvesNothingAndLeavesNoUndoStep) {
  // The preset as shipped, unsolved: flat, its handles not yet pulled, nothing to fold.
  ExampleEditor e("composite-curved-fold");
  const json before = e.session->sceneJson();
  const std::size_t solvedBefore = e.inbox.ofType("solved").size();
  const std::size_t iteratesBefore = e.inbox.ofType("iterate").size();
  e.send(foldMessage(1, 0.5));
  ASSERT_TRUE(e.inbox.last("error").is_object());
  EXPECT_EQ(e.inbox.last("error")["path"], "amount");
  e.send({{"type", "fold_end"}, {"op", 2}});
  EXPECT_EQ(e.inbox.ofType("solved").size(), solvedBefore) << "a fold_end without a fold is no release";
  EXPECT_EQ(e.inbox.ofType("iterate").size(), iteratesBefore);
  EXPECT_EQ(e.session->sceneJson()["model"]["vertices"], before["model"]["vertices"]);
  e.send({{"type", "undo"}, {"op", 3}});
  EXPECT_EQ(e.session->sceneJson()["model"]["vertices"], before["model"]["vertices"]);
}

TEST(FoldSliderSession, AnImportedCreasePatternFoldsToItsFileAnglesAndTheJournalReplaysIt) {
  ExampleEditor e(importedFoldScene(foldExampleFile("diagonal-cp.fold")));
  ASSERT_EQ(e.session->sceneJson()["model"]["fold_amount"], 0.0);  // flat, with the file's 180° valley
  e.send(foldMessage(1, 0.25));
  e.send(foldMessage(2, 0.5));
  e.send({{"type", "fold_end"}, {"op", 3}});
  ASSERT_EQ(firstErrorOf(e.inbox), "");
  const json scene = e.session->sceneJson();
  double zMax = 0.0;
  for (const json& v : scene["model"]["vertices"]) zMax = std::max(zMax, v[2].get<double>());
  EXPECT_GT(zMax, 100.0);  // a 200 mm sheet, a valley at 90°: the free corner rises by ~141 mm
  const json metrics = e.inbox.last("solved")["metrics"];
  EXPECT_LT(metrics["fold_angle_error_max_deg"].get<double>(), 0.5);
  // A restart replays the journalled fold messages (no checkpoint): the same amount.
  ManualExecutor ex2;
  auto restored = std::make_shared<Session>("f1", importedFoldScene(foldExampleFile("diagonal-cp.fold")),
                                            Session::Tokens{tokenHash("edit-token"), tokenHash("view-token")}, SessionSettings{},
                                            ex2.scheduler(), nullptr, nullptr);
  restored->restore(nullptr, 0, e.journal.edits, e.journal.edits.back().first);
  EXPECT_EQ(restored->sceneJson()["model"]["fold_amount"], 0.5);
}

TEST(FoldSliderSession, ADesignWithNothingToFoldAStripAndAViewerGetErrorsNamingTheField) {
  ExampleEditor flat(importedFoldScene(R"({"vertices_coords": [[0,0],[1,0],[1,1],[0,1]], "faces_vertices": [[0,1,2],[0,2,3]],
                              "edges_vertices": [[0,1],[1,2],[2,3],[3,0],[0,2]], "edges_assignment": ["B","B","B","B","U"]})"));
  flat.send(foldMessage(1, 0.5));
  const json error = flat.inbox.last("error");
  ASSERT_TRUE(error.is_object());
  EXPECT_EQ(error["path"], "amount");
  EXPECT_NE(error["message"].get<std::string>().find("nothing to fold"), std::string::npos);

  ExampleEditor strip("strip-cylinder");
  strip.send(foldMessage(1, 0.5));
  ASSERT_TRUE(strip.inbox.last("error").is_object());
  EXPECT_EQ(strip.inbox.last("error")["path"], "type");

  ExampleEditor composite("composite-two-creases");
  Inbox viewer;
  const int view = composite.session->join(Role::View, "", viewer.sink());
  composite.ex.runAll();
  composite.session->post(view, foldMessage(1, 0.5));
  composite.ex.runAll();
  ASSERT_TRUE(viewer.last("error").is_object());
  EXPECT_EQ(viewer.last("error")["code"], "forbidden");
}

}  // namespace
}  // namespace devsurf::server
