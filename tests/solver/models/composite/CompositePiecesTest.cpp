// Flat pieces of a composite cut along its seams (issue 15: the cutting pattern of a shape's cover).
#include "devsurf/models/composite/CompositePieces.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>

#include "CompositeFixtures.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/proto/Scene.h"

namespace devsurf::models::composite {
namespace {

CompositeDesign presetDesign(const std::string& name) {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + name);
  std::stringstream text;
  text << file.rdbuf();
  return std::get<CompositeDesign>(proto::sceneFromText(text.str()).model);
}

double signedArea(const Eigen::MatrixX2d& v, const io::PolygonFace& f) {
  const int n = io::cornerCount(f);
  double a = 0.0;
  for (int k = 0; k < n; ++k) {
    const Eigen::RowVector2d p = v.row(f[k]), q = v.row(f[(k + 1) % n]);
    a += p.x() * q.y() - p.y() * q.x();
  }
  return 0.5 * a;
}

TEST(CompositePieces, ACoverOfEightStripsUnfoldsIntoEightPiecesGluedAlongSevenSeams) {
  const CompositeDesign design = presetDesign("composite-cover-bunny.json");
  const CompositeModel model(design);
  const FlatPieces pieces = unfoldPieces(model.design(), model.topology(), 10);
  EXPECT_EQ(pieces.pieces, 8);
  // Every seam point has its two copies paired: 7 shared edges of U samples each.
  int seamSamples = 0;
  for (int e = 0; e < model.topology().numEdges(); ++e)
    if (isSeam(model.design(), model.topology(), e))
      seamSamples += model.design().edges[e].curve.knots.numSpans() * 10 + 1;
  EXPECT_GT(seamSamples, 7 * 10);
  // A composite vertex where two seams meet would be copied more often; on this cover each seam
  // end is a boundary corner shared by exactly two strips.
  EXPECT_EQ(static_cast<int>(pieces.gluePairs.size()), seamSamples);
  for (const auto& [a, b] : pieces.gluePairs) EXPECT_NE(pieces.pieceOfVertex[a], pieces.pieceOfVertex[b]);
  // Developable strips unfold without stretching (warp 3e-4°: round-off of the sampling).
  EXPECT_LT(pieces.lengthErrorMax, 1e-4);
  // Counter-clockwise, and the pieces side by side without overlapping (their y ranges apart).
  for (const io::PolygonFace& f : pieces.faces) EXPECT_GT(signedArea(pieces.vertices, f), 0.0);
  std::vector<std::pair<double, double>> ranges(8, {1e300, -1e300});
  for (Eigen::Index v = 0; v < pieces.vertices.rows(); ++v) {
    auto& r = ranges[static_cast<std::size_t>(pieces.pieceOfVertex[static_cast<std::size_t>(v)])];
    r.first = std::min(r.first, pieces.vertices(v, 1));
    r.second = std::max(r.second, pieces.vertices(v, 1));
  }
  std::sort(ranges.begin(), ranges.end());
  for (std::size_t k = 1; k < ranges.size(); ++k) EXPECT_LT(ranges[k - 1].second, ranges[k].first);
}

TEST(CompositePieces, ASheetWithADevelopmentIsOnePieceWithNothingToGlue) {
  const CompositeDesign design = presetDesign("composite-curved-fold.json");
  ASSERT_GT(design.developmentSamples, 0);
  const CompositeModel model(design);
  const FlatPieces pieces = unfoldPieces(model.design(), model.topology(), 4);
  EXPECT_EQ(pieces.pieces, 1);
  EXPECT_TRUE(pieces.gluePairs.empty());
  EXPECT_LT(pieces.lengthErrorMax, 1e-3);  // folded, and still one developable sheet
}

TEST(CompositePieces, AFlatSheetUnfoldsCongruentToItself) {
  const CompositeDesign design = fixtures::flatSheet();
  const CompositeModel model(design);
  const FlatPieces pieces = unfoldPieces(model.design(), model.topology(), 3);
  ASSERT_EQ(pieces.pieces, 1);
  const SampledComposite sampled = sampleComposite(model.design(), model.topology(), 3);
  // Every pair of points keeps its 3D distance (a planar sheet unfolds congruent to itself).
  ASSERT_EQ(pieces.pointOfVertex.size(), static_cast<std::size_t>(pieces.vertices.rows()));
  ASSERT_EQ(pieces.vertices.rows(), static_cast<Eigen::Index>(sampled.points.size()));
  double worst = 0.0;
  for (Eigen::Index i = 0; i < pieces.vertices.rows(); ++i)
    for (Eigen::Index j = i + 1; j < pieces.vertices.rows(); ++j) {
      const double flat = (pieces.vertices.row(i) - pieces.vertices.row(j)).norm();
      const double space = (sampled.points[pieces.pointOfVertex[i]] - sampled.points[pieces.pointOfVertex[j]]).norm();
      worst = std::max(worst, std::abs(flat - space));
    }
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(pieces.lengthErrorMax, 1e-12);
}

TEST(CompositePieces, ZeroSamplesPerSpanIsRefused) {
  const CompositeModel model(fixtures::flatSheet());
  EXPECT_THROW(unfoldPieces(model.design(), model.topology(), 0), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::models::composite
