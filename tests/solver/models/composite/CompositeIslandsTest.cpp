// Islands and holes in imported crease patterns (issue 16 item 1): a closed stroke that touches
// nothing is joined to the sheet by two straight bridges (smooth proposed rulings), and what an
// outline drawn inside the sheet encloses is cut out. Checked independently: areas from the
// exported crease pattern's polygons against the drawing's own geometry, fold angles measured
// from face normals (io::measuredFoldAngles), not from the hinge term the slider pulls with.

#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <sstream>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "devsurf/io/FoldImport.h"
#include "devsurf/io/FoldWriter.h"
#include "devsurf/io/QuadMesh.h"
#include "devsurf/io/SvgImport.h"
#include "devsurf/models/composite/CompositeFromCreasePattern.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/models/composite/CompositeTopology.h"
#include "devsurf/spatial/PlanarArrangement.h"
#include "CompositeFixtures.h"

namespace devsurf::models::composite {
namespace {

/// A width × height mm sheet with the given SVG elements drawn on it.
std::string islandSheetSvg(double width, double height, const std::string& elements) {
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "mm\" height=\"" << height << "mm\" viewBox=\"0 0 "
    << width << " " << height << "\"><rect x=\"0\" y=\"0\" width=\"" << width << "\" height=\"" << height
    << "\" fill=\"none\" stroke=\"#000000\"/>" << elements << "</svg>";
  return s.str();
}

/// The area of a crease pattern's faces (shoelace over its development polygons).
double patternArea(const io::CreasePattern& p) {
  double area = 0.0;
  for (const auto& f : p.faces) area += 0.5 * spatial::loopSignedArea2(p.vertices2d, f);
  return area;
}

/// The area of a quad mesh, each quad as the triangles (0, 1, 2) and (0, 2, 3).
double surfaceArea(const io::QuadMesh& mesh) {
  double area = 0.0;
  for (Eigen::Index q = 0; q < mesh.quads.rows(); ++q) {
    const Eigen::Vector3d a = mesh.vertices.row(mesh.quads(q, 0)), b = mesh.vertices.row(mesh.quads(q, 1)),
                          c = mesh.vertices.row(mesh.quads(q, 2)), d = mesh.vertices.row(mesh.quads(q, 3));
    area += 0.5 * (b - a).cross(c - a).norm() + 0.5 * (c - a).cross(d - a).norm();
  }
  return area;
}

using fixtures::measuredValleyAndMountain;

/// Solves the model to the given fold amounts in turn, as the slider does (in stages).
void foldInStages(CompositeModel& model, int stages, int iterationsPerStage) {
  engine::SolverOptions o;
  o.maxIterations = iterationsPerStage;
  for (int k = 1; k <= stages; ++k) {
    model.setFoldAmount(static_cast<double>(k) / stages);
    model.solve(o);
  }
}

bool notedWith(const std::vector<io::ImportNote>& notes, const std::string& words) {
  return std::any_of(notes.begin(), notes.end(), [&words](const io::ImportNote& n) { return n.message.find(words) != std::string::npos; });
}

TEST(CompositeIslands, ASquareHoleIsCutOutAndTheSheetStillFoldsAlongItsValley) {
  // 200 × 100 mm, a valley across the middle at 90° (opacity 0.5), a 40 × 40 hole left of it.
  const io::SvgImport svg = io::importSvgText(islandSheetSvg(
      200, 100,
      R"(<line x1="100" y1="0" x2="100" y2="100" stroke="#0000ff" stroke-opacity="0.5"/>)"
      R"(<rect x="30" y="30" width="40" height="40" fill="none" stroke="#000000"/>)"));
  EXPECT_TRUE(notedWith(svg.notes, "cut out as holes"));
  EXPECT_TRUE(notedWith(svg.notes, "joined to what surrounds them"));
  EXPECT_NEAR(patternArea(svg.pattern), 200.0 * 100.0 - 40.0 * 40.0, 1e-6);
  int bridges = 0;
  for (const io::CreaseEdge& e : svg.pattern.edges) bridges += e.proposed ? 1 : 0;
  EXPECT_EQ(bridges, 2);

  const CreasePatternComposite c = compositeFromCreasePattern(svg.pattern);
  const CompositeTopology topology(c.design);
  // The bridges stay smooth: the faces beside them are one flat piece of the sheet.
  int smooth = 0;
  for (std::size_t e = 0; e < svg.pattern.edges.size(); ++e)
    if (svg.pattern.edges[e].proposed && c.designEdgeOf[e] >= 0)
      smooth += c.design.edges[static_cast<std::size_t>(c.designEdgeOf[e])].crease == CreaseKind::Smooth ? 1 : 0;
  EXPECT_EQ(smooth, 2);
  EXPECT_FALSE(notedWith(c.notes, "folds freely"));

  CompositeModel model(c.design);
  foldInStages(model, 4, 40);
  const auto [valley, mountain] = measuredValleyAndMountain(model);
  EXPECT_NEAR(valley, 90.0, 0.5);
  EXPECT_NEAR(mountain, 0.0, 0.5);  // nothing else folds, the bridges included
  EXPECT_LT(model.developmentLengthError(), 1e-6);
  EXPECT_LT(model.quality().faceFlatnessMax, 1e-6);
  // The exported pattern still has the hole: the same area as the drawing minus the hole.
  EXPECT_NEAR(patternArea(model.creasePattern()), 200.0 * 100.0 - 40.0 * 40.0, 1e-3);
  // So does the folded surface (what is drawn and exported as STL): the faces beside the hole are
  // not convex, and triangles fanned from their centres would cover part of it.
  EXPECT_NEAR(surfaceArea(model.geometry(8, 2).merged), 200.0 * 100.0 - 40.0 * 40.0, 1e-3);
  // OBJ, OFF and PLY write those triangles as triangles (a quad with a corner twice aborted
  // OpenMesh): one face line per quad of the surface.
  const io::QuadMesh surface = model.geometry(8, 2).merged;
  std::istringstream obj(io::meshString(surface, "obj"));
  int faceLines = 0;
  for (std::string line; std::getline(obj, line);) faceLines += line.rfind("f ", 0) == 0 ? 1 : 0;
  EXPECT_EQ(faceLines, surface.quads.rows());
  EXPECT_NO_THROW(io::meshString(surface, "off"));
  EXPECT_NO_THROW(io::meshString(surface, "ply"));
}

TEST(CompositeIslands, ARegionCutAllRoundByAGreenLoopFallsOutAsAHole) {
  // A closed cut (green) circle inside a 200 × 100 mm sheet with a straight valley: the disk is
  // cut out, not kept joined as a slit that would part the sheet. (The straight valley keeps the
  // drawing's faces planar.)
  const io::SvgImport svg = io::importSvgText(islandSheetSvg(
      200, 100,
      R"(<line x1="100" y1="0" x2="100" y2="100" stroke="#0000ff" stroke-opacity="0.5"/>)"
      R"(<polygon points="35,35 65,35 65,65 35,65" fill="none" stroke="#00ff00"/>)"));
  EXPECT_TRUE(notedWith(svg.notes, "cut out as holes"));
  EXPECT_NEAR(patternArea(svg.pattern), 200.0 * 100.0 - 30.0 * 30.0, 1e-9);
  const CreasePatternComposite c = compositeFromCreasePattern(svg.pattern);
  CompositeModel model(c.design);
  foldInStages(model, 4, 40);
  EXPECT_NEAR(measuredValleyAndMountain(model).first, 90.0, 0.5);
  EXPECT_LT(model.developmentLengthError(), 1e-6);
}

TEST(CompositeIslands, ABlackFrameDrawnInsideTheSheetAroundItsCreasesIsNotAHole) {
  // The outline drawn a second time, 5 mm in, around a valley: what it encloses holds a crease, so
  // it is not a hole (the sheet would shrink to the frame); the inner lines stay cuts.
  const io::SvgImport svg = io::importSvgText(islandSheetSvg(
      200, 100,
      R"(<rect x="5" y="5" width="190" height="90" fill="none" stroke="#000000"/>)"
      R"(<line x1="100" y1="5" x2="100" y2="95" stroke="#0000ff" stroke-opacity="0.5"/>)"));
  EXPECT_FALSE(notedWith(svg.notes, "cut out as holes"));
  EXPECT_NEAR(patternArea(svg.pattern), 200.0 * 100.0, 1e-9);
}

TEST(CompositeIslands, AFoldFileWithAHoleWalledOffByBoundaryEdgesImportsWithoutIt) {
  // A 4 × 4 sheet, a mountain along x = 3, a 1 × 1 hole (B edges) at (1, 1); no faces_vertices.
  const std::string fold = R"({"file_spec": 1.2, "frame_classes": ["creasePattern"],
    "vertices_coords": [[0,0],[4,0],[4,4],[0,4],[1,1],[2,1],[2,2],[1,2],[3,0],[3,4]],
    "edges_vertices": [[0,8],[8,1],[1,2],[2,9],[9,3],[3,0],[4,5],[5,6],[6,7],[7,4],[8,9]],
    "edges_assignment": ["B","B","B","B","B","B","B","B","B","B","M"],
    "edges_foldAngle": [0,0,0,0,0,0,0,0,0,0,-60]})";
  const io::FoldImport imported = io::importFoldText(fold);
  EXPECT_TRUE(notedWith(imported.notes, "cut out as holes"));
  EXPECT_NEAR(patternArea(imported.pattern), 16.0 - 1.0, 1e-12);
  const CreasePatternComposite c = compositeFromCreasePattern(imported.pattern);
  CompositeModel model(c.design);
  foldInStages(model, 3, 40);
  const auto [valley, mountain] = measuredValleyAndMountain(model);
  EXPECT_NEAR(mountain, -60.0, 0.5);
  EXPECT_NEAR(valley, 0.0, 0.5);
  EXPECT_LT(model.developmentLengthError(), 1e-6);
}

/// 100 × 100, a valley at x = 50 (60°), a 15 × 20 hole right of it walled off by B edges.
const char* const kSheetWithAHoleFold = R"({"file_spec": 1.2, "frame_classes": ["creasePattern"],
    "vertices_coords": [[0,0],[100,0],[100,100],[0,100],[50,0],[50,100],[70,40],[85,40],[85,60],[70,60]],
    "edges_vertices": [[0,4],[4,1],[1,2],[2,5],[5,3],[3,0],[4,5],[6,7],[7,8],[8,9],[9,6]],
    "edges_assignment": ["B","B","B","B","B","B","V","B","B","B","B"],
    "edges_foldAngle": [0,0,0,0,0,0,60,0,0,0,0]})";

TEST(CompositeIslands, AFlatSheetWithAHoleMeasuresFlatBeforeAndAfterItFolds) {
  // kSheetWithAHoleFold. The face around the hole runs
  // (100,0), (85,40), (70,40), (70,60) through a bridge: four corners whose diagonals are
  // parallel. face_flatness_max read 0.69 for the flat sheet (the distance between the parallel
  // diagonals) and 0.073 once folded (nearly parallel: the distance is ill-conditioned), until
  // planar faces were measured against their least-squares plane.
  const io::FoldImport imported = io::importFoldText(kSheetWithAHoleFold);
  const CreasePatternComposite c = compositeFromCreasePattern(imported.pattern);
  CompositeModel model(c.design);
  EXPECT_EQ(model.quality().faceFlatnessMax, 0.0);
  foldInStages(model, 3, 40);
  const auto [valley, mountain] = measuredValleyAndMountain(model);
  EXPECT_NEAR(valley, 60.0, 0.5);
  EXPECT_NEAR(mountain, 0.0, 0.5);
  EXPECT_LT(model.quality().faceFlatnessMax, 1e-6);
}

TEST(CompositeIslands, ASheetWithAHoleReadBackFromItsFoldExportKeepsItsBridgesSmooth) {
  // The pattern of the test above. Its FOLD export marks the bridges (R edges kept smooth) in
  // edges_devsurf:smooth; read back, they were flat edges whose faces cannot merge (they enclose
  // the hole), so they became hinges that fold freely.
  CompositeModel model(compositeFromCreasePattern(io::importFoldText(kSheetWithAHoleFold).pattern).design);
  for (const bool folded : {false, true}) {
    SCOPED_TRACE(folded ? "folded" : "flat");
    if (folded) foldInStages(model, 3, 40);
    const std::string exported = io::foldString(model.creasePattern("hole"));
    const nlohmann::json document = nlohmann::json::parse(exported);
    ASSERT_TRUE(document.contains("edges_devsurf:smooth"));
    int marked = 0;
    for (const auto& v : document["edges_devsurf:smooth"]) marked += v.get<bool>() ? 1 : 0;
    EXPECT_EQ(marked, 2);  // the two bridges, each one sampled edge

    const io::FoldImport back = io::importFoldText(exported);
    EXPECT_FALSE(notedWith(back.notes, "flat-folded")) << "the flat sheet is not a flat-folded form";
    int proposed = 0;
    for (const io::CreaseEdge& e : back.pattern.edges) proposed += e.proposed ? 1 : 0;
    EXPECT_EQ(proposed, 2);
    const CreasePatternComposite again = compositeFromCreasePattern(back.pattern);
    EXPECT_FALSE(notedWith(again.notes, "folds freely"));
    int smooth = 0;
    for (std::size_t e = 0; e < back.pattern.edges.size(); ++e)
      if (back.pattern.edges[e].proposed && again.designEdgeOf[e] >= 0)
        smooth += again.design.edges[static_cast<std::size_t>(again.designEdgeOf[e])].crease == CreaseKind::Smooth ? 1 : 0;
    EXPECT_EQ(smooth, 2);
  }
}

TEST(CompositeIslands, AHoleBesideACurvedCreaseFoldsWithItsSheet) {
  // A valley arc across a 200 × 150 mm sheet and a round hole below it.
  const io::SvgImport svg = io::importSvgText(islandSheetSvg(
      200, 150,
      R"(<path d="M 0 60 C 60 30 140 30 200 60" fill="none" stroke="#0000ff" stroke-opacity="0.5"/>)"
      R"(<circle cx="100" cy="110" r="18" fill="none" stroke="#000000"/>)"));
  EXPECT_NEAR(patternArea(svg.pattern), 200.0 * 150.0 - M_PI * 18.0 * 18.0, 0.01 * M_PI * 18.0 * 18.0);
  const CreasePatternComposite c = compositeFromCreasePattern(svg.pattern);
  CompositeModel model(c.design);
  foldInStages(model, 10, 60);
  const auto [valley, mountain] = measuredValleyAndMountain(model);
  EXPECT_GT(valley, 0.95 * 90.0);
  EXPECT_LT(model.foldAngleErrorMaxDeg(), 1.0);
  // Measured 0.20 % (the same sheet without the hole: 0.018 %): the strips around the hole end
  // their rulings on it, so the sheet bends in a ruling field the hole imposes.
  EXPECT_LT(model.developmentLengthError(), 3e-3);
  EXPECT_LT(model.quality().warpAngleMaxDeg, 1.0);

  // Its FOLD export read back: the smooth rulings between bent strips show the sampled quads'
  // angle in the folded frame. Those are kept as folds (noted so), not labelled smooth, which
  // would force their two planar faces into one plane.
  const io::FoldImport back = io::importFoldText(io::foldString(model.creasePattern("hole")));
  const std::vector<std::optional<double>> measured = io::measuredFoldAngles(back.pattern);
  const CreasePatternComposite again = compositeFromCreasePattern(back.pattern);
  int marked = 0, bent = 0;
  for (std::size_t e = 0; e < back.pattern.edges.size(); ++e) {
    if (!back.pattern.edges[e].proposed || again.designEdgeOf[e] < 0) continue;
    ++marked;
    if (!measured[e] || std::abs(*measured[e]) < 1.0) continue;
    ++bent;
    EXPECT_NE(again.design.edges[static_cast<std::size_t>(again.designEdgeOf[e])].crease, CreaseKind::Smooth)
        << "edges[" << e << "] folded by " << *measured[e] << "°";
  }
  EXPECT_GT(marked, 0);
  EXPECT_GT(bent, 0);
}

TEST(CompositeIslands, AHoleBesideAStraightCreaseOfACurvedDrawingFoldsWithItsSheet) {
  // A valley arc across a 200 × 150 mm sheet, a straight mountain below it, a round hole between
  // them 10 mm from the mountain. The bridge to the mountain leaves a face S R R R (the hole's
  // arc, two bridges, a piece of the crease) with no strip layout; it was refused by name. Now a
  // ruling from one bridge's foot on the hole to the other's on the crease cuts it into a cone and
  // a planar triangle.
  const io::SvgImport svg = io::importSvgText(islandSheetSvg(
      200, 150,
      R"(<path d="M 0 50 C 60 20 140 20 200 50" fill="none" stroke="#0000ff" stroke-opacity="0.5"/>)"
      R"(<line x1="0" y1="120" x2="200" y2="120" stroke="#ff0000" stroke-opacity="0.5"/>)"
      R"(<circle cx="100" cy="100" r="10" fill="none" stroke="#000000"/>)"));
  const CreasePatternComposite c = compositeFromCreasePattern(svg.pattern);
  EXPECT_TRUE(notedWith(c.notes, "ruling(s) proposed"));
  ASSERT_NO_THROW(CompositeTopology topology(c.design));
  CompositeModel model(c.design);
  EXPECT_LT(model.quality().faceFlatnessMax, 1e-9);
  EXPECT_NEAR(patternArea(model.creasePattern()), 200.0 * 150.0 - M_PI * 10.0 * 10.0, 0.04 * M_PI * 10.0 * 10.0);
  foldInStages(model, 10, 60);
  const auto [valley, mountain] = measuredValleyAndMountain(model);
  // Measured: 90.3° and −90.0°, fold-angle error 7e-6°, development error 0.10 %, flatness 1.9e-4.
  EXPECT_GT(valley, 0.9 * 90.0);
  EXPECT_LT(mountain, -0.9 * 90.0);
  EXPECT_LT(model.foldAngleErrorMaxDeg(), 1e-3);
  EXPECT_LT(model.developmentLengthError(), 5e-3);
  EXPECT_LT(model.quality().faceFlatnessMax, 1e-3);
}

TEST(CompositeIslands, NoRulingBetweenCornersRunsAlongAStraightCreaseThroughAnotherCorner) {
  // As above with a second curved crease below the mountain: the faces beside the mountain have
  // corners in a row on it, and a ruling between two of them along the crease through a third
  // would cut off a triangle of no area. Whatever rulings the import proposes, it either refuses
  // a face by name or builds faces that all have area. (Built here: 13 rulings proposed.)
  const io::SvgImport svg = io::importSvgText(islandSheetSvg(
      200, 150,
      R"(<path d="M 0 50 C 60 20 140 20 200 50" fill="none" stroke="#0000ff" stroke-opacity="0.5"/>)"
      R"(<line x1="0" y1="120" x2="200" y2="120" stroke="#ff0000" stroke-opacity="0.5"/>)"
      R"(<path d="M 0 135 C 60 145 140 145 200 135" fill="none" stroke="#0000ff" stroke-opacity="0.5"/>)"
      R"(<circle cx="100" cy="100" r="10" fill="none" stroke="#000000"/>)"));
  CreasePatternComposite c;
  try {
    c = compositeFromCreasePattern(svg.pattern);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("faces["), std::string::npos) << e.what();
    return;
  }
  const CompositeModel model(c.design);
  const io::CreasePattern pattern = model.creasePattern();
  for (std::size_t f = 0; f < pattern.faces.size(); ++f)
    EXPECT_GT(spatial::loopSignedArea2(pattern.vertices2d, pattern.faces[f]), 1e-6) << "face " << f;
  EXPECT_NEAR(patternArea(pattern), 200.0 * 150.0 - M_PI * 10.0 * 10.0, 0.04 * M_PI * 10.0 * 10.0);
}

TEST(CompositeIslands, ConcentricCreasesAroundAHoleAreJoinedByRadialRulingsIntoStrips) {
  // Tang et al. Fig. 1's annulus as a drawing: a round sheet, a hole, three concentric creases.
  std::ostringstream e;
  e << R"(<circle cx="100" cy="100" r="75" fill="none" stroke="#ff0000" stroke-opacity="0.3"/>)"
    << R"(<circle cx="100" cy="100" r="60" fill="none" stroke="#0000ff" stroke-opacity="0.3"/>)"
    << R"(<circle cx="100" cy="100" r="45" fill="none" stroke="#ff0000" stroke-opacity="0.3"/>)"
    << R"(<circle cx="100" cy="100" r="30" fill="none" stroke="#000000"/>)";
  const std::string text = R"(<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="200mm" viewBox="0 0 200 200">)"
                           R"(<circle cx="100" cy="100" r="90" fill="none" stroke="#000000"/>)" +
                           e.str() + "</svg>";
  const io::SvgImport svg = io::importSvgText(text);
  EXPECT_NEAR(patternArea(svg.pattern), M_PI * (90.0 * 90.0 - 30.0 * 30.0), 0.01 * M_PI * 90.0 * 90.0);
  // Every bridge runs across the rings radially (within 10°: it may end on a corner of the sampled
  // circle).
  const Eigen::Vector2d centre =
      0.5 * (svg.pattern.vertices2d.colwise().minCoeff() + svg.pattern.vertices2d.colwise().maxCoeff()).transpose();
  int bridges = 0;
  for (const io::CreaseEdge& edge : svg.pattern.edges) {
    if (!edge.proposed) continue;
    ++bridges;
    const Eigen::Vector2d a = svg.pattern.vertices2d.row(edge.v0), b = svg.pattern.vertices2d.row(edge.v1);
    const Eigen::Vector2d along = (b - a).normalized(), radial = (0.5 * (a + b) - centre).normalized();
    EXPECT_GT(std::abs(along.dot(radial)), std::cos(10.0 * M_PI / 180.0)) << a.transpose() << " → " << b.transpose() << " centre " << centre.transpose();
  }
  EXPECT_EQ(bridges, 2 * 4);  // three closed creases and the hole's outline: four islands
  const CreasePatternComposite c = compositeFromCreasePattern(svg.pattern);
  const CompositeTopology topology(c.design);
  int strips = 0;
  for (int f = 0; f < topology.numFaces(); ++f) strips += topology.face(f).type == FaceType::Strip ? 1 : 0;
  EXPECT_EQ(strips, topology.numFaces());
  CompositeModel model(c.design);
  EXPECT_LT(model.developmentLengthError(), 1e-4);  // it starts isometric to the drawing
}

TEST(CompositeIslands, AClosedCurvedCreaseWithNothingStraightInsideIsRefusedSayingWhatToDraw) {
  const io::SvgImport svg = io::importSvgText(
      islandSheetSvg(200, 200, R"(<circle cx="100" cy="100" r="50" fill="none" stroke="#0000ff" stroke-opacity="0.3"/>)"));
  try {
    compositeFromCreasePattern(svg.pattern);
    FAIL() << "a disk inside a closed crease has no ruling layout";
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("faces["), std::string::npos) << message;
    EXPECT_NE(message.find("closed curved crease"), std::string::npos) << message;
    EXPECT_NE(message.find("outline it (black in an SVG"), std::string::npos) << message;
  }
}

// Property: 120 random drawings, 1–2 curved creases across a 200 × 100 mm sheet and a round or
// square hole of random size anywhere that does not touch a crease. Each imports into a composite
// whose faces the topology accepts, without the hole (area from the pattern's polygons), and that
// starts isometric to the drawing and flat. Refusals are counted and must stay rare (a face the
// ruling layout cannot fill is refused by name rather than built folded over).
TEST(CompositeIslandsProperty, RandomSheetsWithAHoleImportWithoutIt) {
  std::mt19937 rng(20261205);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int built = 0, refused = 0;
  for (int trial = 0; trial < 120; ++trial) {
    const int creases = 1 + trial % 2;
    std::ostringstream elements;
    std::vector<double> lanes;
    for (int k = 0; k < creases; ++k) {
      const double x0 = 200.0 * (k + 1) / (creases + 1) + 20 * (u(rng) - 0.5), x3 = x0 + 30 * (u(rng) - 0.5);
      const double bend = 40 * (u(rng) - 0.5);
      elements << "<path d=\"M " << x0 << " 100 C " << x0 + bend << " 66, " << x3 - bend << " 33, " << x3
               << " 0\" fill=\"none\" stroke=\"" << (u(rng) < 0.5 ? "#ff0000" : "#0000ff") << "\" stroke-opacity=\"0.4\"/>";
      lanes.push_back(std::min(x0, x3) - 25.0);
      lanes.push_back(std::max(x0, x3) + 25.0);
    }
    // The hole in the widest gap between the creases' lanes (x) and the sheet's edges.
    std::vector<double> bounds{0.0};
    bounds.insert(bounds.end(), lanes.begin(), lanes.end());
    bounds.push_back(200.0);
    double gapStart = 0.0, gapWidth = 0.0;
    for (std::size_t i = 0; i + 1 < bounds.size(); i += 2)
      if (bounds[i + 1] - bounds[i] > gapWidth) {
        gapStart = bounds[i];
        gapWidth = bounds[i + 1] - bounds[i];
      }
    const double size = std::min(gapWidth, 80.0) * (0.25 + 0.45 * u(rng));
    const double cx = gapStart + 0.5 * gapWidth, cy = 50.0 + (80.0 - size) * (u(rng) - 0.5) * 0.8;
    double holeArea = 0.0;
    if (trial % 3 == 0) {
      elements << "<rect x=\"" << cx - size / 2 << "\" y=\"" << cy - size / 2 << "\" width=\"" << size << "\" height=\"" << size
               << "\" fill=\"none\" stroke=\"#000000\"/>";
      holeArea = size * size;
    } else {
      elements << "<circle cx=\"" << cx << "\" cy=\"" << cy << "\" r=\"" << size / 2 << "\" fill=\"none\" stroke=\"#000000\"/>";
      holeArea = M_PI * size * size / 4;
    }
    const std::string text = islandSheetSvg(200, 100, elements.str());
    SCOPED_TRACE(text);
    const io::SvgImport svg = io::importSvgText(text);
    EXPECT_NEAR(patternArea(svg.pattern), 200.0 * 100.0 - holeArea, 0.01 * holeArea);
    CreasePatternComposite c;
    try {
      c = compositeFromCreasePattern(svg.pattern);
    } catch (const std::invalid_argument& e) {
      ++refused;
      EXPECT_NE(std::string(e.what()).find("faces["), std::string::npos) << e.what();  // says which face
      continue;
    }
    ++built;
    ASSERT_NO_THROW(CompositeTopology topology(c.design));
    CompositeModel model(c.design);
    EXPECT_LT(model.developmentLengthError(), 1e-4);
    EXPECT_LT(model.quality().faceFlatnessMax, 1e-9);  // the sheet as imported lies flat
    // The model's curves are splines fitted to the sampled strokes (6–8 control points a side): a
    // round hole's arcs come out up to 3 % smaller in area (measured 2.7 % at most here); with a
    // square hole only the creases' chords count (measured 0.004 mm² at most).
    EXPECT_NEAR(patternArea(model.creasePattern()), 200.0 * 100.0 - holeArea, trial % 3 == 0 ? 0.02 : 0.04 * holeArea);
  }
  RecordProperty("built", built);
  RecordProperty("refused", refused);
  // Measured: 100 built, 20 refused — no ruling from a corner, or rulings that would cross in a
  // strip between a hole's side and a much longer run of outline and crease (small holes near the
  // sheet's edge). Each refusal names its face and says what to draw.
  EXPECT_GE(built, 95) << refused << " of 120 refused";
}

}  // namespace
}  // namespace devsurf::models::composite
