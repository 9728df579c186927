// Adding and removing control points of a composite's S edges (issue 16, item 3): the knot goes into
// every S edge sharing the spline space, insertion leaves the curves where they were, removal
// approximates them and solves; undo restores; bad input names its field.

#include <gtest/gtest.h>

#include <cmath>

#include "devsurf/models/composite/CompositeDesign.h"
#include "server/SessionTesting.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
using testing::ExampleEditor;
namespace composite = models::composite;

const composite::CompositeDesign& designOf(const proto::Scene& s) { return std::get<composite::CompositeDesign>(s.model); }

/// The largest distance between two curves sampled at the same 101 parameters.
double curveGap(const spline::BSplineCurve& a, const spline::BSplineCurve& b) {
  double gap = 0.0;
  for (int k = 0; k <= 100; ++k) {
    const double u = a.knots.domainBegin() + (a.knots.domainEnd() - a.knots.domainBegin()) * k / 100.0;
    gap = std::max(gap, (a.evaluate(u) - b.evaluate(u)).norm());
  }
  return gap;
}

int firstSplineEdge(const composite::CompositeDesign& d) {
  for (std::size_t e = 0; e < d.edges.size(); ++e)
    if (d.edges[e].type == composite::EdgeType::Spline) return static_cast<int>(e);
  return -1;
}

TEST(SessionControlPoints, AnAddedControlPointGoesIntoEveryLinkedEdgeAndNoCurveMoves) {
  ExampleEditor e("composite-two-creases");
  const proto::Scene before = proto::sceneFromJson(e.session->sceneJson());
  const composite::CompositeDesign& d0 = designOf(before);
  const int edge = firstSplineEdge(d0);
  ASSERT_GE(edge, 0);
  const int n0 = static_cast<int>(d0.edges[static_cast<std::size_t>(edge)].curve.points.rows());
  e.send({{"type", "add_control_point"}, {"op", 1}, {"edge", edge}, {"index", n0 / 2}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  const proto::Scene after = proto::sceneFromJson(e.session->sceneJson());
  const composite::CompositeDesign& d1 = designOf(after);
  int grown = 0;
  for (std::size_t k = 0; k < d0.edges.size(); ++k) {
    if (d0.edges[k].type != composite::EdgeType::Spline) continue;
    const int before_n = static_cast<int>(d0.edges[k].curve.points.rows());
    const int after_n = static_cast<int>(d1.edges[k].curve.points.rows());
    EXPECT_TRUE(after_n == before_n || after_n == before_n + 1) << "edge " << k;
    grown += after_n == before_n + 1;
    EXPECT_LT(curveGap(d0.edges[k].curve, d1.edges[k].curve), 1e-9) << "edge " << k << " moved";  // Boehm: exact
  }
  EXPECT_EQ(static_cast<int>(d1.edges[static_cast<std::size_t>(edge)].curve.points.rows()), n0 + 1);
  EXPECT_GE(grown, 2);  // the edge and the other curve of its strip
  // Undo: the scene as it was.
  e.send({{"type", "undo"}, {"op", 2}});
  EXPECT_EQ(e.session->sceneJson()["model"]["edges"], proto::sceneToJson(before)["model"]["edges"]);
}

TEST(SessionControlPoints, ARemovedControlPointLeavesLinkedEdgesOneShorterCloseToWhereTheyWere) {
  ExampleEditor e("composite-two-creases");
  const proto::Scene before = proto::sceneFromJson(e.session->sceneJson());
  const composite::CompositeDesign& d0 = designOf(before);
  const int edge = firstSplineEdge(d0);
  const int n0 = static_cast<int>(d0.edges[static_cast<std::size_t>(edge)].curve.points.rows());
  ASSERT_GT(n0, 4);
  e.send({{"type", "remove_control_point"}, {"op", 1}, {"edge", edge}, {"index", n0 / 2}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  ASSERT_FALSE(e.inbox.ofType("solved").empty());  // removal solves
  const proto::Scene after = proto::sceneFromJson(e.session->sceneJson());
  const composite::CompositeDesign& d1 = designOf(after);
  EXPECT_EQ(static_cast<int>(d1.edges[static_cast<std::size_t>(edge)].curve.points.rows()), n0 - 1);
  const double size = (d0.vertices.colwise().maxCoeff() - d0.vertices.colwise().minCoeff()).norm();
  EXPECT_LT(curveGap(d0.edges[static_cast<std::size_t>(edge)].curve, d1.edges[static_cast<std::size_t>(edge)].curve), 0.05 * size);
  const json metrics = e.inbox.last("solved")["metrics"];
  EXPECT_LT(metrics["crease_fold_residual_max"].get<double>(), 1e-3) << metrics.dump();
}

TEST(SessionControlPoints, RulingsOutOfRangeIndicesAndMinimalEdgesAreRefusedNamingTheField) {
  ExampleEditor e("composite-two-creases");
  const json before = e.session->sceneJson();
  const composite::CompositeDesign d = designOf(proto::sceneFromJson(before));
  int ruling = -1;
  for (std::size_t k = 0; k < d.edges.size(); ++k)
    if (d.edges[k].type == composite::EdgeType::Ruling) ruling = static_cast<int>(k);
  const int edge = firstSplineEdge(d);
  const int n = static_cast<int>(d.edges[static_cast<std::size_t>(edge)].curve.points.rows());
  struct Case {
    json message;
    std::string path;
  };
  const std::vector<Case> cases = {
      {{{"type", "add_control_point"}, {"op", 1}, {"edge", ruling}, {"index", 0}}, "edge"},
      {{{"type", "add_control_point"}, {"op", 2}, {"edge", 9999}, {"index", 0}}, "edge"},
      {{{"type", "add_control_point"}, {"op", 3}, {"edge", edge}, {"index", n - 1}}, "index"},
      {{{"type", "remove_control_point"}, {"op", 4}, {"edge", edge}, {"index", 0}}, "index"},
      {{{"type", "remove_control_point"}, {"op", 5}, {"edge", edge}, {"index", n - 1}}, "index"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.message.dump());
    e.inbox.messages.clear();
    e.send(c.message);
    ASSERT_TRUE(e.inbox.last("error").is_object());
    EXPECT_EQ(e.inbox.last("error")["path"], c.path) << e.inbox.last("error").dump();
    EXPECT_TRUE(e.session->sceneJson() == before);
  }
  // Down to the fewest control points a cubic can have, then refused.
  int op = 10;
  for (int k = n; k > 4; --k) e.send({{"type", "remove_control_point"}, {"op", op++}, {"edge", edge}, {"index", 1}});
  e.inbox.messages.clear();
  e.send({{"type", "remove_control_point"}, {"op", op++}, {"edge", edge}, {"index", 1}});
  EXPECT_EQ(e.inbox.last("error").value("path", ""), "index") << e.inbox.last("error").dump();
}

}  // namespace
}  // namespace devsurf::server
