// Sessions of the two "strip between given curves" kinds (issue 6): quasi_strip (Bo et al.) and
// conical_strip (Chu et al.). A drag moves an input curve's control point; the model is rebuilt and
// solved whole.
#include "devsurf/server/Session.h"

#include "devsurf/proto/Geometry.h"
#include "devsurf/server/Tokens.h"
#include "server/SessionTesting.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iostream>

#include "devsurf/models/quasi_strip/QuasiStripModel.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
using testing::Inbox;
using testing::ManualExecutor;
using testing::MemoryJournal;

using testing::exampleScene;

std::shared_ptr<Session> makeCurveStripSession(ManualExecutor& ex, const std::string& example, SessionJournal* journal) {
  return std::make_shared<Session>("q1", exampleScene(example), Session::Tokens{tokenHash("edit-token"), tokenHash("view-token")},
                                   SessionSettings{}, ex.scheduler(), journal, nullptr);
}

using CurveStripEditor = testing::ExampleEditor;

json point(const json& scene, const std::string& curve, int index) { return scene["model"][curve]["points"][index]; }

json dragTo(int op, const std::string& curve, int index, const json& position) {
  return {{"type", "drag"}, {"op", op}, {"target", {{"curve", curve}, {"index", index}}}, {"position", position}};
}

// ---- quasi_strip ----

TEST(QuasiStripSession, JoinSendsTheSolvedStripItsCurvesAndTheMappingBeforeAndAfter) {
  CurveStripEditor e("quasi-strip-twisted");
  const json state = e.inbox.messages.at(0);
  ASSERT_EQ(state["type"], "state");
  EXPECT_EQ(state["scene"]["model"]["kind"], "quasi_strip");
  EXPECT_LE(state["metrics"]["warp_angle_max_deg"].get<double>(), 2.0);  // solved: from > 30° at T = t
  EXPECT_EQ(state["constraints"]["fixed"], json::array());
  const json& g = state["geometry"];
  EXPECT_EQ(g["kind"], "quasi_strip");
  const Eigen::MatrixXd vertices = proto::decodeFloat32Array(g["surface"]["vertices"]);
  const Eigen::MatrixXd warp = proto::decodeFloat32Array(g["surface"]["warp_angle_deg"]);
  EXPECT_EQ(vertices.rows(), warp.rows());
  EXPECT_LE(warp.maxCoeff(), 2.5);
  EXPECT_EQ(proto::decodeFloat32Array(g["control_points"]["c1"]).rows(), 24);
  EXPECT_EQ(proto::decodeFloat32Array(g["control_points"]["c2"]).rows(), 6);
  // σ after the solve differs from the starting identity T = t; both span σ's domain.
  const Eigen::MatrixXd sigma = proto::decodeFloat32Array(g["mapping"]["sigma"]);
  const Eigen::MatrixXd initial = proto::decodeFloat32Array(g["mapping"]["initial"]);
  ASSERT_EQ(sigma.rows(), initial.rows());
  EXPECT_EQ(sigma.col(0), initial.col(0));
  EXPECT_GT((sigma.col(1) - initial.col(1)).cwiseAbs().maxCoeff(), 0.01);
  for (Eigen::Index i = 1; i < sigma.rows(); ++i) EXPECT_GE(sigma(i, 1), sigma(i - 1, 1) - 1e-6);  // monotone
  EXPECT_EQ(g["mapping"]["trim"].size(), 2u);
  EXPECT_EQ(proto::decodeFloat32Array(g["mapping"]["samples"]).rows(), 100);
}

