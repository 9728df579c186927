// A drag in progress while a co-designer edits (a new user's two-browser tryout at stop 55): an
// edit that renumbers the points ends the drag — its later messages addressed another point by
// the old number — and undo, redo and reset end it too; an edit that leaves the numbers alone
// does not.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "devsurf/models/composite/CompositeDesign.h"
#include "server/SessionTesting.h"
#include "support/Presets.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
using testing::ExampleEditor;
using testing::Inbox;
namespace composite = models::composite;

composite::CompositeDesign designOf(const ExampleEditor& e) {
  return std::get<composite::CompositeDesign>(proto::sceneFromJson(e.session->sceneJson()).model);
}

/// A side of a planar flap on the boundary (an R edge of one face whose edges are all R), or -1.
int boundarySideOfAFlap(const composite::CompositeDesign& d) {
  for (const std::vector<int>& loop : d.faces) {
    const bool planar = std::all_of(loop.begin(), loop.end(), [&d](int e) {
      return d.edges[static_cast<std::size_t>(e)].type == composite::EdgeType::Ruling;
    });
    if (!planar) continue;
    for (int edge : loop) {
      int faces = 0;
      for (const std::vector<int>& other : d.faces) faces += static_cast<int>(std::count(other.begin(), other.end(), edge));
      if (faces == 1) return edge;
    }
  }
  return -1;
}

json vertexOf(const ExampleEditor& e, int v) { return e.session->sceneJson()["model"]["vertices"][static_cast<std::size_t>(v)]; }

json dragMessage(int op, int vertex, const json& position) {
  return {{"type", "drag"}, {"op", op}, {"target", {{"vertex", vertex}}}, {"position", position}};
}

json presenceOf(const Inbox& inbox, int participant) {
  const json presence = inbox.last("presence");
  for (const json& p : presence["participants"])
    if (p["id"] == participant) return p;
  return json();
}

/// Designer A's session on the curved-box preset, and designer B joined to it as an editor.
struct TwoDesigners {
  explicit TwoDesigners(const std::string& nameOfB) : a("composite-curved-box") {
    b = a.session->join(Role::Edit, nameOfB, bInbox.sink());
    a.ex.runAll();
  }
  /// B's message, handled at once.
  void fromB(const json& m) {
    a.session->post(b, m);
    a.ex.runAll();
  }
  ExampleEditor a;
  Inbox bInbox;
  int b = -1;
};

TEST(SessionInterruptedDrag, AVertexRemovedByACoDesignerEndsTheDragInsteadOfMovingTheVertexThatTookItsNumber) {
  TwoDesigners two("bea");
  ExampleEditor& a = two.a;
  const Inbox& bInbox = two.bInbox;
  auto fromB = [&two](const json& m) { two.fromB(m); };
  const int side = boundarySideOfAFlap(designOf(a));
  ASSERT_GE(side, 0);
  const int w = static_cast<int>(designOf(a).vertices.rows());
  // Three vertices on that side: w, w + 1, w + 2.
  for (int k = 0; k < 3; ++k) fromB({{"type", "split_edge"}, {"op", 10 + k}, {"edge", side}, {"at", 0.5}});
  ASSERT_TRUE(bInbox.ofType("error").empty()) << bInbox.last("error").dump();
  ASSERT_EQ(designOf(a).vertices.rows(), w + 3);

  // A grabs w + 1 and pulls it a little; B removes w, so w + 2 becomes w + 1.
  const json grabbed = vertexOf(a, w + 1);
  json pulled = grabbed;
  pulled[2] = pulled[2].get<double>() + 0.05;
  a.send(dragMessage(1, w + 1, pulled));
  ASSERT_TRUE(a.inbox.ofType("error").empty()) << a.inbox.last("error").dump();
  EXPECT_EQ(presenceOf(bInbox, a.pid)["dragging"], json({{"vertex", w + 1}}));
  fromB({{"type", "remove_vertex"}, {"op", 20}, {"vertex", w}});
  ASSERT_TRUE(bInbox.ofType("error").empty()) << bInbox.last("error").dump();
  ASSERT_EQ(designOf(a).vertices.rows(), w + 2);
  const json tookTheNumber = vertexOf(a, w + 1);  // the vertex that was w + 2

  // A's pointer moves on: one error saying what happened, then acks; nothing moves, nothing is
  // journalled, and B no longer sees A dragging.
  const std::size_t journalled = a.journal.edits.size();
  const std::size_t acksBefore = a.inbox.ofType("ack").size();
  for (int k = 0; k < 5; ++k) {
    pulled[2] = pulled[2].get<double>() + 0.05;
    a.send(dragMessage(2 + k, w + 1, pulled));
  }
  const std::vector<json> errors = a.inbox.ofType("error");
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0]["code"], "conflict");
  EXPECT_EQ(errors[0]["path"], "target");
  EXPECT_EQ(errors[0]["op"], 2);
  EXPECT_NE(errors[0]["message"].get<std::string>().find("bea's remove_vertex"), std::string::npos) << errors[0].dump();
  EXPECT_NE(errors[0]["message"].get<std::string>().find("grab the point again"), std::string::npos) << errors[0].dump();
  EXPECT_EQ(a.inbox.ofType("ack").size(), acksBefore + 4);
  EXPECT_EQ(vertexOf(a, w + 1), tookTheNumber);
  EXPECT_EQ(a.journal.edits.size(), journalled);
  EXPECT_TRUE(presenceOf(bInbox, a.pid)["dragging"].is_null());

  // The let-go is acknowledged and releases nothing (no solve); the next grab is a drag again.
  const std::size_t solvedBefore = a.inbox.ofType("solved").size();
  a.send({{"type", "drag_end"}, {"op", 8}, {"target", {{"vertex", w + 1}}}});
  EXPECT_EQ(a.inbox.ofType("solved").size(), solvedBefore);
  EXPECT_EQ(a.inbox.last("ack")["op"], 8);
  EXPECT_EQ(vertexOf(a, w + 1), tookTheNumber);
  json again = tookTheNumber;
  again[2] = again[2].get<double>() + 0.05;
  a.send(dragMessage(9, w + 1, again));
  EXPECT_EQ(a.inbox.ofType("error").size(), 1u) << a.inbox.last("error").dump();
  EXPECT_NE(vertexOf(a, w + 1), tookTheNumber);
  a.send({{"type", "drag_end"}, {"op", 10}, {"target", {{"vertex", w + 1}}}});
  EXPECT_EQ(a.inbox.ofType("solved").size(), solvedBefore + 1);
}

