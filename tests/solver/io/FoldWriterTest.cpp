#include "devsurf/io/FoldWriter.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace devsurf::io {
namespace {

using nlohmann::json;

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("devsurf_fold_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

/// Two triangles sharing the edge (1,0)–(1,1); the right one is folded up by 90° (a valley fold:
/// it turns towards the front side, +z, of the left one).
///
///   2
///   |\.
///   | \ .
///   0--1--3      folded: 3 → (1, 0, 1)
CreasePattern twoTriangles(EdgeAssignment fold = EdgeAssignment::Valley,
                           std::optional<double> angle = 90.0) {
  CreasePattern p;
  p.title = "two triangles";
  p.vertices2d.resize(4, 2);
  p.vertices2d << 0, 0, 1, 0, 1, 1, 2, 0;
  p.vertices3d.resize(4, 3);
  const double z = fold == EdgeAssignment::Mountain ? -1.0 : 1.0;
  p.vertices3d << 0, 0, 0, 1, 0, 0, 1, 1, 0, 1, 0, z;
  p.unitToMm = 10.0;
  p.edges = {{0, 1, EdgeAssignment::Boundary, std::nullopt, -1},
             {1, 3, EdgeAssignment::Boundary, std::nullopt, -1},
             {3, 2, EdgeAssignment::Boundary, std::nullopt, -1},
             {2, 0, EdgeAssignment::Boundary, std::nullopt, -1},
             {1, 2, fold, angle, -1}};
  p.faces = {{0, 1, 2}, {1, 3, 2}};
  return p;
}

/// A strip with a curved mountain crease (curve 0, three edges) and a straight valley (curve 1).
CreasePattern curvedStrip() {
  CreasePattern p;
  p.title = "strip";
  p.vertices2d.resize(8, 2);
  p.vertices2d << 0, 0, 3, 0, 3, 2, 0, 2,  // boundary corners
      0, 1, 1, 1.25, 2, 1.25, 3, 1;        // crease 4-5-6-7
  p.vertices3d.resize(8, 3);
  p.vertices3d << 0, 0, 0, 3, 0, 0, 3, 2, 0.5, 0, 2, 0.5, 0, 1, 0, 1, 1.25, 0, 2, 1.25, 0, 3, 1,
      0;
  p.unitToMm = 2.0;
  p.edges = {{0, 1, EdgeAssignment::Boundary, std::nullopt, -1},
             {1, 7, EdgeAssignment::Boundary, std::nullopt, -1},
             {7, 2, EdgeAssignment::Boundary, std::nullopt, -1},
             {2, 3, EdgeAssignment::Boundary, std::nullopt, -1},
             {3, 4, EdgeAssignment::Boundary, std::nullopt, -1},
             {4, 0, EdgeAssignment::Cut, std::nullopt, -1},
             {4, 5, EdgeAssignment::Mountain, -30.0, 0},
             {5, 6, EdgeAssignment::Mountain, -32.5, 0},
             {6, 7, EdgeAssignment::Mountain, -30.0, 0},
             {0, 6, EdgeAssignment::Valley, 12.0, 1},
             {5, 3, EdgeAssignment::Flat, std::nullopt, -1}};
  p.faces = {{0, 1, 7, 6, 5, 4}, {4, 5, 6, 7, 2, 3}};
  CreaseCurve c;
  c.id = 0;
  c.degree = 2;
  c.knots = {0, 0, 0, 0.5, 1, 1, 1};
  c.controlPoints.resize(4, 3);
  c.controlPoints << 0, 1, 0, 1, 1.3, 0.1, 2, 1.3, 0.1, 3, 1, 0;
  c.weights = {1, 0.75, 0.75, 1};
  CreaseCurve d;
  d.id = 1;
  d.degree = 1;
  d.knots = {0, 0, 1, 1};
  d.controlPoints.resize(2, 3);
  d.controlPoints << 0, 0, 0, 2, 1.25, 0;
  p.curves = {c, d};
  p.rulings.resize(2, 4);
  p.rulings << 1, 1.25, 1, 2, 2, 1.25, 2, 2;
  return p;
}

TEST(FoldWriter, TwoTriangleValleySheetGivesExactlyTheExpectedArrays) {
  const json doc = json::parse(foldString(twoTriangles()));
  const json expected = json::parse(R"json({
    "file_spec": 1.2,
    "file_creator": "devsurf",
    "file_title": "two triangles",
    "file_classes": ["singleModel"],
    "frame_title": "two triangles (crease pattern)",
    "frame_classes": ["creasePattern"],
    "frame_attributes": ["2D", "noCuts"],
    "frame_unit": "cm",
    "vertices_coords": [[0, 0], [1, 0], [1, 1], [2, 0]],
    "edges_vertices": [[0, 1], [1, 3], [3, 2], [2, 0], [1, 2]],
    "edges_assignment": ["B", "B", "B", "B", "V"],
    "edges_foldAngle": [0, 0, 0, 0, 90],
    "faces_vertices": [[0, 1, 2], [1, 3, 2]],
    "devsurf:unitToMm": 10,
    "file_frames": [{
      "frame_title": "two triangles (folded form)",
      "frame_classes": ["foldedForm"],
      "frame_attributes": ["3D", "noCuts"],
      "frame_parent": 0,
      "frame_inherit": true,
      "frame_unit": "cm",
      "vertices_coords": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 0, 1]]
    }]
  })json");
  EXPECT_EQ(doc, expected) << doc.dump(1);
}

