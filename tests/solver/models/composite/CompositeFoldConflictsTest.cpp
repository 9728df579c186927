// Points whose creases cannot all fold (issue 16: two straight M/V creases drawn across each other
// were accepted and the slider stretched the sheet without a word). The rules are checked on
// drawings a user makes, the shipped presets and FOLD examples must have none, and the reason is
// checked against the solver itself: a flagged design does not reach its fold, a clean one does.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "devsurf/io/FoldImport.h"
#include "devsurf/models/composite/CompositeFoldConflicts.h"
#include "devsurf/models/composite/CompositeFromCreasePattern.h"
#include "devsurf/models/composite/CompositeFromDrawing.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/proto/Scene.h"
#include "support/Presets.h"

namespace devsurf::models::composite {
namespace {

using V2 = Eigen::Vector2d;

io::CreaseStroke conflictStroke(std::vector<V2> points, io::EdgeAssignment a) {
  io::CreaseStroke s;
  s.points = std::move(points);
  s.assignment = a;
  return s;
}

/// A 200 × 200 mm sheet with the given creases.
DrawingComposite sheetWith(std::vector<io::CreaseStroke> creases) {
  std::vector<io::CreaseStroke> drawing{conflictStroke({V2(0, 0), V2(200, 0)}, io::EdgeAssignment::Boundary),
                                        conflictStroke({V2(200, 0), V2(200, 200)}, io::EdgeAssignment::Boundary),
                                        conflictStroke({V2(200, 200), V2(0, 200)}, io::EdgeAssignment::Boundary),
                                        conflictStroke({V2(0, 200), V2(0, 0)}, io::EdgeAssignment::Boundary)};
  for (io::CreaseStroke& s : creases) drawing.push_back(std::move(s));
  return compositeFromDrawing(drawing);
}

/// The design vertex at sheet point p (flat designs: x, y as drawn).
int vertexAt(const CompositeDesign& d, const V2& p) {
  for (Eigen::Index v = 0; v < d.vertices.rows(); ++v)
    if ((d.vertices.row(v).head<2>().transpose() - p).norm() < 1e-6) return static_cast<int>(v);
  return -1;
}

constexpr auto M = io::EdgeAssignment::Mountain;
constexpr auto Vl = io::EdgeAssignment::Valley;

TEST(CompositeFoldConflicts, TwoStraightCreasesDrawnAcrossEachOtherCannotBothFold) {
  for (const auto second : {M, Vl}) {
    const DrawingComposite built = sheetWith({conflictStroke({V2(0, 100), V2(200, 100)}, M),
                                              conflictStroke({V2(100, 0), V2(100, 200)}, second)});
    const std::vector<FoldConflict> conflicts = foldConflicts(built.design);
    ASSERT_EQ(conflicts.size(), 1u);
    EXPECT_EQ(conflicts[0].vertex, vertexAt(built.design, V2(100, 100)));
    EXPECT_NE(conflicts[0].reason.find("cross"), std::string::npos) << conflicts[0].reason;
    // The import's notes say it too, by where it is.
    bool noted = false;
    for (const io::ImportNote& n : built.notes) noted = noted || n.message.find("at (100, 100): two straight creases cross") == 0;
    EXPECT_TRUE(noted);
  }
}

TEST(CompositeFoldConflicts, ACreaseEndingOnAnotherMakesARigidPointOfThree) {
  const DrawingComposite built = sheetWith({conflictStroke({V2(0, 100), V2(200, 100)}, M),
                                            conflictStroke({V2(100, 100), V2(100, 200)}, Vl)});
  const std::vector<FoldConflict> conflicts = foldConflicts(built.design);
  ASSERT_EQ(conflicts.size(), 1u);
  EXPECT_EQ(conflicts[0].vertex, vertexAt(built.design, V2(100, 100)));
  EXPECT_NE(conflicts[0].reason.find("three creases"), std::string::npos);
}

// A straight crease drawn to end on a curved one (a T): at that point three creases fold, their
// tangent planes a vertex of degree three, so the one that ends cannot fold there. Two curved
// creases that do not meet, and the curved one alone, are not flagged.
TEST(CompositeFoldConflicts, AStraightCreaseEndingOnACurvedOneIsARigidPointOfThree) {
  std::vector<V2> arc;
  for (int k = 0; k <= 16; ++k) {
    const double x = 12.5 * k;
    arc.emplace_back(x, 80.0 + 30.0 * (1.0 - std::pow((x - 100.0) / 100.0, 2)));
  }
  const DrawingComposite tee = sheetWith({conflictStroke(arc, M), conflictStroke({V2(100, 110), V2(100, 200)}, Vl)});
  const std::vector<FoldConflict> conflicts = foldConflicts(tee.design);
  ASSERT_EQ(conflicts.size(), 1u);
  EXPECT_EQ(conflicts[0].vertex, vertexAt(tee.design, V2(100, 110)));
  EXPECT_NE(conflicts[0].reason.find("ends on a curved one"), std::string::npos) << conflicts[0].reason;
  EXPECT_TRUE(foldConflicts(sheetWith({conflictStroke(arc, M)}).design).empty());
  std::vector<V2> lower = arc;
  for (V2& p : lower) p.y() -= 50.0;
  EXPECT_TRUE(foldConflicts(sheetWith({conflictStroke(arc, M), conflictStroke(lower, Vl)}).design).empty());
}

TEST(CompositeFoldConflicts, AFourCreasePointFoldsWithThreeOfOneKindAndOneOfTheOther) {
  // A bird's foot at (100, 100): a straight mountain line and two creases below it at ±45°.
  const auto birdsFoot = [](io::EdgeAssignment left, io::EdgeAssignment right) {
    return sheetWith({conflictStroke({V2(0, 100), V2(100, 100)}, M), conflictStroke({V2(100, 100), V2(200, 100)}, M),
                      conflictStroke({V2(100, 100), V2(0, 0)}, left), conflictStroke({V2(100, 100), V2(200, 0)}, right)});
  };
  EXPECT_TRUE(foldConflicts(birdsFoot(Vl, M).design).empty()) << "3 mountains, 1 valley";
  const std::vector<FoldConflict> twoTwo = foldConflicts(birdsFoot(Vl, Vl).design);
  ASSERT_EQ(twoTwo.size(), 1u);
  EXPECT_NE(twoTwo[0].reason.find("2 mountain and 2 valley"), std::string::npos) << twoTwo[0].reason;
  const std::vector<FoldConflict> allMountains = foldConflicts(birdsFoot(M, M).design);
  ASSERT_EQ(allMountains.size(), 1u);
  EXPECT_NE(allMountains[0].reason.find("4 mountain and 0 valley"), std::string::npos) << allMountains[0].reason;
}

TEST(CompositeFoldConflicts, ACreaseThatBendsOrTurnsFromMountainToValleyIsFlagged) {
  const DrawingComposite bent = sheetWith({conflictStroke({V2(0, 100), V2(100, 100)}, M),
                                           conflictStroke({V2(100, 100), V2(200, 150)}, M)});
  const std::vector<FoldConflict> b = foldConflicts(bent.design);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_NE(b[0].reason.find("meet at an angle of 153°"), std::string::npos) << b[0].reason;
  const DrawingComposite turning = sheetWith({conflictStroke({V2(0, 100), V2(100, 100)}, M),
                                              conflictStroke({V2(100, 100), V2(200, 100)}, Vl)});
  const std::vector<FoldConflict> t = foldConflicts(turning.design);
  ASSERT_EQ(t.size(), 1u);
  EXPECT_NE(t[0].reason.find("turns from mountain to valley"), std::string::npos) << t[0].reason;
}

TEST(CompositeFoldConflicts, ACreaseWithoutATargetFoldsFreelyAndIsNotJudged) {
  DrawingComposite built = sheetWith({conflictStroke({V2(0, 100), V2(200, 100)}, M),
                                      conflictStroke({V2(100, 100), V2(100, 200)}, Vl)});
  const int centre = vertexAt(built.design, V2(100, 100));
  // Drop the target of the crease that ends on the line: it may fold or not.
  std::vector<FoldAngleTarget>& targets = built.design.foldAngles;
  targets.erase(std::remove_if(targets.begin(), targets.end(),
                               [&built, centre](const FoldAngleTarget& t) {
                                 const CompositeEdge& e = built.design.edges[static_cast<std::size_t>(t.edge)];
                                 const Eigen::Vector3d other = built.design.vertices.row(e.v0 == centre ? e.v1 : e.v0).transpose();
                                 return (e.v0 == centre || e.v1 == centre) && other.y() > 150.0;
                               }),
                targets.end());
  EXPECT_TRUE(foldConflicts(built.design).empty());
}

TEST(CompositeFoldConflicts, TheFoldExamplesHaveNone) {
  for (const char* file : {"box.fold", "diagonal-cp.fold", "diagonal-folded.fold", "simple.fold", "squaretwist.fold"}) {
    SCOPED_TRACE(file);
    std::ifstream in(std::string(DEVSURF_SOURCE_DIR) + "/tests/data/fold/" + file);
    std::stringstream text;
    text << in.rdbuf();
    const io::FoldImport imported = io::importFoldDocument(nlohmann::json::parse(text.str()));
    const CreasePatternComposite built = compositeFromCreasePattern(imported.pattern);
    EXPECT_TRUE(foldConflicts(built.design).empty());
  }
}

/// The composite presets of examples/ (discovered).
std::vector<std::string> compositePresetFiles() {
  std::vector<std::string> files;
  for (const std::string& f : testing::presetFiles())
    if (testing::readPreset(f)["model"].value("kind", "") == "composite") files.push_back(f);
  return files;
}

class CompositePresetFoldConflicts : public ::testing::TestWithParam<std::string> {};

TEST_P(CompositePresetFoldConflicts, AShippedCompositeHasNone) {
  const nlohmann::json doc = testing::readPreset(GetParam());
  const proto::Scene scene = proto::sceneFromJson(doc);
  const auto& design = std::get<CompositeDesign>(scene.model);
  for (const FoldConflict& c : foldConflicts(design)) ADD_FAILURE() << "vertex " << c.vertex << ": " << c.reason;
}

INSTANTIATE_TEST_SUITE_P(Presets, CompositePresetFoldConflicts, ::testing::ValuesIn(compositePresetFiles()),
                         [](const auto& info) { return testing::presetTestName(info); });

/// The reason holds in the solver: halfway along the slider, the flagged crossing misses its fold
/// angles by tens of degrees and stretches the sheet, while the same sheet with one straight
/// crease folds to within a degree.
TEST(CompositeFoldConflicts, TheSolverCannotFoldAFlaggedCrossingButFoldsOneLine) {
  engine::SolverOptions options;
  options.maxIterations = 60;
  options.fairness = 0.0;
  const auto foldHalfway = [&options](const CompositeDesign& d) {
    CompositeModel model(d);
    model.setFoldAmount(0.5);
    model.solve(options);
    return std::make_pair(model.foldAngleErrorMaxDeg(), model.developmentLengthError());
  };
  const DrawingComposite crossing = sheetWith({conflictStroke({V2(0, 100), V2(200, 100)}, M),
                                               conflictStroke({V2(100, 0), V2(100, 200)}, Vl)});
  ASSERT_FALSE(foldConflicts(crossing.design).empty());
  const auto [crossingError, crossingStretch] = foldHalfway(crossing.design);
  EXPECT_GT(crossingError, 20.0);
  const DrawingComposite line = sheetWith({conflictStroke({V2(0, 100), V2(200, 100)}, M)});
  ASSERT_TRUE(foldConflicts(line.design).empty());
  const auto [lineError, lineStretch] = foldHalfway(line.design);
  EXPECT_LT(lineError, 1.0);
  EXPECT_LT(lineStretch, 1e-4);
  EXPECT_GT(crossingStretch, 10.0 * lineStretch);
}

}  // namespace
}  // namespace devsurf::models::composite