TEST(QuasiStripSession, DraggingAControlPointOfC1MovesItAndResolvesTheWholeStrip) {
  CurveStripEditor e("quasi-strip-twisted");
  const json before = e.session->sceneJson();
  json moved = point(before, "c1", 5);
  moved[1] = moved[1].get<double>() + 0.02;
  e.send(dragTo(1, "c1", 5, moved));
  moved[1] = moved[1].get<double>() + 0.02;
  e.send(dragTo(2, "c1", 5, moved));
  e.send({{"type", "drag_end"}, {"op", 3}, {"target", {{"curve", "c1"}, {"index", 5}}}});
  EXPECT_EQ(e.inbox.ofType("ack").size(), 3u);
  EXPECT_TRUE(e.inbox.ofType("error").empty());
  const auto iterates = e.inbox.ofType("iterate");
  ASSERT_GE(iterates.size(), 2u);
  const json& it = iterates.front();
  EXPECT_EQ(it["geometry"]["kind"], "quasi_strip");
  EXPECT_TRUE(it["metrics"].contains("warp_angle_max_deg"));
  EXPECT_TRUE(it["residuals"].contains("objective"));
  const Eigen::MatrixXd c1 = proto::decodeFloat32Array(it["geometry"]["control_points"]["c1"]);
  EXPECT_NEAR(c1(5, 1), point(before, "c1", 5)[1].get<double>() + 0.02, 1e-6);
  const json solved = e.inbox.last("solved");
  ASSERT_FALSE(solved.is_null());
  EXPECT_EQ(solved["metrics"], e.session->metricsJson());
  EXPECT_NE(solved["metrics"]["warp_angle_max_deg"], e.inbox.messages.at(0)["metrics"]["warp_angle_max_deg"]);
  const json after = e.session->sceneJson();
  EXPECT_EQ(point(after, "c1", 5), moved);
  EXPECT_EQ(point(after, "c2", 0), point(before, "c2", 0));  // the other curve stays
  // One drag gesture is one undo step.
  e.send({{"type", "undo"}, {"op", 4}});
  EXPECT_EQ(point(e.session->sceneJson(), "c1", 5), point(before, "c1", 5));
}