TEST(FoldWriter, OutputParsesAsJsonWithTheRequiredKeys) {
  const std::string text = foldString(curvedStrip());
  json doc;
  ASSERT_NO_THROW(doc = json::parse(text));
  for (const char* key :
       {"file_spec", "file_creator", "file_classes", "frame_title", "frame_classes", "frame_unit",
        "vertices_coords", "edges_vertices", "edges_assignment", "edges_foldAngle",
        "faces_vertices", "file_frames"})
    EXPECT_TRUE(doc.contains(key)) << key;
  EXPECT_EQ(doc["file_spec"], 1.2);
  EXPECT_EQ(doc["file_creator"], "devsurf");
  EXPECT_EQ(doc["file_classes"], json::array({"singleModel"}));
  EXPECT_EQ(doc["frame_classes"], json::array({"creasePattern"}));
  EXPECT_EQ(doc["frame_unit"], "mm");
  EXPECT_EQ(doc["edges_vertices"].size(), doc["edges_assignment"].size());
  EXPECT_EQ(doc["edges_vertices"].size(), doc["edges_foldAngle"].size());
  // One-line output parses too.
  FoldWriteOptions compact;
  compact.indent = -1;
  compact.author = "someone";
  const std::string line = foldString(curvedStrip(), compact);
  EXPECT_EQ(line.find('\n'), line.size() - 1);
  EXPECT_EQ(json::parse(line)["file_author"], "someone");
}

TEST(FoldWriter, AssignmentsAndFoldAngleSignsAgree) {
  const json doc = foldDocument(curvedStrip());
  const json& a = doc["edges_assignment"];
  const json& f = doc["edges_foldAngle"];
  ASSERT_EQ(a.size(), 11u);
  int mountains = 0, valleys = 0;
  for (std::size_t e = 0; e < a.size(); ++e) {
    const std::string letter = a[e];
    const double angle = f[e];
    if (letter == "M") {
      EXPECT_LT(angle, 0.0) << e;
      ++mountains;
    } else if (letter == "V") {
      EXPECT_GT(angle, 0.0) << e;
      ++valleys;
    } else {
      EXPECT_EQ(angle, 0.0) << e;
      EXPECT_TRUE(letter == "B" || letter == "F" || letter == "C") << letter;
    }
    EXPECT_GE(angle, -180.0);
    EXPECT_LE(angle, 180.0);
  }
  EXPECT_EQ(mountains, 3);
  EXPECT_EQ(valleys, 1);
  EXPECT_EQ(a[5], "C");  // FOLD 1.2 cut assignment
  EXPECT_EQ(a[10], "F");
  EXPECT_EQ(doc["frame_attributes"], json::array({"2D", "cuts"}));
}

