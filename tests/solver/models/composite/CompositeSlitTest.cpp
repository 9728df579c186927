// Slits (issue 16 item 1: FOLD's C edges; until now noted and joined): a sheet is cut along its cut
// edges before it becomes a composite, so a slit opens when the sheet folds. Checked on a square
// of four panels with a slit from the bottom edge to the centre: the two sides of the slit fold
// opposite ways and come apart — which a sheet joined there cannot do (a straight valley running
// into a straight mountain through a point: fold conflict).

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "devsurf/io/CreasePatternSlits.h"
#include "devsurf/models/composite/CompositeFoldConflicts.h"
#include "devsurf/models/composite/CompositeFromCreasePattern.h"
#include "devsurf/models/composite/CompositeModel.h"

namespace devsurf::models::composite {
namespace {

using A = io::EdgeAssignment;

/// A 200 mm square in four panels (vertex (i, j) = 3j + i on a 3 × 3 grid, 100 mm apart): the
/// horizontal middle line a valley on the left and a mountain on the right (90° each), the upper
/// vertical half flat, the lower vertical half `lower` (a cut: a slit from the bottom edge to the
/// centre).
io::CreasePattern fourPanels(A lower) {
  io::CreasePattern p;
  p.vertices2d.resize(9, 2);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) p.vertices2d.row(3 * j + i) << 100.0 * i, 100.0 * j;
  p.edges = {{0, 1, A::Boundary}, {1, 2, A::Boundary}, {2, 5, A::Boundary}, {5, 8, A::Boundary},
             {8, 7, A::Boundary}, {7, 6, A::Boundary}, {6, 3, A::Boundary}, {3, 0, A::Boundary},
             {3, 4, A::Valley, 90.0}, {4, 5, A::Mountain, -90.0}, {4, 7, A::Flat}, {1, 4, lower}};
  p.faces = {{0, 1, 4, 3}, {1, 2, 5, 4}, {3, 4, 7, 6}, {4, 5, 8, 7}};
  return p;
}

TEST(CompositeSlit, ASlitFromTheEdgeToTheCentreDoublesItsEdgePointOnlyAndBothSidesBecomeBoundary) {
  const io::SlitCut cut = io::cutAlongSlits(fourPanels(A::Cut));
  ASSERT_EQ(cut.pattern.numVertices(), 10);  // vertex 1 (on the sheet's edge) doubled, the tip 4 not
  EXPECT_EQ(cut.sourceVertex[9], 1);
  EXPECT_EQ((cut.pattern.vertices2d.row(9) - cut.pattern.vertices2d.row(1)).norm(), 0.0);
  ASSERT_EQ(cut.pattern.edges.size(), 13u);
  EXPECT_EQ(cut.pattern.edges[11].assignment, A::Boundary);
  EXPECT_EQ(cut.pattern.edges[12].assignment, A::Boundary);
  // The two sides: one from vertex 1, one from its copy, both to the tip.
  const auto ends = [&cut](int e) { return std::minmax(cut.pattern.edges[static_cast<std::size_t>(e)].v0, cut.pattern.edges[static_cast<std::size_t>(e)].v1); };
  EXPECT_EQ(ends(11), std::minmax(1, 4));
  EXPECT_EQ(ends(12), std::minmax(9, 4));
  // The lower-left panel keeps vertex 1, the lower-right one uses the copy.
  EXPECT_EQ(cut.pattern.faces[0], (std::vector<int>{0, 1, 4, 3}));
  EXPECT_EQ(cut.pattern.faces[1], (std::vector<int>{9, 2, 5, 4}));
}

TEST(CompositeSlit, TheTwoSidesOfASlitFoldOppositeWaysAndComeApartWhereAJoinedSheetCannot) {
  const CreasePatternComposite slit = compositeFromCreasePattern(fourPanels(A::Cut));
  ASSERT_NO_THROW(CompositeTopology topology(slit.design));
  EXPECT_EQ(slit.design.vertices.rows(), 10);
  EXPECT_TRUE(foldConflicts(slit.design).empty()) << foldConflicts(slit.design)[0].reason;
  // Joined there (the lower half a flat line), the valley meets the mountain in a straight line
  // through the centre: named as a point that cannot fold.
  const CreasePatternComposite joined = compositeFromCreasePattern(fourPanels(A::Flat));
  EXPECT_FALSE(foldConflicts(joined.design).empty());

  CompositeModel model(slit.design);
  model.setFoldAmount(1.0);
  engine::SolverOptions o;
  o.maxIterations = 60;
  o.fairness = 0.0;
  model.solve(o);
  const CompositeDesign folded = model.design();
  const int a = slit.designVertexOf[1], b = static_cast<int>(slit.design.vertices.rows()) - 1;
  const double apart = (folded.vertices.row(a) - folded.vertices.row(b)).norm();
  std::printf("slit folded: fold-angle error %.3g°, development length error %.2g, the slit's mouth %.1f mm open\n",
              model.foldAngleErrorMaxDeg(), model.developmentLengthError(), apart);
  EXPECT_LT(model.foldAngleErrorMaxDeg(), 0.5);
  EXPECT_LT(model.developmentLengthError(), 1e-5);
  EXPECT_LT(model.quality().faceFlatnessMax, 1e-6);
  // The lower panels turned 90° about the middle line, one up, one down: their corners at the
  // slit's mouth are 2 × 100 mm apart.
  EXPECT_NEAR(apart, 200.0, 1.0);
}

TEST(CompositeSlit, ACutThatWouldPartTheSheetOrJoinTheSamePointsTwiceIsKeptWithANote) {
  // From edge to edge: two pieces.
  io::CreasePattern across = fourPanels(A::Cut);
  across.edges[10].assignment = A::Cut;  // the upper half too: the sheet cut in two
  const io::SlitCut parted = io::cutAlongSlits(across);
  EXPECT_EQ(parted.pattern.numVertices(), 9);
  ASSERT_FALSE(parted.notes.empty());
  EXPECT_NE(parted.notes.back().message.find("2 pieces"), std::string::npos) << parted.notes.back().message;
  // One edge with both ends inside the sheet: the vertical edge between the two interior points
  // of the left column of a 3 × 3 grid of panels.
  io::CreasePattern p;
  p.vertices2d.resize(16, 2);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) p.vertices2d.row(4 * j + i) << 100.0 * i, 100.0 * j;
  const auto id = [](int i, int j) { return 4 * j + i; };
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 3; ++i)
      p.edges.push_back({id(i, j), id(i + 1, j), j == 0 || j == 3 ? A::Boundary : A::Flat});
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 3; ++j)
      p.edges.push_back({id(i, j), id(i, j + 1), i == 0 || i == 3 ? A::Boundary : (j == 1 && i == 1 ? A::Cut : A::Mountain)});
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) p.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  const io::SlitCut single = io::cutAlongSlits(p);
  EXPECT_EQ(single.pattern.numVertices(), 16);
  ASSERT_FALSE(single.notes.empty());
  EXPECT_NE(single.notes.front().message.find("same two points"), std::string::npos) << single.notes.front().message;
}

}  // namespace
}  // namespace devsurf::models::composite
