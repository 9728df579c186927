#include "devsurf/io/DxfDrawing.h"

#include <gtest/gtest.h>

#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace devsurf::io {
namespace {

/// A DXF read as its group-code/value pairs, and its entities of one section as lists of pairs.
struct DxfPairs {
  std::vector<std::pair<int, std::string>> pairs;

  explicit DxfPairs(const std::string& text) {
    std::istringstream in(text);
    std::string code, value;
    while (std::getline(in, code) && std::getline(in, value)) pairs.emplace_back(std::stoi(code), value);
  }
  /// The records (from one code-0 pair to the next) of type `type` in section `section`.
  std::vector<std::vector<std::pair<int, std::string>>> records(const std::string& section, const std::string& type) const {
    std::vector<std::vector<std::pair<int, std::string>>> out;
    std::string current;
    bool collecting = false;
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const auto& [code, text] = pairs[k];
      if (code != 0) {
        if (collecting) out.back().push_back(pairs[k]);
        continue;
      }
      collecting = false;
      if (text == "SECTION" && k + 1 < pairs.size()) current = pairs[k + 1].second;
      else if (text == "ENDSEC") current.clear();
      else if (current == section && text == type) {
        out.emplace_back();
        collecting = true;
      }
    }
    return out;
  }
  /// The value after header variable `name`.
  std::string header(const std::string& name) const {
    for (std::size_t k = 0; k + 1 < pairs.size(); ++k)
      if (pairs[k] == std::make_pair(9, name)) return pairs[k + 1].second;
    return "";
  }
};

std::string value(const std::vector<std::pair<int, std::string>>& record, int code) {
  for (const auto& [c, v] : record)
    if (c == code) return v;
  return "";
}

std::vector<double> values(const std::vector<std::pair<int, std::string>>& record, int code) {
  std::vector<double> out;
  for (const auto& [c, v] : record)
    if (c == code) out.push_back(std::stod(v));
  return out;
}

DxfDrawing square() {
  DxfDrawing d;
  d.title = "a square";
  d.layers = {{"CUT", 7, true, "CONTINUOUS", "cut"}, {"MESH", 8, false, "CONTINUOUS", "reference"}};
  d.polylines = {{"CUT", {{0, 0}, {10, 0}, {10, 10}, {0, 10}}, true}, {"MESH", {{0, 0}, {10, 10}}, false}};
  d.texts = {{"CUT", {5, 5}, 2.5, "1"}};
  return d;
}

TEST(DxfDrawing, IsInMillimetresWithItsLayersPolylinesAndTextsAsGiven) {
  const DxfPairs dxf(dxfDocument(square()));
  EXPECT_EQ(dxf.header("$ACADVER"), "AC1015");
  EXPECT_EQ(dxf.header("$INSUNITS"), "4");
  const auto layers = dxf.records("TABLES", "LAYER");
  std::map<std::string, int> colour;
  for (const auto& layer : layers) colour[value(layer, 2)] = std::stoi(value(layer, 62));
  EXPECT_EQ(colour.at("CUT"), 7);
  EXPECT_EQ(colour.at("MESH"), -8) << "an invisible layer is off: a negative colour";
  EXPECT_TRUE(colour.count("0"));
  const auto polylines = dxf.records("ENTITIES", "LWPOLYLINE");
  ASSERT_EQ(polylines.size(), 2u);
  EXPECT_EQ(value(polylines[0], 8), "CUT");
  EXPECT_EQ(value(polylines[0], 70), "1") << "closed";
  EXPECT_EQ(values(polylines[0], 10), (std::vector<double>{0, 10, 10, 0}));
  EXPECT_EQ(values(polylines[0], 20), (std::vector<double>{0, 0, 10, 10}));
  EXPECT_EQ(value(polylines[1], 70), "0");
  const auto texts = dxf.records("ENTITIES", "TEXT");
  ASSERT_EQ(texts.size(), 1u);
  EXPECT_EQ(value(texts[0], 1), "1");
  EXPECT_EQ(values(texts[0], 40), (std::vector<double>{2.5}));
}