TEST(SessionInterruptedDrag, AnUndoByACoDesignerEndsTheDragAndASettingChangeDoesNot) {
  TwoDesigners two("");
  ExampleEditor& a = two.a;
  const Inbox& bInbox = two.bInbox;
  auto fromB = [&two](const json& m) { two.fromB(m); };
  const json start = vertexOf(a, 0);
  json pulled = start;
  pulled[2] = pulled[2].get<double>() + 0.05;
  a.send(dragMessage(1, 0, pulled));
  // A setting leaves every point its number: the drag goes on.
  fromB({{"type", "set_solver"}, {"op", 30}, {"solver", {{"fairness", 0.02}}}});
  ASSERT_TRUE(bInbox.ofType("error").empty()) << bInbox.last("error").dump();
  pulled[2] = pulled[2].get<double>() + 0.05;
  a.send(dragMessage(2, 0, pulled));
  EXPECT_TRUE(a.inbox.ofType("error").empty()) << a.inbox.last("error").dump();
  // B's undo takes back the last step; A's drag is over, and A is told by whom.
  fromB({{"type", "undo"}, {"op", 31}});
  ASSERT_TRUE(bInbox.ofType("error").empty()) << bInbox.last("error").dump();
  const json undone = vertexOf(a, 0);
  pulled[2] = pulled[2].get<double>() + 0.05;
  a.send(dragMessage(3, 0, pulled));
  ASSERT_EQ(a.inbox.ofType("error").size(), 1u);
  EXPECT_NE(a.inbox.last("error")["message"].get<std::string>().find("'s undo"), std::string::npos)
      << a.inbox.last("error").dump();
  EXPECT_EQ(vertexOf(a, 0), undone);
  // A's own reset during A's own drag says so too.
  a.send({{"type", "drag_end"}, {"op", 4}, {"target", {{"vertex", 0}}}});
  a.send(dragMessage(5, 0, pulled));
  a.send({{"type", "reset"}, {"op", 6}});
  a.send(dragMessage(7, 0, pulled));
  ASSERT_EQ(a.inbox.ofType("error").size(), 2u);
  EXPECT_NE(a.inbox.last("error")["message"].get<std::string>().find("your own reset"), std::string::npos)
      << a.inbox.last("error").dump();
}

// A vertex added on a straight side of a flat flap (split_edge) lies on a line with its
// neighbours, and so do the development's triangles there: the orientation guard of such a sliver
// (area 1.5e-10 for sides of 0.12) blew the first step of a drag up by 1e12, and the session
// answered every drag of the vertex with "the solver diverged". Every composite preset with such
// a flap, one to three vertices added on the side, each dragged along and out of its plane.
TEST(SessionInterruptedDrag, AVertexAddedOnAFlatFlapsSideFollowsADragOnEveryCompositePreset) {
  int presets = 0;
  for (const std::string& file : devsurf::testing::presetFiles()) {
    if (file.rfind("composite-", 0) != 0) continue;
    const std::string name = file.substr(0, file.size() - 5);
    const int side = boundarySideOfAFlap(
        std::get<composite::CompositeDesign>(proto::sceneFromJson(devsurf::testing::readPreset(file)).model));
    if (side < 0) continue;
    ++presets;
    for (int splits = 1; splits <= 3; ++splits) {
      for (int which = 0; which < splits; ++which) {
        for (const bool outOfPlane : {false, true}) {
          SCOPED_TRACE(name + ": " + std::to_string(splits) + " added, dragging number " + std::to_string(which) +
                       (outOfPlane ? " out of its plane" : " along x"));
          ExampleEditor e(name);
          const int w = static_cast<int>(designOf(e).vertices.rows());
          for (int k = 0; k < splits; ++k) e.send({{"type", "split_edge"}, {"op", k}, {"edge", side}, {"at", 0.5}});
          ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
          const json from = vertexOf(e, w + which);
          const double reach = 0.02 * std::max(1.0, std::abs(from[0].get<double>()) + std::abs(from[1].get<double>()));
          json to = from;
          to[outOfPlane ? 2 : 0] = to[outOfPlane ? 2 : 0].get<double>() + reach;
          for (int step = 0; step < 4; ++step) e.send(dragMessage(10 + step, w + which, to));
          e.send({{"type", "drag_end"}, {"op", 20}, {"target", {{"vertex", w + which}}}});
          ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
          const json at = vertexOf(e, w + which);
          double moved = 0.0;
          for (int c = 0; c < 3; ++c) moved += std::pow(at[c].get<double>() - from[c].get<double>(), 2);
          EXPECT_GT(std::sqrt(moved), 1e-3 * reach) << "the vertex did not move";
        }
      }
    }
  }
  EXPECT_GE(presets, 1);  // the curved box (its flaps); a preset with flat flaps joins by itself
}

}  // namespace
}  // namespace devsurf::server