TEST(FoldWriter, FoldedFrameHasThreeDimensionalCoordinatesInMillimetres) {
  const CreasePattern p = curvedStrip();
  const json doc = foldDocument(p);
  ASSERT_TRUE(doc.contains("file_frames"));
  ASSERT_EQ(doc["file_frames"].size(), 1u);
  const json& folded = doc["file_frames"][0];
  EXPECT_EQ(folded["frame_classes"], json::array({"foldedForm"}));
  EXPECT_EQ(folded["frame_parent"], 0);
  EXPECT_EQ(folded["frame_inherit"], true);
  EXPECT_EQ(folded["frame_unit"], "mm");
  ASSERT_EQ(folded["vertices_coords"].size(), 8u);
  for (std::size_t i = 0; i < 8; ++i) {
    ASSERT_EQ(folded["vertices_coords"][i].size(), 3u);
    for (int d = 0; d < 3; ++d)
      EXPECT_DOUBLE_EQ(folded["vertices_coords"][i][d].get<double>(),
                       p.vertices3d(static_cast<Eigen::Index>(i), d) * 2.0);
  }
  for (const json& c : doc["vertices_coords"]) EXPECT_EQ(c.size(), 2u);

  // Without a folded state (or when switched off) there is a single frame.
  CreasePattern flat = p;
  flat.vertices3d.resize(0, 3);
  EXPECT_FALSE(foldDocument(flat).contains("file_frames"));
  FoldWriteOptions noFolded;
  noFolded.foldedFrame = false;
  EXPECT_FALSE(foldDocument(p, noFolded).contains("file_frames"));
}

TEST(FoldWriter, CurveDataRoundTripsThroughTheNamespacedKeys) {
  const CreasePattern p = curvedStrip();
  const json doc = foldDocument(p);
  ASSERT_TRUE(doc.contains("edges_devsurf:curve"));
  EXPECT_EQ(doc["edges_devsurf:curve"],
            json::parse("[null, null, null, null, null, null, 0, 0, 0, 1, null]"));
  ASSERT_TRUE(doc.contains("devsurf:curves"));
  ASSERT_EQ(doc["devsurf:curves"].size(), 2u);
  const json& c0 = doc["devsurf:curves"][0];
  EXPECT_EQ(c0["id"], 0);
  EXPECT_EQ(c0["degree"], 2);
  EXPECT_EQ(c0["knots"], json::parse("[0, 0, 0, 0.5, 1, 1, 1]"));
  EXPECT_EQ(c0["controlPoints"][1], json::parse("[2, 2.6, 0.2]"));  // × unitToMm = 2
  EXPECT_EQ(c0["weights"], json::parse("[1, 0.75, 0.75, 1]"));
  EXPECT_FALSE(doc["devsurf:curves"][1].contains("weights"));
  EXPECT_EQ(doc["devsurf:rulings"][0], json::parse("[[2, 2.5], [2, 4]]"));

  const CreasePattern back = parseFold(foldString(p));
  EXPECT_EQ(back.title, p.title);
  EXPECT_DOUBLE_EQ(back.unitToMm, 2.0);
  EXPECT_TRUE(back.vertices2d.isApprox(p.vertices2d, 1e-15));
  EXPECT_TRUE(back.vertices3d.isApprox(p.vertices3d, 1e-15));
  ASSERT_EQ(back.edges.size(), p.edges.size());
  for (std::size_t e = 0; e < p.edges.size(); ++e) {
    EXPECT_EQ(back.edges[e].v0, p.edges[e].v0);
    EXPECT_EQ(back.edges[e].v1, p.edges[e].v1);
    EXPECT_EQ(back.edges[e].assignment, p.edges[e].assignment) << e;
    EXPECT_EQ(back.edges[e].curve, p.edges[e].curve) << e;
    ASSERT_TRUE(back.edges[e].foldAngle.has_value());
    if (p.edges[e].foldAngle) {
      EXPECT_EQ(*back.edges[e].foldAngle, *p.edges[e].foldAngle);
    }
  }
  EXPECT_EQ(back.faces, p.faces);
  ASSERT_EQ(back.curves.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(back.curves[k].id, p.curves[k].id);
    EXPECT_EQ(back.curves[k].degree, p.curves[k].degree);
    EXPECT_EQ(back.curves[k].knots, p.curves[k].knots);
    EXPECT_EQ(back.curves[k].weights, p.curves[k].weights);
    EXPECT_TRUE(back.curves[k].controlPoints.isApprox(p.curves[k].controlPoints, 1e-15));
  }
  EXPECT_TRUE(back.rulings.isApprox(p.rulings, 1e-15));
}

