// Editing a composite's labelled mesh (issue 16 item 3, 000_… §4.1): edges relabelled R ↔ S, a
// face split by a new ruling between two corners, two faces merged across their edge. Checked on
// shipped presets: what the composite's checks accept is solved, undone exactly, journalled and
// replayed; what they refuse changes nothing and says why; random edits in any order never leave
// a session the model rejects.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include "devsurf/metrics/QuadFlatness.h"
#include "devsurf/models/composite/CompositeDesign.h"
#include "devsurf/models/composite/CompositeTopology.h"
#include "devsurf/server/SceneSolver.h"
#include "server/SessionTesting.h"
#include "support/Presets.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
using testing::ExampleEditor;
namespace composite = models::composite;

composite::CompositeDesign labelledDesignOf(const ExampleEditor& e) {
  return std::get<composite::CompositeDesign>(proto::sceneFromJson(e.session->sceneJson()).model);
}

std::vector<int> edgesLabelled(const composite::CompositeDesign& d, composite::EdgeType t) {
  std::vector<int> out;
  for (std::size_t k = 0; k < d.edges.size(); ++k)
    if (d.edges[k].type == t) out.push_back(static_cast<int>(k));
  return out;
}

/// The first face whose edges are all rulings, or −1.
/// The creases of a FOLD export, read from the file: the distinct edges_devsurf:curve ids of its
/// mountain and valley edges (a curved crease is one id however many facets it runs along).
std::size_t foldFileCurvedCreases(const json& scene) {
  const json fold = json::parse(SceneSolver::exportScene(scene, "fold").content);
  std::set<int> curves;
  for (std::size_t e = 0; e < fold["edges_vertices"].size(); ++e) {
    const std::string letter = fold["edges_assignment"][e];
    const json& curve = fold["edges_devsurf:curve"][e];
    if ((letter == "M" || letter == "V") && curve.is_number_integer()) curves.insert(curve.get<int>());
  }
  return curves.size();
}

int firstPlanarFace(const composite::CompositeDesign& d) {
  for (std::size_t f = 0; f < d.faces.size(); ++f)
    if (std::all_of(d.faces[f].begin(), d.faces[f].end(),
                    [&d](int e) { return d.edges[static_cast<std::size_t>(e)].type == composite::EdgeType::Ruling; }))
      return static_cast<int>(f);
  return -1;
}

/// Corner k of a face: where its loop edges k − 1 and k meet.
int cornerOf(const composite::CompositeDesign& d, int face, int k) {
  const std::vector<int>& loop = d.faces[static_cast<std::size_t>(face)];
  const int n = static_cast<int>(loop.size());
  const composite::CompositeEdge& a = d.edges[static_cast<std::size_t>(loop[static_cast<std::size_t>((k + n - 1) % n)])];
  const composite::CompositeEdge& b = d.edges[static_cast<std::size_t>(loop[static_cast<std::size_t>(k)])];
  return a.v0 == b.v0 || a.v0 == b.v1 ? a.v0 : a.v1;
}

/// Two scenes' composites have the same labelled mesh (faces; edges' vertices, labels, creases)
/// and vertices within 1e-9 (an undo brings back the scene, which may be written with the
/// development it had and numbers rounded differently).
::testing::AssertionResult sameLabelledMesh(const json& a, const json& b) {
  const json& ma = a["model"];
  const json& mb = b["model"];
  if (ma["faces"] != mb["faces"]) return ::testing::AssertionFailure() << "faces differ";
  if (ma["edges"].size() != mb["edges"].size()) return ::testing::AssertionFailure() << "edge counts differ";
  for (std::size_t k = 0; k < ma["edges"].size(); ++k)
    for (const char* key : {"v", "type", "crease"})
      if (ma["edges"][k].value(key, json()) != mb["edges"][k].value(key, json()))
        return ::testing::AssertionFailure() << "edge " << k << " differs in " << key;
  if (ma["vertices"].size() != mb["vertices"].size()) return ::testing::AssertionFailure() << "vertex counts differ";
  for (std::size_t v = 0; v < ma["vertices"].size(); ++v)
    for (std::size_t c = 0; c < 3; ++c)
      if (std::abs(ma["vertices"][v][c].get<double>() - mb["vertices"][v][c].get<double>()) > 1e-9)
        return ::testing::AssertionFailure() << "vertex " << v << " moved";
  return ::testing::AssertionSuccess();
}