TEST(DxfDrawing, BadEntitiesAndLayersAreRefusedNamingThem) {
  auto message = [](const DxfDrawing& d) {
    try {
      dxfDocument(d);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  DxfDrawing d = square();
  d.polylines[1].layer = "FOLDS";
  EXPECT_NE(message(d).find("polyline 1: unknown layer \"FOLDS\""), std::string::npos) << message(d);
  d = square();
  d.polylines[0].points.resize(1);
  EXPECT_NE(message(d).find("polyline 0"), std::string::npos);
  d = square();
  d.polylines[0].points[2].x() = NAN;
  EXPECT_NE(message(d).find("polyline 0"), std::string::npos);
  d = square();
  d.layers[0].name = "cut lines";
  EXPECT_NE(message(d).find("layer name"), std::string::npos);
  d = square();
  d.layers[1].colour = 0;
  EXPECT_NE(message(d).find("layer MESH: colour"), std::string::npos);
  d = square();
  d.texts[0].text = "two\nlines";
  EXPECT_NE(message(d).find("text 0"), std::string::npos);
}

/// A unit square sheet split by a valley diagonal 0–2, at 10 mm per unit.
CreasePattern foldedSquare() {
  CreasePattern cp;
  cp.title = "square";
  cp.unitToMm = 10.0;
  cp.vertices2d.resize(4, 2);
  cp.vertices2d << 0, 0, 1, 0, 1, 1, 0, 1;
  cp.edges = {{0, 1, EdgeAssignment::Boundary}, {1, 2, EdgeAssignment::Boundary}, {2, 3, EdgeAssignment::Boundary},
              {3, 0, EdgeAssignment::Boundary}, {0, 2, EdgeAssignment::Valley}};
  cp.faces = {{0, 1, 2}, {0, 2, 3}};
  cp.rulings.resize(1, 4);
  cp.rulings << 0.5, 0.0, 1.0, 0.5;
  return cp;
}

TEST(DxfDrawing, ACreasePatternIsItsOutlineToCutItsFoldsToScoreAndItsRulingsOff) {
  const DxfDrawing d = creasePatternDrawing(foldedSquare());
  std::map<std::string, int> count;
  for (const DxfPolyline& p : d.polylines) ++count[p.layer];
  EXPECT_EQ(count["CUT"], 1) << "the boundary is one closed outline";
  EXPECT_EQ(count["VALLEY"], 1);
  EXPECT_EQ(count["MOUNTAIN"], 0);
  EXPECT_EQ(count["RULINGS"], 1);
  for (const DxfPolyline& p : d.polylines) {
    if (p.layer == "CUT") {
      EXPECT_TRUE(p.closed);
      ASSERT_EQ(p.points.size(), 4u) << "no vertex repeated";
      EXPECT_NEAR((p.points[2] - p.points[0]).norm(), std::sqrt(200.0), 1e-12) << "in millimetres";
    }
    if (p.layer == "VALLEY") {
      ASSERT_EQ(p.points.size(), 2u);
      EXPECT_NEAR((p.points[1] - p.points[0]).norm(), std::sqrt(200.0), 1e-12);
    }
  }
  std::vector<std::string> layers;
  for (const DxfLayer& l : d.layers) layers.push_back(l.name);
  EXPECT_EQ(layers, (std::vector<std::string>{"CUT", "VALLEY", "RULINGS"})) << "only the layers in use";
  EXPECT_FALSE(d.layers[2].visible);
  EXPECT_NO_THROW(dxfDocument(d));
}

TEST(DxfDrawing, ACuttingPatternCutsItsOutlineAndNumbersBothSidesOfEachSeam) {
  // Two unit squares side by side in the unfolding, 0.5 apart; edge 1–2 of the left one is glued
  // to edge 4–7 of the right one (1 ~ 4, 2 ~ 7).
  Eigen::MatrixXd V(8, 2);
  V << 0, 0, 1, 0, 1, 1, 0, 1, 1.5, 0, 2.5, 0, 2.5, 1, 1.5, 1;
  const std::vector<PolygonFace> faces = {{{0, 1, 2, 3}}, {{4, 5, 6, 7}}};
  const DxfDrawing d = cuttingPatternDrawing(V, faces, {{{1, 4}}, {{2, 7}}}, 20.0, 4.0);
  std::map<std::string, int> count;
  double cutLength = 0.0;
  for (const DxfPolyline& p : d.polylines) {
    ++count[p.layer];
    if (p.layer == "CUT")
      for (std::size_t k = 0; k + 1 < p.points.size(); ++k) cutLength += (p.points[k + 1] - p.points[k]).norm();
  }
  EXPECT_EQ(count["GLUE"], 2) << "one chain per side of the seam";
  EXPECT_EQ(count["MESH"], 0) << "no mesh unless asked";
  EXPECT_NEAR(cutLength, 6 * 20.0, 1e-9) << "three open sides of each square, in mm";
  ASSERT_EQ(d.texts.size(), 2u);
  EXPECT_EQ(d.texts[0].text, "1");
  EXPECT_EQ(d.texts[1].text, "1");
  EXPECT_DOUBLE_EQ(d.texts[0].height, 4.0);
  // Each number sits inside its own square.
  const Eigen::Vector2d left = d.texts[0].position / 20.0, right = d.texts[1].position / 20.0;
  EXPECT_TRUE((left.x() > 0 && left.x() < 1) != (right.x() > 0 && right.x() < 1));
  EXPECT_THROW(cuttingPatternDrawing(V, faces, {}, 0.0), std::invalid_argument);
  EXPECT_THROW(cuttingPatternDrawing(V, faces, {{{1, 9}}}, 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::io