TEST(QuasiStripSession, LargeDragsNeverGiveAStripWorseThanTheIdentityMapping) {
  // Issue 11: dragging a control point by 10–40% of the bounding-box diagonal gave 80–90° of warp.
  // Every preset, a point of each curve, three distances: the solved strip's largest warp over
  // 1000 rulings is at most that of σ(t) = t on the dragged curves.
  int fallbacks = 0, drags = 0;
  for (const std::string example : {"quasi-strip-hull", "quasi-strip-brim", "quasi-strip-twisted"}) {
    for (const std::string curve : {"c1", "c2"}) {
      for (const double fraction : {0.1, 0.25, 0.4}) {
        CurveStripEditor e(example);
        const json scene = e.session->sceneJson();
        const json& points = scene["model"][curve]["points"];
        Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
        for (const std::string c : {"c1", "c2"})
          for (const json& p : scene["model"][c]["points"]) {
            const Eigen::Vector3d x(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
            lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
          }
        const int index = static_cast<int>(points.size()) / 3;
        const Eigen::Vector3d step = fraction * (hi - lo).norm() * Eigen::Vector3d(0.3, -0.5, 0.81).normalized();
        json moved = points[index];
        for (int k = 0; k < 3; ++k) moved[k] = moved[k].get<double>() + step[k];
        SCOPED_TRACE(example + " " + curve + "[" + std::to_string(index) + "] by " + std::to_string(fraction));
        e.send(dragTo(1, curve, index, moved));
        e.send({{"type", "drag_end"}, {"op", 2}, {"target", {{"curve", curve}, {"index", index}}}});
        ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
        const json solved = e.inbox.last("solved");
        ASSERT_FALSE(solved.is_null());
        // σ(t) = t on the dragged curves: the model before it solves.
        const proto::Scene dragged = proto::sceneFromJson(e.session->sceneJson());
        const auto& q = std::get<proto::QuasiStripScene>(dragged.model);
        const models::quasi_strip::QuasiStripModel identity(q.design, q.options);
        const double start = identity.results().warpAngleMaxDegDense;
        const double result = solved["metrics"]["warp_angle_max_deg_dense"].get<double>();
        EXPECT_LE(result, start * (1 + 1e-12)) << solved["reason"];
        const bool fallback = solved["reason"] == "identity_fallback";
        EXPECT_EQ(fallback, solved["metrics"]["selected_round"] == 0) << solved.dump();
        fallbacks += fallback;
        ++drags;
        std::cout << example << " " << curve << "[" << index << "] dragged by " << fraction << " of the diagonal: σ = t "
                  << start << "°, solved " << result << "° (" << solved["reason"].get<std::string>() << ")\n";
      }
    }
  }
  std::cout << drags << " drags, " << fallbacks << " identity fallbacks\n";
}

TEST(QuasiStripSession, SetParamsRebuildsWithTheNewMappingAndIsUndoable) {
  CurveStripEditor e("quasi-strip-hull");
  const json before = e.session->sceneJson()["model"]["mapping"];
  e.send({{"type", "set_params"}, {"op", "p"}, {"params", {{"mapping", {{"coefficients", 12}}}, {"samples", 60}}}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  const json update = e.inbox.last("update");
  ASSERT_FALSE(update.is_null());
  EXPECT_EQ(update["scene"]["model"]["mapping"]["coefficients"], 12);
  EXPECT_EQ(update["scene"]["model"]["mapping"]["degree"], before["degree"]);
  EXPECT_EQ(update["scene"]["model"]["samples"], 60);
  EXPECT_EQ(proto::decodeFloat32Array(update["geometry"]["mapping"]["samples"]).rows(), 60);
  e.send({{"type", "undo"}});
  EXPECT_EQ(e.session->sceneJson()["model"]["mapping"], before);
  e.send({{"type", "redo"}});
  EXPECT_EQ(e.session->sceneJson()["model"]["mapping"]["coefficients"], 12);
  e.send({{"type", "reset"}});
  EXPECT_EQ(e.session->sceneJson()["model"]["mapping"], before);
}

TEST(QuasiStripSession, ParamsOfTheOtherKindOrOutOfRangeGetErrorsNamingTheField) {
  CurveStripEditor e("quasi-strip-hull");
  const std::int64_t seq = e.session->seq();
  e.send({{"type", "set_params"}, {"op", 1}, {"params", {{"np", 10}}}});
  json err = e.inbox.last("error");
  EXPECT_EQ(err["op"], 1);
  EXPECT_EQ(err["path"], "params.np");
  EXPECT_EQ(err["message"].get<std::string>().rfind("set_params: ", 0), 0u);
  e.send({{"type", "set_params"}, {"op", 2}, {"params", {{"mapping", {{"degree", 5}, {"coefficients", 3}}}}}});
  err = e.inbox.last("error");
  EXPECT_EQ(err["op"], 2);
  EXPECT_EQ(err["path"].get<std::string>().rfind("params.mapping", 0), 0u) << err.dump();
  EXPECT_EQ(e.session->seq(), seq);  // nothing applied
}

TEST(QuasiStripSession, OpsThatDoNotApplyAndWrongTargetsGetErrorsNamingTheOpAndField) {
  CurveStripEditor e("quasi-strip-hull");
  const json target = {{"curve", "c1"}, {"index", 1}};
  const std::vector<json> ops = {
      {{"type", "add_handle"}, {"op", "h"}, {"target", target}, {"position", {0, 0, 0}}},
      {{"type", "remove_handle"}, {"op", "r"}, {"target", target}},
      {{"type", "set_fixed"}, {"op", "f"}, {"target", target}, {"fixed", true}},
      {{"type", "set_crease"}, {"op", "c"}, {"edge", 0}, {"crease", "fold"}},
      {{"type", "set_solver"}, {"op", "s"}, {"solver", {{"iterations", 3}}}}};
  for (const json& op : ops) {
    e.send(op);
    const json err = e.inbox.last("error");
    EXPECT_EQ(err["op"], op["op"]);
    EXPECT_EQ(err["path"], "type");
    EXPECT_EQ(err["message"].get<std::string>().rfind(op["type"].get<std::string>() + ": does not apply to quasi_strip", 0), 0u)
        << err.dump();
  }
  e.send(dragTo(7, "a", 1, {0, 0, 0}));
  EXPECT_EQ(e.inbox.last("error")["path"], "target.curve");
  e.send(dragTo(8, "c2", 999, {0, 0, 0}));
  EXPECT_EQ(e.inbox.last("error")["path"], "target.index");
  e.send({{"type", "drag"}, {"op", 9}, {"target", {{"vertex", 0}}}, {"position", {0, 0, 0}}});
  EXPECT_EQ(e.inbox.last("error")["path"], "target");
  EXPECT_EQ(e.session->seq(), 0);
}

TEST(QuasiStripSession, APointThrownOutOfReachIsRefusedAndTheLastGoodStateKept) {
  CurveStripEditor e("quasi-strip-hull");
  const json before = e.session->sceneJson();
  const json metricsBefore = e.session->metricsJson();
  // A control point thrown out to 1e300 (the curve would have no finite length): refused by the
  // reach check (100× the model's size) before anything is solved.
  e.send(dragTo(1, "c1", 2, {1e300, -1e300, 1e300}));
  const json err = e.inbox.last("error");
  ASSERT_FALSE(err.is_null());
  EXPECT_EQ(err["op"], 1);
  EXPECT_EQ(err["code"], "invalid") << err.dump();
  EXPECT_EQ(err["path"], "position");
  EXPECT_EQ(err["message"].get<std::string>().rfind("drag: position is too far from the model's centre to measure", 0), 0u)
      << err.dump();
  EXPECT_TRUE(e.inbox.ofType("ack").empty());
  EXPECT_EQ(e.session->sceneJson(), before);
  EXPECT_EQ(e.session->metricsJson(), metricsBefore);
  EXPECT_EQ(e.session->seq(), 0);
  e.send(dragTo(2, "c1", 2, point(before, "c1", 2)));  // still editable
  EXPECT_EQ(e.inbox.last("ack")["op"], 2);
}

TEST(QuasiStripSession, ReplayingTheJournalRestoresDragsAndParams) {
  CurveStripEditor e("quasi-strip-hull");
  e.send(dragTo(1, "c2", 3, {4.0, 1.4, 1.9}));
  e.send({{"type", "drag_end"}, {"op", 2}, {"target", {{"curve", "c2"}, {"index", 3}}}});
  e.send({{"type", "set_params"}, {"op", 3}, {"params", {{"samples", 40}}}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  ManualExecutor ex2;
  auto restored = makeCurveStripSession(ex2, "quasi-strip-hull", nullptr);
  restored->restore(nullptr, 0, e.journal.edits, e.journal.edits.back().first);
  EXPECT_EQ(restored->seq(), e.session->seq());
  EXPECT_EQ(restored->sceneJson(), e.session->sceneJson());
  EXPECT_NEAR(restored->metricsJson()["warp_angle_max_deg"].get<double>(),
              e.session->metricsJson()["warp_angle_max_deg"].get<double>(), 1e-9);
}

// ---- conical_strip ----

TEST(ConicalStripSession, JoinSendsPatchesWithTypesProjectionPointsAndTheDevelopment) {
  CurveStripEditor e("conical-strip-hull");
  const json state = e.inbox.messages.at(0);
  ASSERT_EQ(state["type"], "state");
  const json& g = state["geometry"];
  EXPECT_EQ(g["kind"], "conical_strip");
  const int patches = state["metrics"]["patches"].get<int>();
  ASSERT_GT(patches, 0);
  EXPECT_EQ(g["patches"]["type"]["shape"][0], patches);
  EXPECT_EQ(g["patches"]["base"].get<std::string>().size(), static_cast<std::size_t>(patches));
  EXPECT_EQ(g["patches"]["projection_points"]["shape"], json({patches, 3}));
  EXPECT_EQ(g["rulings"]["shape"], json({patches + 1, 6}));
  const Eigen::MatrixXd vertices = proto::decodeFloat32Array(g["surface"]["vertices"]);
  EXPECT_EQ(proto::decodeFloat32Array(g["surface"]["normal_jump_deg"]).rows(), vertices.rows());
  EXPECT_EQ(g["surface"]["quad_patch"]["shape"][0], g["surface"]["quads"]["shape"][0]);
  const Eigen::MatrixXd flat = proto::decodeFloat32Array(g["development"]["vertices"]);
  EXPECT_GT(flat.rows(), 0);
  EXPECT_EQ(flat.cols(), 2);
  const int n3 = state["metrics"]["n3"].get<int>(), n4 = state["metrics"]["n4"].get<int>();
  const Eigen::MatrixXd type = proto::decodeFloat32Array(g["surface"]["patch_type"]);
  EXPECT_EQ((type.array() == 4.0).count(), 2 * 9 * n4);  // 9 rungs × 2 vertices per patch
  EXPECT_EQ((type.array() == 3.0).count(), 2 * 9 * n3);
}

TEST(ConicalStripSession, DraggingAPointOfPAndSettingParamsRebuildTheStrip) {
  CurveStripEditor e("conical-strip-hull");
  const json before = e.session->sceneJson();
  json p3 = point(before, "p", 3);
  p3[2] = p3[2].get<double>() + 0.1;
  e.send(dragTo(1, "p", 3, p3));
  e.send({{"type", "drag_end"}, {"op", 2}, {"target", {{"curve", "p"}, {"index", 3}}}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  EXPECT_EQ(point(e.session->sceneJson(), "p", 3), p3);
  const json it = e.inbox.last("iterate");
  EXPECT_EQ(it["geometry"]["kind"], "conical_strip");
  EXPECT_TRUE(it["residuals"].contains("normal_variation"));
  EXPECT_FALSE(e.inbox.last("solved").is_null());
  e.send({{"type", "set_params"}, {"op", 3}, {"params", {{"np", 20}, {"nq", 22}, {"g1", false}}}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  const json update = e.inbox.last("update");
  EXPECT_EQ(update["scene"]["model"]["np"], 20);
  EXPECT_EQ(update["scene"]["model"]["g1"], false);
  EXPECT_EQ(update["geometry"]["samples"]["p"]["shape"][0], 20);
  e.send({{"type", "set_params"}, {"op", 4}, {"params", {{"mapping", {{"degree", 2}}}}}});
  EXPECT_EQ(e.inbox.last("error")["path"], "params.mapping");
  e.send({{"type", "set_params"}, {"op", 5}, {"params", {{"h3", -1.0}}}});
  EXPECT_EQ(e.inbox.last("error")["path"], "params.h3");
}

TEST(StripSession, SetParamsIsRejectedNamingTheOp) {
  ManualExecutor ex;
  auto s = std::make_shared<Session>("s", exampleScene("strip-twisted"), Session::Tokens{tokenHash("e"), tokenHash("v")},
                                     SessionSettings{}, ex.scheduler(), nullptr, nullptr);
  Inbox inbox;
  const int pid = s->join(Role::Edit, "", inbox.sink());
  ex.runAll();
  s->post(pid, {{"type", "set_params"}, {"op", 1}, {"params", {{"np", 3}}}});
  s->post(pid, dragTo(2, "c1", 0, {0, 0, 0}));
  ex.runAll();
  const auto errors = inbox.ofType("error");
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0]["path"], "type");
  EXPECT_EQ(errors[0]["message"].get<std::string>().rfind("set_params: applies to quasi_strip and conical_strip", 0), 0u);
  EXPECT_EQ(errors[1]["path"], "target.curve");
}

}  // namespace
}  // namespace devsurf::server
