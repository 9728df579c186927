// Cutting a chain of strips across along a new ruling (issue 16 item 3, 000_… §4.1 "editing the
// labelled mesh"): on every composite preset (discovered) and at random places, the cut either
// gives a composite whose curves are the old ones point for point — checked by evaluating the old
// curves, not through the code that cut them — and whose new rulings lie on the old surface, or is
// refused naming the field.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/models/composite/CompositeRulingSplit.h"
#include "devsurf/models/composite/CompositeTopology.h"
#include "devsurf/proto/Scene.h"
#include "support/Presets.h"

namespace devsurf::models::composite {
namespace {

/// Composite presets that are not drawings, by file name, with their designs.
std::vector<std::pair<std::string, CompositeDesign>> rulingSplitPresets() {
  std::vector<std::pair<std::string, CompositeDesign>> out;
  for (const std::string& file : devsurf::testing::presetFiles()) {
    const nlohmann::json doc = devsurf::testing::readPreset(file);
    if (doc["model"].value("kind", "") != "composite" || doc["model"].contains("drawing")) continue;
    out.emplace_back(file, std::get<CompositeDesign>(proto::sceneFromJson(doc).model));
  }
  return out;
}

/// Largest distance between the old curve of edge e and the new halves: the old curve at 64
/// parameters per half against the first half (from v0 to the cut point) and the second (from the
/// cut point to v1), where the new vertex is found as the point of the old curve nearest to it.
double halvesDeviation(const spline::BSplineCurve& old, const spline::BSplineCurve& first, const spline::BSplineCurve& second) {
  // Where the cut is on the old curve: the parameter whose point is first's last control point.
  const Eigen::RowVectorXd cutPoint = first.points.bottomRows(1);
  const double a = old.knots.domainBegin(), b = old.knots.domainEnd();
  double cut = a, best = INFINITY;
  for (int k = 0; k <= 4000; ++k) {
    const double u = a + (b - a) * k / 4000.0;
    const double dist = (old.evaluate(u).transpose() - cutPoint).norm();
    if (dist < best) {
      best = dist;
      cut = u;
    }
  }
  for (int it = 0; it < 60; ++it) {  // refine by golden-free bisection on the distance
    const double h = (b - a) / 4000.0 / std::pow(2.0, it);
    for (double u : {cut - h, cut + h}) {
      if (u < a || u > b) continue;
      const double dist = (old.evaluate(u).transpose() - cutPoint).norm();
      if (dist < best) {
        best = dist;
        cut = u;
      }
    }
  }
  double worst = best;
  for (int k = 0; k <= 64; ++k) {
    const double s = k / 64.0;
    worst = std::max(worst, (old.evaluate(a + s * (cut - a)) - first.evaluate(first.knots.domainBegin() +
                                                                             s * (first.knots.domainEnd() - first.knots.domainBegin())))
                                .norm());
    worst = std::max(worst, (old.evaluate(cut + s * (b - cut)) - second.evaluate(second.knots.domainBegin() +
                                                                                s * (second.knots.domainEnd() - second.knots.domainBegin())))
                                .norm());
  }
  return worst;
}

double designSize(const CompositeDesign& d) {
  return (d.vertices.colwise().maxCoeff() - d.vertices.colwise().minCoeff()).norm();
}

TEST(CompositeRulingSplit, EveryPresetCutAcrossItsFirstStripKeepsEveryCurveAndAddsExactRulings) {
  const auto presets = rulingSplitPresets();
  ASSERT_GE(presets.size(), 5u) << "composite presets are discovered";
  for (const auto& [name, design] : presets) {
    SCOPED_TRACE(name);
    const CompositeTopology topology(design);
    int edge = -1;
    for (int f = 0; f < topology.numFaces() && edge < 0; ++f)
      if (topology.face(f).type == FaceType::Strip) edge = topology.face(f).a.edge;
    if (edge < 0) continue;
    const std::map<int, bool> chain = linkedSplineEdges(topology, edge);
    const CompositeDesign cut = splitAlongRuling(design, topology, edge, 0.5);
    const CompositeTopology after(cut);  // a composite (throws otherwise)
    const int vertices = static_cast<int>(design.vertices.rows());
    EXPECT_EQ(cut.vertices.rows(), vertices + static_cast<int>(chain.size()));
    int stripFaces = 0;
    for (int f = 0; f < topology.numFaces(); ++f) {
      const FaceInfo& info = topology.face(f);
      if (info.a.edge >= 0 && chain.count(info.a.edge)) ++stripFaces;
    }
    EXPECT_EQ(cut.faces.size(), design.faces.size() + static_cast<std::size_t>(stripFaces));
    EXPECT_EQ(cut.edges.size(), design.edges.size() + chain.size() + static_cast<std::size_t>(stripFaces));
    // The curves did not move: the first halves keep their index, the second halves are appended
    // in the chain's (ascending) order.
    const double size = designSize(design);
    int k = 0;
    for (const auto& [e, reversed] : chain) {
      const spline::BSplineCurve& old = design.edges[static_cast<std::size_t>(e)].curve;
      const CompositeEdge& first = cut.edges[static_cast<std::size_t>(e)];
      const CompositeEdge& second = cut.edges[design.edges.size() + static_cast<std::size_t>(k++)];
      EXPECT_EQ(first.v0, design.edges[static_cast<std::size_t>(e)].v0);
      EXPECT_EQ(second.v1, design.edges[static_cast<std::size_t>(e)].v1);
      EXPECT_EQ(first.v1, second.v0);
      EXPECT_LT(halvesDeviation(old, first.curve, second.curve), 1e-9 * size) << "edge " << e;
      // The halves are one smooth curve: a tangent-continuity pair, and their legs at the cut
      // point are parallel (knot insertion), so the pair holds from the start.
      const int secondIndex = static_cast<int>(design.edges.size()) + k - 1;
      const bool paired = std::any_of(cut.tangentContinuity.begin(), cut.tangentContinuity.end(), [e = e, secondIndex](const std::array<int, 2>& p) {
        return (p[0] == e && p[1] == secondIndex) || (p[0] == secondIndex && p[1] == e);
      });
      EXPECT_TRUE(paired) << "edge " << e << " and its second half " << secondIndex;
      const Eigen::Index n = first.curve.points.rows();
      const Eigen::Vector3d in = (first.curve.points.row(n - 1) - first.curve.points.row(n - 2)).transpose().normalized();
      const Eigen::Vector3d out = (second.curve.points.row(1) - second.curve.points.row(0)).transpose().normalized();
      EXPECT_GT(in.dot(out), 1.0 - 1e-9) << "edge " << e << ": the halves' legs at the cut";
    }
    // The new rulings lie on the old surface: the cut composite's faces are as flat as before
    // (a chord that left the strip would make its new faces warp), and its model builds.
    const CompositeModel before(design), split(cut);
    const CompositeQuality q0 = before.quality(), q1 = split.quality();
    std::printf("%-36s edge %d: chain of %zu curves, %d faces cut; face flatness %.2e → %.2e\n", name.c_str(), edge,
                chain.size(), stripFaces, q0.faceFlatnessMax, q1.faceFlatnessMax);
    EXPECT_LE(q1.faceFlatnessMax, q0.faceFlatnessMax + 1e-9);
  }
}

TEST(CompositeRulingSplit, RandomCutsGiveACompositeWithTheSameCurvesOrARefusalNamingTheField) {
  std::mt19937 rng(161);
  int accepted = 0, refused = 0;
  for (const auto& [name, design] : rulingSplitPresets()) {
    SCOPED_TRACE(name);
    const CompositeTopology topology(design);
    std::vector<int> splines;
    for (int e = 0; e < static_cast<int>(design.edges.size()); ++e)
      if (design.edges[static_cast<std::size_t>(e)].type == EdgeType::Spline) splines.push_back(e);
    if (splines.empty()) continue;
    for (int trial = 0; trial < 30; ++trial) {
      const int edge = splines[rng() % splines.size()];
      const double at = std::uniform_real_distribution<double>(0.02, 0.98)(rng);
      CompositeDesign cut;
      try {
        cut = splitAlongRuling(design, topology, edge, at);
      } catch (const std::invalid_argument& e) {
        ++refused;
        const std::string what = e.what();
        EXPECT_TRUE(what.rfind("edge: ", 0) == 0 || what.rfind("at: ", 0) == 0) << what;
        continue;
      }
      ++accepted;
      EXPECT_NO_THROW({ const CompositeTopology check(cut); }) << "edge " << edge << " at " << at;
      const spline::BSplineCurve& old = design.edges[static_cast<std::size_t>(edge)].curve;
      const int second = [&cut, edge]() {
        for (std::size_t e = 0; e < cut.edges.size(); ++e)
          if (cut.edges[e].type == EdgeType::Spline && cut.edges[e].v0 == cut.edges[static_cast<std::size_t>(edge)].v1 &&
              static_cast<int>(e) != edge)
            return static_cast<int>(e);
        return -1;
      }();
      ASSERT_GE(second, 0);
      EXPECT_LT(halvesDeviation(old, cut.edges[static_cast<std::size_t>(edge)].curve, cut.edges[static_cast<std::size_t>(second)].curve),
                1e-9 * designSize(design));
    }
  }
  std::printf("random cuts: %d accepted, %d refused\n", accepted, refused);
  EXPECT_GT(accepted, 100);
}

TEST(CompositeRulingSplit, ARulingEdgeAndAFractionOutsideTheEdgeAreRefusedNamingTheField) {
  const auto presets = rulingSplitPresets();
  ASSERT_FALSE(presets.empty());
  const CompositeDesign& design = presets.front().second;
  const CompositeTopology topology(design);
  int ruling = -1, spline = -1;
  for (int e = 0; e < static_cast<int>(design.edges.size()); ++e)
    (design.edges[static_cast<std::size_t>(e)].type == EdgeType::Ruling ? ruling : spline) = e;
  ASSERT_GE(ruling, 0);
  ASSERT_GE(spline, 0);
  const auto message = [&design, &topology](int edge, double at) {
    try {
      splitAlongRuling(design, topology, edge, at);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message(ruling, 0.5).rfind("edge: ", 0), 0u) << message(ruling, 0.5);
  EXPECT_EQ(message(-1, 0.5).rfind("edge: ", 0), 0u);
  EXPECT_EQ(message(spline, 0.0).rfind("at: ", 0), 0u);
  EXPECT_EQ(message(spline, 1.0).rfind("at: ", 0), 0u);
  EXPECT_EQ(message(spline, std::nan("")).rfind("at: ", 0), 0u);
  EXPECT_EQ(message(spline, 1e-12).rfind("at: ", 0), 0u) << message(spline, 1e-12);
  EXPECT_EQ(message(spline, 1.0 - 1e-12).rfind("at: ", 0), 0u) << message(spline, 1.0 - 1e-12);
}

}  // namespace
}  // namespace devsurf::models::composite