TEST(FoldWriter, SmoothEdgesRoundTripOnFlatEdgesOnly) {
  // The shared diagonal flat and smooth: written as true, read back as proposed.
  CreasePattern p = twoTriangles(EdgeAssignment::Flat, 0.0);
  p.vertices3d.row(3) << 2, 0, 0;
  p.edges[4].proposed = true;
  const json doc = foldDocument(p);
  ASSERT_TRUE(doc.contains("edges_devsurf:smooth"));
  EXPECT_EQ(doc["edges_devsurf:smooth"], json({false, false, false, false, true}));
  EXPECT_TRUE(parseFold(foldString(p)).edges[4].proposed);
  // No edge smooth: no key.
  EXPECT_FALSE(foldDocument(twoTriangles()).contains("edges_devsurf:smooth"));
  // A valley marked smooth is read as the valley it is.
  json valley = foldDocument(twoTriangles());
  valley["edges_devsurf:smooth"] = {false, false, false, false, true};
  EXPECT_FALSE(readFoldDocument(valley).edges[4].proposed);
  // Entries that are not booleans, and arrays of another length, are refused naming the key.
  json bad = doc;
  bad["edges_devsurf:smooth"][1] = "yes";
  EXPECT_THROW(
      {
        try {
          readFoldDocument(bad);
        } catch (const std::invalid_argument& e) {
          EXPECT_NE(std::string(e.what()).find("edges_devsurf:smooth"), std::string::npos) << e.what();
          throw;
        }
      },
      std::invalid_argument);
  bad["edges_devsurf:smooth"] = {true};
  EXPECT_THROW(readFoldDocument(bad), std::invalid_argument);
}

TEST(FoldWriter, FoldAnglesAreMeasuredFromTheFoldedStateWhenNotGiven) {
  const json valley = foldDocument(twoTriangles(EdgeAssignment::Valley, std::nullopt));
  EXPECT_NEAR(valley["edges_foldAngle"][4].get<double>(), 90.0, 1e-12);
  const json mountain = foldDocument(twoTriangles(EdgeAssignment::Mountain, std::nullopt));
  EXPECT_EQ(mountain["edges_assignment"][4], "M");
  EXPECT_NEAR(mountain["edges_foldAngle"][4].get<double>(), -90.0, 1e-12);

  const auto measured = measuredFoldAngles(twoTriangles(EdgeAssignment::Mountain, std::nullopt));
  ASSERT_TRUE(measured[4].has_value());
  EXPECT_NEAR(*measured[4], -90.0, 1e-12);
  EXPECT_FALSE(measured[0].has_value());  // a boundary edge has one face

  // Neither given nor measurable: edges_foldAngle is left out rather than guessed.
  CreasePattern unknown = twoTriangles(EdgeAssignment::Valley, std::nullopt);
  unknown.vertices3d.resize(0, 3);
  const json doc = foldDocument(unknown);
  EXPECT_FALSE(doc.contains("edges_foldAngle"));
  EXPECT_EQ(doc["edges_assignment"][4], "V");
}

