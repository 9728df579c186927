// The fold slider's model side (issue 16, item 2): fold-angle targets scaled by the fold amount
// pull the sheet through developable intermediate states, checked with the crease pattern's own
// fold-angle measurement (io::measuredFoldAngles, computed from face normals independently of
// the hinge term).

#include <cmath>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "devsurf/io/FoldImport.h"
#include "devsurf/models/composite/CompositeFromCreasePattern.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/proto/Scene.h"
#include "support/Presets.h"

namespace devsurf::models::composite {
namespace {

engine::SolverOptions foldSliderSolve(int iterations) {
  engine::SolverOptions o;
  o.maxIterations = iterations;
  o.fairness = 0.0;
  return o;
}

/// A unit square (200 mm) with one valley diagonal, as a crease-pattern import makes it.
CompositeDesign squareWithValleyDiagonal() {
  io::CreasePattern p;
  p.vertices2d.resize(4, 2);
  p.vertices2d << 0, 0, 200, 0, 200, 200, 0, 200;
  p.edges = {{0, 1, io::EdgeAssignment::Boundary}, {1, 2, io::EdgeAssignment::Boundary},
             {2, 3, io::EdgeAssignment::Boundary}, {3, 0, io::EdgeAssignment::Boundary},
             {0, 2, io::EdgeAssignment::Valley, 120.0}};
  p.faces = {{0, 1, 2}, {0, 2, 3}};
  return compositeFromCreasePattern(p).design;
}

/// The largest |measured fold angle| of the model's crease pattern, from its face normals.
double measuredValleyDeg(const CompositeModel& model) {
  const io::CreasePattern cp = model.creasePattern();
  double valley = 0.0;
  for (const auto& a : io::measuredFoldAngles(cp))
    if (a) valley = std::max(valley, *a);
  return valley;
}

TEST(CompositeCreaseFolding, TheSliderFoldsAStraightCreaseToItsAmountOfTheTargetAngle) {
  CompositeDesign d = squareWithValleyDiagonal();
  ASSERT_EQ(d.foldAngles.size(), 1u);
  EXPECT_EQ(d.foldAmount, 0.0);  // a flat sheet with targets starts flat
  CompositeModel model(d);
  for (double amount : {0.25, 0.5, 1.0, 0.0}) {
    SCOPED_TRACE(amount);
    model.setFoldAmount(amount);
    model.solve(foldSliderSolve(40));
    EXPECT_NEAR(measuredValleyDeg(model), 120.0 * amount, 0.5);
    EXPECT_LT(model.foldAngleErrorMaxDeg(), 0.5);
    EXPECT_LT(model.developmentLengthError(), 1e-6);  // every intermediate state is the same sheet
    EXPECT_LT(model.quality().faceFlatnessMax, 1e-6);
  }
  // Valley: the free corner rises towards the front (+z) side of the development.
  model.setFoldAmount(0.5);
  model.solve(foldSliderSolve(40));
  const CompositeDesign folded = model.design();
  int freeCorner = -1;
  for (int v = 0; v < 4; ++v) {
    bool fixed = false;
    for (const PointRef& r : folded.fixed) fixed = fixed || r.vertex == v;
    if (!fixed) freeCorner = v;
  }
  ASSERT_GE(freeCorner, 0);
  EXPECT_GT(folded.vertices(freeCorner, 2), 50.0);
}

TEST(CompositeCreaseFolding, CapturingTheFoldKeepsTargetsOfHingesLeftFlatOrFoldedTheWrongWay) {
  CompositeDesign d = squareWithValleyDiagonal();  // valley, 120°
  {
    CompositeModel model(d);
    model.setFoldAmount(0.5);
    model.solve(foldSliderSolve(40));
    d = model.design();  // folded to 60° at half
  }
  ASSERT_NEAR(d.foldAmount, 0.5, 1e-12);
  // Folded the way of its target, by 60° at half: the target becomes 120° whatever it was.
  CompositeDesign asked = d;
  asked.foldAngles[0].angleDeg = 100.0;
  CompositeModel same(asked);
  same.captureFoldTargets();
  EXPECT_NEAR(same.design().foldAngles[0].angleDeg, 120.0, 1.0);
  // The sheet mirrored (every fold the other way, −60°): the valley keeps its 120°.
  CompositeDesign mirrored = d;
  mirrored.vertices.col(2) *= -1.0;
  CompositeModel against(mirrored);
  ASSERT_LT(against.hingeAngles()[0].angleDeg, -50.0);
  against.captureFoldTargets();
  EXPECT_EQ(against.design().foldAngles[0].angleDeg, 120.0);
  // Flat at half (a drag that left the sheet unfolded): the target stays too.
  CompositeDesign flat = squareWithValleyDiagonal();
  flat.foldAmount = 0.5;
  CompositeModel unfolded(flat);
  unfolded.captureFoldTargets();
  EXPECT_EQ(unfolded.design().foldAngles[0].angleDeg, 120.0);
}

TEST(CompositeCreaseFolding, HingeAnglesAgreeWithTheCreasePatternsMeasurement) {
  CompositeDesign d = squareWithValleyDiagonal();
  d.foldAmount = 0.6;
  CompositeModel model(d);
  model.solve(foldSliderSolve(40));
  const auto hinges = model.hingeAngles();
  ASSERT_EQ(hinges.size(), 1u);
  EXPECT_NEAR(hinges[0].angleDeg, measuredValleyDeg(model), 1e-6);
}

// A curved-crease preset folds down to flat and back up through its hinges at the crease ends:
// the targets are its own hinge angles (what the session takes as 100 % on the first slider move).
TEST(CompositeCreaseFolding, ACurvedCreasePresetUnfoldsToFlatAndFoldsBack) {
  const proto::Scene scene = proto::sceneFromJson(devsurf::testing::readPreset("composite-two-creases.json"));
  CompositeDesign d = std::get<CompositeDesign>(scene.model);
  {
    CompositeModel designed(d);
    designed.solve(foldSliderSolve(40));
    d = designed.design();
    for (const auto& h : designed.hingeAngles()) d.foldAngles.push_back({h.edge, h.end, h.angleDeg});
    d.handles.clear();  // the slider alone folds it
  }
  ASSERT_GE(d.foldAngles.size(), 2u);
  double designedMax = 0.0;
  for (const auto& t : d.foldAngles) designedMax = std::max(designedMax, std::abs(t.angleDeg));
  ASSERT_GT(designedMax, 10.0);
  CompositeModel model(d);
  for (double amount : {0.5, 0.0, 1.0}) {
    SCOPED_TRACE(amount);
    model.setFoldAmount(amount);
    model.solve(foldSliderSolve(60));
    EXPECT_LT(model.foldAngleErrorMaxDeg(), 0.05 * designedMax + 1.0);
    EXPECT_LT(model.quality().creaseFoldResidualMax, 1e-3);  // still curved folds (eq. 7)
    EXPECT_LT(model.developmentLengthError(), 1e-3);
    if (amount == 0.0) EXPECT_LT(model.quality().foldAngleMaxDeg, 0.1 * designedMax);
  }
}

// An imported crease pattern exported before it is folded (fold amount 0) is the pattern a
// cutter scores: its valley stays a valley with its designed angle, not a flat line.
TEST(CompositeCreaseFolding, AFlatSheetsCreasePatternKeepsItsDesignedMountainsAndValleys) {
  for (const double designed : {120.0, -75.0}) {
    SCOPED_TRACE(designed);
    CompositeDesign d = squareWithValleyDiagonal();
    ASSERT_EQ(d.foldAngles.size(), 1u);
    d.foldAngles[0].angleDeg = designed;
    CompositeModel model(d);
    auto diagonal = [&model]() {
      const io::CreasePattern cp = model.creasePattern();
      for (const io::CreaseEdge& e : cp.edges)
        if (e.assignment != io::EdgeAssignment::Boundary) return e;
      return io::CreaseEdge{};
    };
    const io::EdgeAssignment expected = designed > 0 ? io::EdgeAssignment::Valley : io::EdgeAssignment::Mountain;
    io::CreaseEdge flat = diagonal();
    EXPECT_EQ(flat.assignment, expected);
    ASSERT_TRUE(flat.foldAngle);
    EXPECT_NEAR(*flat.foldAngle, designed, 1e-9);
    // Folded part way, the pattern says what the sheet does; back at 0 % the design again.
    model.setFoldAmount(0.5);
    model.solve(foldSliderSolve(40));
    const io::CreaseEdge half = diagonal();
    EXPECT_EQ(half.assignment, expected);
    ASSERT_TRUE(half.foldAngle);
    EXPECT_NEAR(*half.foldAngle, 0.5 * designed, 1.0);
    model.setFoldAmount(0.0);
    model.solve(foldSliderSolve(40));
    flat = diagonal();
    EXPECT_EQ(flat.assignment, expected);
    ASSERT_TRUE(flat.foldAngle);
    EXPECT_NEAR(*flat.foldAngle, designed, 1.0);
  }
}

TEST(CompositeCreaseFolding, BadTargetsAreRefusedNamingTheField) {
  CompositeDesign d = squareWithValleyDiagonal();
  auto messageOf = [](const CompositeDesign& design) {
    try {
      CompositeModel::validateDesign(design);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  CompositeDesign boundary = d;
  boundary.foldAngles[0].edge = 0;
  EXPECT_NE(messageOf(boundary).find("fold_angles[0].edge"), std::string::npos) << messageOf(boundary);
  CompositeDesign end = d;
  end.foldAngles[0].end = 1;
  EXPECT_NE(messageOf(end).find("fold_angles[0].end"), std::string::npos) << messageOf(end);
  CompositeDesign angle = d;
  angle.foldAngles[0].angleDeg = 270;
  EXPECT_NE(messageOf(angle).find("fold_angles[0].angle"), std::string::npos) << messageOf(angle);
  CompositeDesign amount = d;
  amount.foldAmount = 1.5;
  EXPECT_NE(messageOf(amount).find("fold_amount"), std::string::npos) << messageOf(amount);
  CompositeModel model(d);
  EXPECT_THROW(model.setFoldAmount(-0.1), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::models::composite