TEST(SessionLabelledMesh, EverySplineEdgeMadeARulingGivesPlanarFacesFoldedAlongStraightCreases) {
  ExampleEditor e("composite-curved-fold");
  const json before = e.session->sceneJson();
  const composite::CompositeDesign d0 = labelledDesignOf(e);
  const std::vector<int> splines = edgesLabelled(d0, composite::EdgeType::Spline);
  ASSERT_GE(splines.size(), 3u);
  e.send({{"type", "relabel_edge"}, {"op", 1}, {"edges", splines}, {"label", "R"}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  ASSERT_FALSE(e.inbox.ofType("solved").empty());  // relabelling solves
  const composite::CompositeDesign d1 = labelledDesignOf(e);
  EXPECT_TRUE(edgesLabelled(d1, composite::EdgeType::Spline).empty());
  // Every face planar now: the solve flattened them (δ of every face's corners, independent of the
  // model's own metric).
  for (std::size_t f = 0; f < d1.faces.size(); ++f) {
    ASSERT_EQ(d1.faces[f].size(), 4u);
    Eigen::Vector3d c[4];
    for (int k = 0; k < 4; ++k) c[k] = d1.vertices.row(cornerOf(d1, static_cast<int>(f), k)).transpose();
    EXPECT_LT(metrics::quadFlatness(c[0], c[1], c[2], c[3], 1e-12), 1e-3) << "face " << f;
  }
  // Undo: the curved fold as it was.
  e.send({{"type", "undo"}, {"op", 2}});
  EXPECT_TRUE(sameLabelledMesh(e.session->sceneJson(), before));
}

TEST(SessionLabelledMesh, TwoOppositeSidesOfAPlanarFaceMadeSplinesMakeAStripThatDoesNotMove) {
  ExampleEditor e("composite-curved-box");
  e.send({{"type", "solve"}, {"op", 0}});  // the box folded up by its handles first
  const composite::CompositeDesign d0 = labelledDesignOf(e);
  const int f = firstPlanarFace(d0);
  ASSERT_GE(f, 0);
  ASSERT_EQ(d0.faces[static_cast<std::size_t>(f)].size(), 4u);
  const std::vector<int>& loop = d0.faces[static_cast<std::size_t>(f)];
  // One side alone makes S R R R: refused, quoting the face, nothing changed.
  const json before = e.session->sceneJson();
  e.send({{"type", "relabel_edge"}, {"op", 1}, {"edges", {loop[0]}}, {"label", "S"}});
  const json refusal = e.inbox.last("error");
  ASSERT_TRUE(refusal.is_object());
  EXPECT_EQ(refusal["path"], "edges");
  EXPECT_NE(refusal["message"].get<std::string>().find("faces["), std::string::npos) << refusal.dump();
  EXPECT_EQ(e.session->sceneJson(), before);
  // Two opposite sides: S R S R, the curves straight along the old sides.
  e.inbox.messages.clear();
  e.send({{"type", "relabel_edge"}, {"op", 2}, {"edges", {loop[0], loop[2]}}, {"label", "S"}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  const composite::CompositeDesign d1 = labelledDesignOf(e);
  for (int side : {loop[0], loop[2]}) {
    const composite::CompositeEdge& s = d1.edges[static_cast<std::size_t>(side)];
    ASSERT_EQ(s.type, composite::EdgeType::Spline);
    const Eigen::Vector3d a = d1.vertices.row(s.v0).transpose(), b = d1.vertices.row(s.v1).transpose();
    for (Eigen::Index k = 0; k < s.curve.points.rows(); ++k) {
      const Eigen::Vector3d p = s.curve.points.row(k).transpose();
      EXPECT_LT((p - a).cross(b - a).norm() / (b - a).norm(), 1e-6 * (b - a).norm()) << "edge " << side << " control point " << k;
    }
  }
  const double size = (d0.vertices.colwise().maxCoeff() - d0.vertices.colwise().minCoeff()).norm();
  EXPECT_LT((d1.vertices - d0.vertices).cwiseAbs().maxCoeff(), 1e-3 * size) << "the box stays where it was";
}

TEST(SessionLabelledMesh, ASplitFaceMergedAgainIsTheFaceItWasAndBothAreJournalled) {
  ExampleEditor e("composite-curved-box");
  e.send({{"type", "solve"}, {"op", 0}});  // the box folded up by its handles first
  const std::size_t journalled = e.journal.edits.size();
  const json before = e.session->sceneJson();
  const composite::CompositeDesign d0 = labelledDesignOf(e);
  const int f = firstPlanarFace(d0);
  ASSERT_GE(f, 0);
  const int a = cornerOf(d0, f, 0), b = cornerOf(d0, f, 2);
  e.send({{"type", "split_face"}, {"op", 1}, {"face", f}, {"vertices", {a, b}}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  const composite::CompositeDesign d1 = labelledDesignOf(e);
  ASSERT_EQ(d1.faces.size(), d0.faces.size() + 1);
  ASSERT_EQ(d1.edges.size(), d0.edges.size() + 1);
  const composite::CompositeEdge& added = d1.edges.back();
  EXPECT_EQ(added.type, composite::EdgeType::Ruling);
  EXPECT_TRUE((added.v0 == a && added.v1 == b) || (added.v0 == b && added.v1 == a));
  EXPECT_EQ(d1.faces[static_cast<std::size_t>(f)].size(), 3u);
  EXPECT_EQ(d1.faces.back().size(), 3u);
  // Merged across the new edge: the same faces, edges and points as before.
  e.send({{"type", "merge_faces"}, {"op", 2}, {"edge", static_cast<int>(d1.edges.size()) - 1}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  const composite::CompositeDesign d2 = labelledDesignOf(e);
  ASSERT_EQ(d2.faces.size(), d0.faces.size());
  EXPECT_EQ(d2.edges.size(), d0.edges.size());
  std::vector<int> was = d0.faces[static_cast<std::size_t>(f)], is = d2.faces[static_cast<std::size_t>(f)];
  std::sort(was.begin(), was.end());
  std::sort(is.begin(), is.end());
  EXPECT_EQ(is, was);
  // The journal holds both; a restart replays them onto the preset.
  EXPECT_EQ(e.journal.edits.size(), journalled + 2);
  testing::ManualExecutor ex2;
  auto restored = std::make_shared<Session>("e1", testing::exampleScene("composite-curved-box"),
                                            Session::Tokens{tokenHash("edit-token"), tokenHash("view-token")},
                                            SessionSettings{}, ex2.scheduler(), nullptr, nullptr);
  restored->restore(nullptr, 0, e.journal.edits, e.journal.edits.back().first);
  EXPECT_EQ(restored->sceneJson()["model"]["faces"], e.session->sceneJson()["model"]["faces"]);
  // Two undos: the design before the split.
  e.send({{"type", "undo"}, {"op", 3}});
  e.send({{"type", "undo"}, {"op", 4}});
  EXPECT_TRUE(sameLabelledMesh(e.session->sceneJson(), before));
}

TEST(SessionLabelledMesh, AStripCutAcrossAlongANewRulingBecomesTwoStripsThatDoNotMoveAndTheCutUndoes) {
  // The two-crease sheet: three strips side by side between its curves; cut across at a third of
  // the first curve, every strip of the chain is cut (the curves are linked through the strips).
  ExampleEditor e("composite-two-creases");
  const std::size_t journalled = e.journal.edits.size();
  const json before = e.session->sceneJson();
  const composite::CompositeDesign d0 = labelledDesignOf(e);
  const std::vector<int> curves = edgesLabelled(d0, composite::EdgeType::Spline);
  ASSERT_FALSE(curves.empty());
  e.inbox.messages.clear();
  e.send({{"type", "split_along_ruling"}, {"op", 1}, {"edge", curves[0]}, {"at", 1.0 / 3.0}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  const composite::CompositeDesign d1 = labelledDesignOf(e);
  const int cutCurves = static_cast<int>(d1.vertices.rows() - d0.vertices.rows());
  EXPECT_EQ(cutCurves, static_cast<int>(curves.size())) << "every curve of the chain is cut";
  EXPECT_EQ(d1.faces.size(), d0.faces.size() + static_cast<std::size_t>(cutCurves - 1));
  // Nothing moved: every old vertex where it was, every cut point on its old curve.
  for (Eigen::Index v = 0; v < d0.vertices.rows(); ++v)
    EXPECT_LT((d1.vertices.row(v) - d0.vertices.row(v)).norm(), 1e-9) << "vertex " << v;
  for (int e0 : curves) {
    const Eigen::RowVector3d cutPoint = d1.edges[static_cast<std::size_t>(e0)].curve.points.bottomRows(1);
    const spline::BSplineCurve& old = d0.edges[static_cast<std::size_t>(e0)].curve;
    double nearest = INFINITY;
    for (int k = 0; k <= 3000; ++k)
      nearest = std::min(nearest, (old.evaluate(old.knots.domainBegin() + (old.knots.domainEnd() - old.knots.domainBegin()) * k / 3000.0).transpose() -
                                   cutPoint).norm());
    EXPECT_LT(nearest, 0.05) << "the cut point of edge " << e0 << " lies on the old curve";
  }
  // The new rulings are straight R edges without a crease, and the geometry message has them.
  for (std::size_t k = d1.edges.size() - static_cast<std::size_t>(cutCurves - 1); k < d1.edges.size(); ++k) {
    EXPECT_EQ(d1.edges[k].type, composite::EdgeType::Ruling);
    EXPECT_EQ(d1.edges[k].crease, composite::CreaseKind::None);
  }
  EXPECT_EQ(e.journal.edits.size(), journalled + 1);
  // A restart replays the journal onto the preset: the same cut.
  testing::ManualExecutor ex2;
  auto restored = std::make_shared<Session>("e1", testing::exampleScene("composite-two-creases"),
                                            Session::Tokens{tokenHash("edit-token"), tokenHash("view-token")},
                                            SessionSettings{}, ex2.scheduler(), nullptr, nullptr);
  restored->restore(nullptr, 0, e.journal.edits, e.journal.edits.back().first);
  EXPECT_TRUE(sameLabelledMesh(restored->sceneJson(), e.session->sceneJson()));
  // The cut design solves like any composite (the preset's handles fold the sheet up): as
  // developable, and its old vertices end where the uncut sheet's do (the new rulings are
  // rulings the strips had).
  e.send({{"type", "solve"}, {"op", 10}});
  const json solved = e.inbox.last("solved");
  ASSERT_TRUE(solved.is_object());
  EXPECT_LT(solved["metrics"]["face_flatness_max"].get<double>(), 1e-3);
  const composite::CompositeDesign d2 = labelledDesignOf(e);
  ExampleEditor whole("composite-two-creases");
  whole.send({{"type", "solve"}, {"op", 1}});
  const composite::CompositeDesign w = labelledDesignOf(whole);
  double apart = 0.0;
  for (Eigen::Index v = 0; v < w.vertices.rows(); ++v) apart = std::max(apart, (d2.vertices.row(v) - w.vertices.row(v)).norm());
  std::printf("solved cut and uncut sheets: vertices %.3g apart (sheet 3 × 2), δ_max %.2g\n", apart,
              solved["metrics"]["face_flatness_max"].get<double>());
  EXPECT_LT(apart, 0.05 * 3.0);
  // Each cut curve is still one smooth curve after the solve (its halves meet with one tangent),
  // and the FOLD export writes as many curved creases as the uncut sheet's.
  for (int e0 : curves) {
    const auto& first = d2.edges[static_cast<std::size_t>(e0)].curve.points;
    int second = -1;
    for (std::size_t k = 0; k < d2.edges.size(); ++k)
      if (static_cast<int>(k) != e0 && d2.edges[k].type == composite::EdgeType::Spline && d2.edges[k].v0 == d2.edges[static_cast<std::size_t>(e0)].v1)
        second = static_cast<int>(k);
    ASSERT_GE(second, 0) << "the second half of edge " << e0;
    const auto& next = d2.edges[static_cast<std::size_t>(second)].curve.points;
    const Eigen::Vector3d in = (first.row(first.rows() - 1) - first.row(first.rows() - 2)).transpose().normalized();
    const Eigen::Vector3d out = (next.row(1) - next.row(0)).transpose().normalized();
    EXPECT_GT(in.dot(out), std::cos(1e-3)) << "edge " << e0 << " and " << second << " meet at " << std::acos(std::min(1.0, in.dot(out))) << " rad";
  }
  EXPECT_EQ(foldFileCurvedCreases(e.session->sceneJson()), foldFileCurvedCreases(whole.session->sceneJson()));
  EXPECT_GT(foldFileCurvedCreases(whole.session->sceneJson()), 0u);
  e.send({{"type", "undo"}, {"op", 11}});
  // A ruling cannot be cut across, nor a fraction outside (0, 1): refused naming the field.
  const std::vector<int> rulings = edgesLabelled(d1, composite::EdgeType::Ruling);
  const json cut = e.session->sceneJson();
  e.send({{"type", "split_along_ruling"}, {"op", 2}, {"edge", rulings[0]}});
  EXPECT_EQ(e.inbox.last("error").value("path", ""), "edge");
  e.send({{"type", "split_along_ruling"}, {"op", 3}, {"edge", curves[0]}, {"at", 1.5}});
  EXPECT_EQ(e.inbox.last("error").value("path", ""), "at");
  EXPECT_EQ(e.session->sceneJson(), cut);
  e.send({{"type", "undo"}, {"op", 4}});
  EXPECT_TRUE(sameLabelledMesh(e.session->sceneJson(), before));
}

TEST(SessionLabelledMesh, AVertexAddedOnAFlapsSideSplitsTheFlapFromThereAndRemovedAgainLeavesTheDesignAsItWas) {
  ExampleEditor e("composite-curved-box");
  const json before = e.session->sceneJson();
  const composite::CompositeDesign d0 = labelledDesignOf(e);
  const int flap = firstPlanarFace(d0);
  ASSERT_GE(flap, 0);
  // A side of the flap on the boundary (one face): a vertex at a quarter of it.
  int side = -1;
  for (int edge : d0.faces[static_cast<std::size_t>(flap)]) {
    int faces = 0;
    for (const std::vector<int>& loop : d0.faces) faces += static_cast<int>(std::count(loop.begin(), loop.end(), edge));
    if (faces == 1) side = edge;
  }
  ASSERT_GE(side, 0);
  const composite::CompositeEdge& was = d0.edges[static_cast<std::size_t>(side)];
  e.send({{"type", "split_edge"}, {"op", 1}, {"edge", side}, {"at", 0.25}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  const composite::CompositeDesign d1 = labelledDesignOf(e);
  const int w = static_cast<int>(d0.vertices.rows());
  ASSERT_EQ(d1.vertices.rows(), w + 1);
  const Eigen::RowVector3d expected = 0.75 * d0.vertices.row(was.v0) + 0.25 * d0.vertices.row(was.v1);
  EXPECT_LT((d1.vertices.row(w) - expected).norm(), 1e-9);
  EXPECT_EQ(d1.faces[static_cast<std::size_t>(flap)].size(), d0.faces[static_cast<std::size_t>(flap)].size() + 1);
  // The flap split from the new vertex to the corner across it.
  const std::vector<int>& loop = d1.faces[static_cast<std::size_t>(flap)];
  const int n = static_cast<int>(loop.size());
  int k = 0;
  while (cornerOf(d1, flap, k) != w) ++k;
  e.send({{"type", "split_face"}, {"op", 2}, {"face", flap}, {"vertices", {w, cornerOf(d1, flap, (k + n / 2) % n)}}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  EXPECT_EQ(labelledDesignOf(e).faces.size(), d0.faces.size() + 1);
  e.send({{"type", "undo"}, {"op", 3}});
  // Removed again: the labelled mesh as it was (the vertex and the edge gone, indices as before;
  // the solve that follows moves the points as the preset's handles pull them).
  e.send({{"type", "remove_vertex"}, {"op", 4}, {"vertex", w}});
  ASSERT_TRUE(e.inbox.ofType("error").empty()) << e.inbox.last("error").dump();
  const json again = e.session->sceneJson();
  EXPECT_EQ(again["model"]["faces"], before["model"]["faces"]);
  EXPECT_EQ(again["model"]["vertices"].size(), before["model"]["vertices"].size());
  for (std::size_t k = 0; k < before["model"]["edges"].size(); ++k)
    for (const char* key : {"v", "type", "crease"})
      EXPECT_EQ(again["model"]["edges"][k].value(key, json()), before["model"]["edges"][k].value(key, json())) << "edge " << k << " " << key;
  // A vertex where three edges meet, a curve's end and a fixed vertex stay, naming the field.
  const composite::CompositeDesign d2 = labelledDesignOf(e);
  std::vector<int> degree(static_cast<std::size_t>(d2.vertices.rows()), 0);
  for (const composite::CompositeEdge& edge : d2.edges) ++degree[static_cast<std::size_t>(edge.v0)], ++degree[static_cast<std::size_t>(edge.v1)];
  const int busy = static_cast<int>(std::max_element(degree.begin(), degree.end()) - degree.begin());
  ASSERT_GT(degree[static_cast<std::size_t>(busy)], 2);
  const json kept = e.session->sceneJson();
  e.send({{"type", "remove_vertex"}, {"op", 5}, {"vertex", busy}});
  EXPECT_EQ(e.inbox.last("error").value("path", ""), "vertex");
  e.send({{"type", "split_edge"}, {"op", 6}, {"edge", edgesLabelled(d2, composite::EdgeType::Spline)[0]}});
  EXPECT_EQ(e.inbox.last("error").value("path", ""), "edge");
  EXPECT_NE(e.inbox.last("error").value("message", "").find("Cut across"), std::string::npos);
  EXPECT_EQ(e.session->sceneJson(), kept);
}

TEST(SessionLabelledMesh, BadEditsNameTheirFieldAndChangeNothing) {
  ExampleEditor e("composite-curved-box");
  const json before = e.session->sceneJson();
  const composite::CompositeDesign d = labelledDesignOf(e);
  const int f = firstPlanarFace(d);
  const int a = cornerOf(d, f, 0), next = cornerOf(d, f, 1);
  int boundary = -1, strip = -1;
  for (std::size_t k = 0; k < d.edges.size() && boundary < 0; ++k) {
    int uses = 0;
    for (const auto& face : d.faces) uses += static_cast<int>(std::count(face.begin(), face.end(), static_cast<int>(k)));
    if (uses == 1) boundary = static_cast<int>(k);
  }
  for (std::size_t g = 0; g < d.faces.size() && strip < 0; ++g)
    if (static_cast<int>(g) != f) strip = static_cast<int>(g);
  const int notOnFace = cornerOf(d, strip, 0) != a && cornerOf(d, strip, 0) != next ? cornerOf(d, strip, 0) : cornerOf(d, strip, 1);
  struct Case {
    json message;
    std::string path;
  };
  const std::vector<Case> cases = {
      {{{"type", "relabel_edge"}, {"op", 1}, {"edges", {9999}}, {"label", "S"}}, "edges[0]"},
      {{{"type", "relabel_edge"}, {"op", 2}, {"edges", {d.faces[static_cast<std::size_t>(f)][0]}}, {"label", "R"}}, "edges[0]"},
      {{{"type", "split_face"}, {"op", 3}, {"face", 9999}, {"vertices", {a, next}}}, "face"},
      {{{"type", "split_face"}, {"op", 4}, {"face", f}, {"vertices", {a, next}}}, "vertices"},
      {{{"type", "split_face"}, {"op", 5}, {"face", f}, {"vertices", {a, a}}}, "vertices"},
      {{{"type", "merge_faces"}, {"op", 6}, {"edge", boundary}}, "edge"},
      {{{"type", "merge_faces"}, {"op", 7}, {"edge", 9999}}, "edge"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.message.dump());
    e.inbox.messages.clear();
    e.send(c.message);
    ASSERT_TRUE(e.inbox.last("error").is_object());
    EXPECT_EQ(e.inbox.last("error")["path"], c.path) << e.inbox.last("error").dump();
    EXPECT_EQ(e.session->sceneJson(), before);
  }
  if (cornerOf(d, f, 0) != notOnFace) {
    e.inbox.messages.clear();
    e.send({{"type", "split_face"}, {"op", 8}, {"face", f}, {"vertices", {a, notOnFace}}});
    const json err = e.inbox.last("error");
    EXPECT_TRUE(err.is_object());
    EXPECT_EQ(e.session->sceneJson(), before);
  }
  // Another kind of session, and a composite drawn on a sheet, refuse by type.
  ExampleEditor strip_("strip-twisted");
  strip_.send({{"type", "merge_faces"}, {"op", 1}, {"edge", 0}});
  EXPECT_EQ(strip_.inbox.last("error").value("path", ""), "type");
}

/// The composite presets in examples/ that are not drawings (a drawing's faces follow its creases:
/// it refuses labelled-mesh edits), discovered: "composite-curved-box", ….
std::vector<std::string> labelledMeshPresets() {
  std::vector<std::string> out;
  for (const std::string& file : devsurf::testing::presetFiles()) {
    const json model = devsurf::testing::readPreset(file)["model"];
    if (model.value("kind", "") == "composite" && !model.contains("drawing")) out.push_back(file.substr(0, file.size() - 5));
  }
  return out;
}

/// Random edits in any order on every composite preset: each is accepted (the session's
/// composite then passes the model's checks when read back, and undo restores the scene before it
/// exactly) or refused with the scene unchanged. Seeded, 24 edits a preset (about a third accepted).
TEST(SessionLabelledMesh, RandomEditsInAnyOrderLeaveAValidCompositeOrChangeNothing) {
  std::mt19937 rng(16);
  int accepted = 0, refused = 0;
  const std::vector<std::string> presets = labelledMeshPresets();
  ASSERT_GE(presets.size(), 3u) << "the composite presets are discovered";
  for (const std::string& preset : presets) {
    SCOPED_TRACE(preset);
    const int acceptedBefore = accepted, refusedBefore = refused;
    // What is checked is validity, not convergence: the solves after an edit get 300 ms, not 2 s.
    SessionSettings quick;
    quick.releaseTimeBudgetMs = 300.0;
    ExampleEditor e(preset, quick);
    for (int step = 0; step < 24; ++step) {
      const composite::CompositeDesign d = labelledDesignOf(e);
      const int kind = static_cast<int>(rng() % 6);
      json m{{"op", step}};
      // Every other edit is one a designer would make (a strip's two curves made rulings or a
      // planar face's opposite sides made curves, a face split between two corners that are not
      // neighbours, two faces joined across an interior edge); the rest are picked blindly.
      const bool plausible = step % 2 == 0;
      if (plausible) {
        const int f = static_cast<int>(rng() % d.faces.size());
        const std::vector<int>& loop = d.faces[static_cast<std::size_t>(f)];
        const int n = static_cast<int>(loop.size());
        const int k = static_cast<int>(rng() % static_cast<unsigned>(n));
        const std::vector<int> curves = edgesLabelled(d, composite::EdgeType::Spline);
        const std::vector<int> rulingEdges = edgesLabelled(d, composite::EdgeType::Ruling);
        if (kind == 4 && !rulingEdges.empty()) {
          m.update({{"type", "split_edge"}, {"edge", rulingEdges[rng() % rulingEdges.size()]},
                    {"at", std::uniform_real_distribution<double>(0.1, 0.9)(rng)}});
        } else if (kind == 5) {
          m.update({{"type", "remove_vertex"}, {"vertex", static_cast<int>(rng() % static_cast<unsigned>(d.vertices.rows()))}});
        } else if (kind == 3 && !curves.empty()) {
          m.update({{"type", "split_along_ruling"}, {"edge", curves[rng() % curves.size()]},
                    {"at", std::uniform_real_distribution<double>(0.05, 0.95)(rng)}});
        } else if (kind == 0 && n == 4) {
          const composite::CompositeEdge& edge = d.edges[static_cast<std::size_t>(loop[static_cast<std::size_t>(k)])];
          const bool toRuling = edge.type == composite::EdgeType::Spline;
          m.update({{"type", "relabel_edge"},
                    {"edges", {loop[static_cast<std::size_t>(k)], loop[static_cast<std::size_t>((k + 2) % 4)]}},
                    {"label", toRuling ? "R" : "S"}});
        } else if (kind == 1 && n >= 4) {
          m.update({{"type", "split_face"}, {"face", f}, {"vertices", {cornerOf(d, f, k), cornerOf(d, f, (k + 2) % n)}}});
        } else {
          std::vector<int> interior;
          std::vector<int> faceCount(d.edges.size(), 0);
          for (const std::vector<int>& l : d.faces)
            for (int e : l) ++faceCount[static_cast<std::size_t>(e)];
          for (std::size_t e = 0; e < d.edges.size(); ++e)
            if (faceCount[e] == 2) interior.push_back(static_cast<int>(e));
          if (interior.empty()) continue;
          m.update({{"type", "merge_faces"}, {"edge", interior[rng() % interior.size()]}});
        }
      } else if (kind == 0) {
        std::vector<int> edges;
        const composite::EdgeType to = rng() % 2 ? composite::EdgeType::Spline : composite::EdgeType::Ruling;
        const std::vector<int> candidates = edgesLabelled(d, to == composite::EdgeType::Spline ? composite::EdgeType::Ruling : composite::EdgeType::Spline);
        if (candidates.empty()) continue;
        const int count = 1 + static_cast<int>(rng() % std::min<std::size_t>(3, candidates.size()));
        for (int k = 0; k < count; ++k) {
          const int pick = candidates[rng() % candidates.size()];
          if (std::find(edges.begin(), edges.end(), pick) == edges.end()) edges.push_back(pick);
        }
        m.update({{"type", "relabel_edge"}, {"edges", edges}, {"label", to == composite::EdgeType::Spline ? "S" : "R"}});
      } else if (kind == 1) {
        const int f = static_cast<int>(rng() % d.faces.size());
        const int n = static_cast<int>(d.faces[static_cast<std::size_t>(f)].size());
        m.update({{"type", "split_face"}, {"face", f},
                  {"vertices", {cornerOf(d, f, static_cast<int>(rng() % n)), cornerOf(d, f, static_cast<int>(rng() % n))}}});
      } else if (kind == 4) {
        m.update({{"type", "split_edge"}, {"edge", static_cast<int>(rng() % d.edges.size())},
                  {"at", std::uniform_real_distribution<double>(0.0, 1.0)(rng)}});
      } else if (kind == 5) {
        m.update({{"type", "remove_vertex"}, {"vertex", static_cast<int>(rng() % static_cast<unsigned>(d.vertices.rows() + 1))}});
      } else if (kind == 3) {
        m.update({{"type", "split_along_ruling"}, {"edge", static_cast<int>(rng() % d.edges.size())},
                  {"at", std::uniform_real_distribution<double>(0.0, 1.0)(rng)}});
      } else {
        m.update({{"type", "merge_faces"}, {"edge", static_cast<int>(rng() % d.edges.size())}});
      }
      const json before = e.session->sceneJson();
      e.inbox.messages.clear();
      e.send(m);
      if (e.inbox.last("error").is_object()) {
        ++refused;
        EXPECT_NE(e.inbox.last("error").value("code", ""), "internal") << m.dump() << " → " << e.inbox.last("error").dump();
        EXPECT_EQ(e.session->sceneJson(), before) << m.dump();
        continue;
      }
      ++accepted;
      const json after = e.session->sceneJson();
      const composite::CompositeDesign readBack = std::get<composite::CompositeDesign>(proto::sceneFromJson(after).model);
      EXPECT_NO_THROW({ composite::CompositeTopology topology(readBack); }) << m.dump();
      json metrics;
      for (const json& msg : e.inbox.messages)
        if (msg.contains("metrics")) metrics = msg["metrics"];
      ASSERT_TRUE(metrics.is_object()) << "no metrics after " << m.dump();
      for (const auto& [name, value] : metrics.items())
        if (value.is_number()) {
          EXPECT_TRUE(std::isfinite(value.get<double>())) << name << " after " << m.dump();
        }
      e.send({{"type", "undo"}, {"op", 1000 + step}});
      EXPECT_TRUE(sameLabelledMesh(e.session->sceneJson(), before)) << "undo of " << m.dump();
      e.send({{"type", "redo"}, {"op", 2000 + step}});
    }
    std::printf("%s: %d accepted, %d refused\n", preset.c_str(), accepted - acceptedBefore, refused - refusedBefore);
    EXPECT_GT(accepted - acceptedBefore, 0) << preset << ": no edit was accepted";
  }
  std::printf("labelled-mesh edits: %d accepted, %d refused\n", accepted, refused);
  EXPECT_GT(accepted, 10);
  EXPECT_GT(refused, 10);
}

}  // namespace
}  // namespace devsurf::server