TEST(FoldWriter, InconsistentPatternsAreRejected) {
  CreasePattern p = twoTriangles(EdgeAssignment::Mountain, 30.0);  // mountain with a valley angle
  EXPECT_THROW(foldDocument(p), std::invalid_argument);
  p = twoTriangles(EdgeAssignment::Valley, -30.0);
  EXPECT_THROW(foldDocument(p), std::invalid_argument);
  p = twoTriangles();
  p.edges[0].foldAngle = 10.0;  // a boundary edge does not fold
  EXPECT_THROW(foldDocument(p), std::invalid_argument);
  p = twoTriangles(EdgeAssignment::Valley, 190.0);
  EXPECT_THROW(foldDocument(p), std::invalid_argument);
  p = twoTriangles();
  p.faces[1] = {1, 2, 3};  // clockwise
  EXPECT_THROW(foldDocument(p), std::invalid_argument);
  p = twoTriangles();
  p.edges[2].v1 = 4;
  EXPECT_THROW(foldDocument(p), std::invalid_argument);
  p = curvedStrip();
  p.curves[0].knots.pop_back();
  EXPECT_THROW(foldDocument(p), std::invalid_argument);
  EXPECT_THROW(parseFold("{\"vertices_coords\": [[0, 0]"), std::invalid_argument);
  EXPECT_THROW(parseFold(R"({"vertices_coords": [[0, 0], [1, 0]], "edges_vertices": [[0, 1]],
                             "edges_assignment": ["Q"]})"),
               std::invalid_argument);
}

TEST(FoldWriter, ReadsForeignUnitsAndUnassignedEdges) {
  const CreasePattern p = parseFold(R"({
    "file_spec": 1.2, "frame_unit": "cm",
    "vertices_coords": [[0, 0], [1, 0], [0, 1]],
    "edges_vertices": [[0, 1], [1, 2], [2, 0]],
    "edges_assignment": ["B", "U", "J"],
    "faces_vertices": [[0, 1, 2]]})");
  EXPECT_DOUBLE_EQ(p.unitToMm, 10.0);
  EXPECT_EQ(p.edges[1].assignment, EdgeAssignment::Flat);
  EXPECT_EQ(p.edges[2].assignment, EdgeAssignment::Flat);
  EXPECT_FALSE(p.edges[0].foldAngle.has_value());
  EXPECT_FALSE(p.hasFoldedState());
}

TEST(FoldWriter, AModelUnitFoldNamesIsTheFrameUnitWithCoordinatesAsTheyAre) {
  for (const auto& [mm, unit] : std::vector<std::pair<double, std::string>>{
           {1.0, "mm"}, {10.0, "cm"}, {1000.0, "m"}, {25.4, "in"}}) {
    CreasePattern p = twoTriangles();
    p.unitToMm = mm;
    const json doc = foldDocument(p);
    EXPECT_EQ(doc["frame_unit"], unit);
    EXPECT_EQ(doc["file_frames"][0]["frame_unit"], unit);
    EXPECT_EQ(doc["vertices_coords"], json::parse("[[0, 0], [1, 0], [1, 1], [2, 0]]")) << unit;
    EXPECT_EQ(doc["file_frames"][0]["vertices_coords"][3], json::parse("[1, 0, 1]")) << unit;
    EXPECT_EQ(doc["devsurf:unitToMm"], mm);
    const CreasePattern back = parseFold(foldString(p));
    EXPECT_DOUBLE_EQ(back.unitToMm, mm) << unit;
    EXPECT_TRUE(back.vertices2d.isApprox(p.vertices2d, 1e-15)) << unit;
    EXPECT_TRUE(back.vertices3d.isApprox(p.vertices3d, 1e-15)) << unit;
  }
  // A scale FOLD has no name for is written in millimetres.
  CreasePattern odd = twoTriangles();
  odd.unitToMm = 2.0;
  const json doc = foldDocument(odd);
  EXPECT_EQ(doc["frame_unit"], "mm");
  EXPECT_EQ(doc["vertices_coords"][3], json::parse("[4, 0]"));
}

TEST(FoldWriter, WritesAndReadsFiles) {
  const std::string path = tempPath("sheet.fold");
  writeFold(twoTriangles(), path);
  const CreasePattern back = readFold(path);
  EXPECT_EQ(back.edges[4].assignment, EdgeAssignment::Valley);
  EXPECT_EQ(*back.edges[4].foldAngle, 90.0);
  EXPECT_TRUE(back.vertices3d.isApprox(twoTriangles().vertices3d));
  std::remove(path.c_str());
  EXPECT_THROW(writeFold(twoTriangles(), "/nonexistent-dir/x.fold"), std::runtime_error);
  EXPECT_THROW(readFold("/nonexistent-dir/x.fold"), std::runtime_error);
}

}  // namespace
}  // namespace devsurf::io
