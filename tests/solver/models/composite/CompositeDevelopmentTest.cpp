// Development management of composite scenes: the sampled mesh, its unfolded development, the
// isometry solve on the Fig. 8 preset and the crease pattern exports (FOLD, SVG).

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "CompositeFixtures.h"
#include "devsurf/io/FoldWriter.h"
#include "devsurf/io/SvgFoldPattern.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/proto/Scene.h"

namespace devsurf::models::composite {
namespace {

std::string readExample(const std::string& name) {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + name);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

struct Solved {
  std::unique_ptr<CompositeModel> model;
  std::string name;
};

Solved solvedPreset() {
  const proto::Scene scene = proto::sceneFromText(readExample("composite-curved-fold.json"));
  Solved s;
  s.name = scene.name;
  s.model = std::make_unique<CompositeModel>(std::get<CompositeDesign>(scene.model), scene.solver.compositeOptions());
  s.model->solve(scene.solver.solverOptions());
  return s;
}

TEST(CompositeDevelopment, OffByDefault) {
  CompositeModel model(fixtures::flatSheet());
  EXPECT_FALSE(model.hasDevelopment());
  EXPECT_EQ(model.developmentLengthError(), 0.0);
  EXPECT_THROW(model.development(), std::logic_error);
  EXPECT_THROW(model.creasePattern(), std::logic_error);
}

TEST(CompositeDevelopment, SampledMeshSharesEdgeSamples) {
  CompositeDesign d = fixtures::flatSheet();
  d.developmentSamples = 4;
  CompositeModel model(d);
  ASSERT_TRUE(model.hasDevelopment());
  const CompositeDevelopment dev = model.development();
  // 6 vertices + 3 S edges with (2 spans... ) interior samples each; two strips of U×2 grids.
  int expected = 6;
  for (int e : {0, 3, 6}) expected += d.edges[e].curve.knots.numSpans() * 4 - 1;
  EXPECT_EQ(dev.vertices3d.rows(), expected);
  const int U = d.edges[0].curve.knots.numSpans() * 4 + 1;
  EXPECT_EQ(static_cast<int>(dev.polygons.size()), 2 * (U - 1));
  // Every pair once.
  std::map<std::pair<int, int>, int> count;
  for (const auto& p : dev.pairs) ++count[std::minmax(p.v0, p.v1)];
  for (const auto& [k, c] : count) EXPECT_EQ(c, 1);
  // Samples are linear in the control points: they lie on the curves.
  const Eigen::MatrixXd crease = d.edges[0].curve.evaluate(d.edges[0].curve.knots.uniformSamples(U), 0);
  for (int i = 0; i < U; ++i) {
    double best = 1e9;
    for (Eigen::Index k = 0; k < dev.vertices3d.rows(); ++k)
      best = std::min(best, (dev.vertices3d.row(k) - crease.row(i)).norm());
    EXPECT_LT(best, 1e-12);
  }
}

TEST(CompositeDevelopment, UnfoldedFlatCompositeIsRigidMotionOfIt) {
  for (CompositeDesign d : {fixtures::flatSheet(), fixtures::foldedCylinders(35.0)}) {
    d.developmentSamples = 5;
    CompositeModel model(d);
    const CompositeDevelopment dev = model.development();
    const Eigen::MatrixX2d unfolded = model.unfoldedDevelopment();
    EXPECT_LT((unfolded - dev.vertices2d).cwiseAbs().maxCoeff(), 1e-12);
    double err = 0.0;
    for (const auto& p : dev.pairs) {
      const double l3 = (dev.vertices3d.row(p.v0) - dev.vertices3d.row(p.v1)).norm();
      const double l2 = (dev.vertices2d.row(p.v0) - dev.vertices2d.row(p.v1)).norm();
      err = std::max(err, std::abs(l3 - l2));
    }
    // The flat sheet is exact; the folded cylinders' quads are planar too (cylinders).
    EXPECT_LT(err, 1e-12);
    EXPECT_LT(model.developmentLengthError(), 1e-12);
    // Anchors: vertex anchor0 at the origin, anchor1 on the x axis; faces counterclockwise.
    EXPECT_LT(dev.vertices2d.row(dev.anchor0).norm(), 1e-15);
    EXPECT_LT(std::abs(dev.vertices2d(dev.anchor1, 1)), 1e-15);
    for (const std::vector<int>& poly : dev.polygons) {
      double area = 0.0;
      for (std::size_t i = 0; i < poly.size(); ++i) {
        const Eigen::RowVector2d p = dev.vertices2d.row(poly[i]), q = dev.vertices2d.row(poly[(i + 1) % poly.size()]);
        area += p.x() * q.y() - p.y() * q.x();
      }
      EXPECT_GT(area, 0.0);
    }
  }
  // Flat sheet: the development is the sheet itself up to a rigid motion (all pairwise distances).
  CompositeDesign d = fixtures::flatSheet();
  d.developmentSamples = 3;
  CompositeModel model(d);
  const CompositeDevelopment dev = model.development();
  double worst = 0.0;
  for (Eigen::Index i = 0; i < dev.vertices2d.rows(); ++i)
    for (Eigen::Index j = i + 1; j < dev.vertices2d.rows(); ++j)
      worst = std::max(worst, std::abs((dev.vertices3d.row(i) - dev.vertices3d.row(j)).norm() -
                                       (dev.vertices2d.row(i) - dev.vertices2d.row(j)).norm()));
  EXPECT_LT(worst, 1e-12);
}

TEST(CompositeDevelopment, ScenesRoundTripTheOption) {
  const proto::Scene scene = proto::sceneFromText(readExample("composite-curved-fold.json"));
  EXPECT_EQ(std::get<CompositeDesign>(scene.model).developmentSamples, 4);
  const proto::Scene again = proto::sceneFromJson(proto::sceneToJson(scene));
  EXPECT_EQ(std::get<CompositeDesign>(again.model).developmentSamples, 4);
  nlohmann::json doc = proto::sceneToJson(scene);
  doc["model"]["development"]["samples"] = 0;
  EXPECT_THROW(proto::sceneFromJson(doc), proto::SceneError);
}

TEST(CompositeDevelopment, PresetSolvesIsometric) {
  const Solved s = solvedPreset();
  const double err = s.model->developmentLengthError();
  const CompositeQuality q = s.model->quality();
  std::cout << "development_length_error " << err << ", warp_angle_max_deg " << q.warpAngleMaxDeg
            << ", crease_fold_angle_max_deg " << q.foldAngleMaxDeg << "\n";
  EXPECT_LE(err, 1e-3);
  EXPECT_LT(q.warpAngleMaxDeg, 0.05);
  EXPECT_GT(q.foldAngleMaxDeg, 1.0);  // it does fold
}

TEST(CompositeDevelopment, PresetExportsFoldAndSvg) {
  const Solved s = solvedPreset();
  const io::CreasePattern cp = s.model->creasePattern(s.name);
  const io::CreasePattern back = io::parseFold(io::foldString(cp));
  ASSERT_EQ(back.edges.size(), cp.edges.size());
  EXPECT_EQ(back.numVertices(), cp.numVertices());
  // Crease edge 0: every segment M or V with the model's fold angle sign.
  const std::vector<CreaseGeometry> creases = s.model->creases(4);
  const CreaseGeometry* crease = nullptr;
  for (const CreaseGeometry& c : creases)
    if (c.edge == 0) crease = &c;
  ASSERT_NE(crease, nullptr);
  const double modelSign = crease->foldAngleDeg.mean() > 0 ? 1.0 : -1.0;
  int foldEdges = 0;
  for (std::size_t i = 0; i < back.edges.size(); ++i) {
    if (cp.edges[i].curve != 0) continue;
    const io::CreaseEdge& e = back.edges[i];
    ASSERT_TRUE(e.assignment == io::EdgeAssignment::Mountain || e.assignment == io::EdgeAssignment::Valley);
    ASSERT_TRUE(e.foldAngle.has_value());
    EXPECT_EQ(*e.foldAngle > 0 ? 1.0 : -1.0, modelSign);
    EXPECT_EQ(e.assignment, modelSign > 0 ? io::EdgeAssignment::Valley : io::EdgeAssignment::Mountain);
    ++foldEdges;
  }
  EXPECT_EQ(foldEdges, crease->foldAngleDeg.size() - 1);
  // Boundary edges are B, sampled rulings F.
  int boundary = 0;
  for (const io::CreaseEdge& e : back.edges) boundary += e.assignment == io::EdgeAssignment::Boundary;
  EXPECT_GT(boundary, 0);
  // The measured fold angles of the folded frame agree in sign with the given ones.
  const auto measured = io::measuredFoldAngles(cp);
  for (std::size_t i = 0; i < cp.edges.size(); ++i)
    if (cp.edges[i].curve == 0 && measured[i]) EXPECT_GT(*measured[i] * *cp.edges[i].foldAngle, 0.0);

  const std::string svg = io::svgFoldPattern(cp);
  EXPECT_NE(svg.find("id=\"curve-0\""), std::string::npos);
  EXPECT_NE(svg.find("<polyline"), std::string::npos);
}

}  // namespace
}  // namespace devsurf::models::composite
