// DXF fabrication drawings (issue 16 item 5) written through Debian's dxflib (libdxflib-dev).
#include "devsurf/io/DxfDrawing.h"
#include "devsurf/io/OneLine.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

#include <dl_dxf.h>
#include <dl_writer_ascii.h>

#include "devsurf/io/GlueSeams.h"

namespace devsurf::io {
namespace {

/// dxflib's ASCII writer with its group-code/value pairs kept in memory instead of a file (the
/// base class opens /dev/null; every write goes through the virtuals overridden here). dxflib
/// writes a layer's colour without its sign; layers named in `offLayers` get theirs negated in the
/// layer table (a negative colour is how DXF marks a layer off).
class DxfStringWriter : public DL_WriterA {
 public:
  DxfStringWriter() : DL_WriterA("/dev/null", DL_Codes::AC1015) {}

  std::set<std::string> offLayers;
  bool inLayerTable = false;

  void dxfReal(int gc, double value) const override {
    char text[64];
    std::snprintf(text, sizeof text, "%.10f", value);
    std::string s(text);
    // Trailing zeros off, one digit after the point kept ("12.5", "3.0").
    const std::size_t point = s.find('.');
    if (point != std::string::npos) {
      std::size_t last = s.find_last_not_of('0');
      if (last == point) ++last;
      s.erase(last + 1);
    }
    if (s == "-0.0") s = "0.0";
    pair(gc, s);
  }
  void dxfInt(int gc, int value) const override {
    if (inLayerTable && gc == 62 && offLayers.count(lastName_)) value = -std::abs(value);
    pair(gc, std::to_string(value));
  }
  void dxfHex(int gc, int value) const override {
    char text[32];
    std::snprintf(text, sizeof text, "%0X", static_cast<unsigned>(value));
    pair(gc, text);
  }
  void dxfString(int gc, const char* value) const override { dxfString(gc, std::string(value ? value : "")); }
  void dxfString(int gc, const std::string& value) const override {
    if (gc == 2) lastName_ = value;
    pair(gc, value);
  }

  std::string text() const { return out_.str(); }

 private:
  void pair(int gc, const std::string& value) const {
    // Group codes right-aligned in three columns, as AutoCAD writes them.
    out_ << (gc < 10 ? "  " : (gc < 100 ? " " : "")) << gc << "\n" << value << "\n";
  }
  mutable std::ostringstream out_;
  mutable std::string lastName_;  ///< the last name (group code 2) written
};

bool validLayerName(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  for (const char c : name)
    if (!((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_')) return false;
  return true;
}

}  // namespace

std::string dxfDocument(const DxfDrawing& drawing) {
  std::map<std::string, const DxfLayer*> layerByName;
  for (const DxfLayer& layer : drawing.layers) {
    if (!validLayerName(layer.name))
      throw std::invalid_argument("dxf: layer name \"" + layer.name + "\" must be 1–64 of A–Z, 0–9 and _");
    if (layer.colour < 1 || layer.colour > 255)
      throw std::invalid_argument("dxf: layer " + layer.name + ": colour must lie in [1, 255]");
    if (layer.lineType != "CONTINUOUS" && layer.lineType != "DASHED" && layer.lineType != "DASHDOT")
      throw std::invalid_argument("dxf: layer " + layer.name + ": line type must be CONTINUOUS, DASHED or DASHDOT");
    if (!layerByName.emplace(layer.name, &layer).second)
      throw std::invalid_argument("dxf: layer " + layer.name + " is defined twice");
  }
  for (std::size_t k = 0; k < drawing.polylines.size(); ++k) {
    const DxfPolyline& p = drawing.polylines[k];
    const std::string what = "dxf: polyline " + std::to_string(k);
    if (!layerByName.count(p.layer)) throw std::invalid_argument(what + ": unknown layer \"" + p.layer + "\"");
    if (p.points.size() < 2) throw std::invalid_argument(what + ": needs at least two points");
    for (const Eigen::Vector2d& q : p.points)
      if (!q.allFinite()) throw std::invalid_argument(what + ": every coordinate must be finite");
  }
  for (std::size_t k = 0; k < drawing.texts.size(); ++k) {
    const DxfText& t = drawing.texts[k];
    const std::string what = "dxf: text " + std::to_string(k);
    if (!layerByName.count(t.layer)) throw std::invalid_argument(what + ": unknown layer \"" + t.layer + "\"");
    if (!t.position.allFinite() || !(std::isfinite(t.height) && t.height > 0.0))
      throw std::invalid_argument(what + ": position must be finite and height positive");
    if (t.text.empty() || t.text.find_first_of("\r\n") != std::string::npos)
      throw std::invalid_argument(what + ": one non-empty line of text expected");
  }

  // The writing sequence of dxflib's programmer's guide for AutoCAD 2000 files.
  DL_Dxf dxf;
  DxfStringWriter dw;
  dxf.writeComment(dw, "devsurf: " + (drawing.title.empty() ? std::string("fabrication drawing") : oneLine(drawing.title)) +
                           "; units: millimetres");
  for (const DxfLayer& layer : drawing.layers)
    if (!layer.description.empty()) dxf.writeComment(dw, oneLine("layer " + layer.name + ": " + layer.description));
  dxf.writeHeader(dw);
  dw.dxfString(9, "$INSUNITS");
  dw.dxfInt(70, 4);  // millimetres
  dw.dxfString(9, "$MEASUREMENT");
  dw.dxfInt(70, 1);  // metric
  dw.sectionEnd();

  dw.sectionTables();
  dxf.writeVPort(dw);
  double dashed[2] = {5.0, -2.5};
  double dashDot[4] = {6.0, -1.5, 0.0, -1.5};
  dw.tableLinetypes(5);
  dxf.writeLinetype(dw, DL_LinetypeData("BYBLOCK", "", 0, 0, 0.0));
  dxf.writeLinetype(dw, DL_LinetypeData("BYLAYER", "", 0, 0, 0.0));
  dxf.writeLinetype(dw, DL_LinetypeData("CONTINUOUS", "Solid line", 0, 0, 0.0));
  dxf.writeLinetype(dw, DL_LinetypeData("DASHED", "Dashed __ __ __", 0, 2, 7.5, dashed));
  dxf.writeLinetype(dw, DL_LinetypeData("DASHDOT", "Dash dot __ . __ .", 0, 4, 9.0, dashDot));
  dw.tableEnd();
  for (const DxfLayer& layer : drawing.layers)
    if (!layer.visible) dw.offLayers.insert(layer.name);
  dw.inLayerTable = true;
  dw.tableLayers(static_cast<int>(drawing.layers.size()) + 1);
  dxf.writeLayer(dw, DL_LayerData("0", 0), DL_Attributes("", 7, 0, "CONTINUOUS", 1.0));
  for (const DxfLayer& layer : drawing.layers)
    dxf.writeLayer(dw, DL_LayerData(layer.name, 0), DL_Attributes("", layer.colour, 0, layer.lineType, 1.0));
  dw.tableEnd();
  dw.inLayerTable = false;
  dw.tableStyle(1);
  dxf.writeStyle(dw, DL_StyleData("standard", 0, 0.0, 1.0, 0.0, 0, 2.5, "txt", ""));
  dw.tableEnd();
  dxf.writeView(dw);
  dxf.writeUcs(dw);
  dw.tableAppid(1);
  dxf.writeAppid(dw, "ACAD");
  dw.tableEnd();
  dxf.writeDimStyle(dw, 1.0, 1.0, 1.0, 1.0, 1.0);
  dxf.writeBlockRecord(dw);
  dw.tableEnd();
  dw.sectionEnd();

  dw.sectionBlocks();
  dxf.writeBlock(dw, DL_BlockData("*Model_Space", 0, 0.0, 0.0, 0.0));
  dxf.writeEndBlock(dw, "*Model_Space");
  dxf.writeBlock(dw, DL_BlockData("*Paper_Space", 0, 0.0, 0.0, 0.0));
  dxf.writeEndBlock(dw, "*Paper_Space");
  dxf.writeBlock(dw, DL_BlockData("*Paper_Space0", 0, 0.0, 0.0, 0.0));
  dxf.writeEndBlock(dw, "*Paper_Space0");
  dw.sectionEnd();

  dw.sectionEntities();
  for (const DxfPolyline& p : drawing.polylines) {
    const DL_Attributes attributes(p.layer, 256, 0, "BYLAYER", 1.0);  // colour and line type by layer
    dxf.writePolyline(dw, DL_PolylineData(static_cast<int>(p.points.size()), 0, 0, p.closed ? 1 : 0), attributes);
    for (const Eigen::Vector2d& q : p.points) dxf.writeVertex(dw, DL_VertexData(q.x(), q.y(), 0.0, 0.0));
    dxf.writePolylineEnd(dw);
  }
  for (const DxfText& t : drawing.texts) {
    const DL_Attributes attributes(t.layer, 256, 0, "BYLAYER", 1.0);
    // Horizontal justification 1 (centre) and vertical 2 (middle): the alignment point is the centre.
    dxf.writeText(dw,
                  DL_TextData(t.position.x(), t.position.y(), 0.0, t.position.x(), t.position.y(), 0.0, t.height, 1.0,
                              0, 1, 2, t.text, "standard", 0.0),
                  attributes);
  }
  dw.sectionEnd();
  dxf.writeObjects(dw);
  dxf.writeObjectsEnd(dw);
  dw.dxfEOF();
  return dw.text();
}

std::vector<DxfLayer> fabricationLayers() {
  return {
      {"CUT", 7, true, "CONTINUOUS", "outline of the sheet and slits: cut through"},
      {"MOUNTAIN", 1, true, "DASHDOT", "mountain folds: score on the back"},
      {"VALLEY", 5, true, "DASHED", "valley folds: score on the front"},
      {"GLUE", 3, true, "CONTINUOUS", "edges glued to another after cutting: cut through as well"},
      {"LABEL", 3, true, "CONTINUOUS", "seam numbers: edges with the same number are glued together; do not cut"},
      {"RULINGS", 8, false, "CONTINUOUS", "rulings of the developable surface: reference only"},
      {"MESH", 8, false, "CONTINUOUS", "interior mesh edges: reference only"},
  };
}

namespace {

/// The fabrication layers the drawing's entities are on, in fabricationLayers' order.
std::vector<DxfLayer> layersUsed(const DxfDrawing& drawing) {
  std::set<std::string> used;
  for (const DxfPolyline& p : drawing.polylines) used.insert(p.layer);
  for (const DxfText& t : drawing.texts) used.insert(t.layer);
  std::vector<DxfLayer> out;
  for (const DxfLayer& layer : fabricationLayers())
    if (used.count(layer.name)) out.push_back(layer);
  return out;
}

/// Links segments (vertex pairs) into maximal chains, broken where a vertex does not have exactly
/// two of them: per chain its vertices in order (a closed chain does not repeat its first).
std::vector<std::pair<std::vector<int>, bool>> chainSegments(const std::vector<std::array<int, 2>>& segments) {
  std::map<int, std::vector<int>> segmentsAt;
  for (std::size_t k = 0; k < segments.size(); ++k)
    for (const int v : segments[k]) segmentsAt[v].push_back(static_cast<int>(k));
  std::vector<bool> used(segments.size(), false);
  std::vector<std::pair<std::vector<int>, bool>> chains;
  auto walk = [&segments, &segmentsAt, &used](int k, int from, std::vector<int>& vertices) {
    int v = from;
    while (true) {
      used[static_cast<std::size_t>(k)] = true;
      const auto& seg = segments[static_cast<std::size_t>(k)];
      v = seg[0] == v ? seg[1] : seg[0];
      vertices.push_back(v);
      const std::vector<int>& next = segmentsAt[v];
      if (next.size() != 2) return;
      const int n = next[0] == k ? next[1] : next[0];
      if (used[static_cast<std::size_t>(n)]) return;
      k = n;
    }
  };
  // Open chains first, from their ends; then the closed loops that remain.
  for (const auto& [v, at] : segmentsAt) {
    if (at.size() == 2) continue;
    for (const int k : at) {
      if (used[static_cast<std::size_t>(k)]) continue;
      std::vector<int> vertices{v};
      walk(k, v, vertices);
      chains.emplace_back(std::move(vertices), false);
    }
  }
  for (std::size_t k = 0; k < segments.size(); ++k) {
    if (used[k]) continue;
    std::vector<int> vertices{segments[k][0]};
    walk(static_cast<int>(k), segments[k][0], vertices);
    const bool closed = vertices.size() > 2 && vertices.back() == vertices.front();
    if (closed) vertices.pop_back();
    chains.emplace_back(std::move(vertices), closed);
  }
  return chains;
}

}  // namespace

DxfDrawing creasePatternDrawing(const CreasePattern& pattern) {
  pattern.validate();
  const double s = pattern.unitToMm;
  DxfDrawing drawing;
  drawing.title = pattern.title.empty() ? std::string("crease pattern") : pattern.title;
  auto at = [&pattern, s](int v) { return Eigen::Vector2d(pattern.vertices2d.row(v).transpose() * s); };
  for (const EdgeChain& chain : edgeChains(pattern)) {
    const char* layer = nullptr;
    switch (chain.assignment) {
      case EdgeAssignment::Boundary:
      case EdgeAssignment::Cut: layer = "CUT"; break;
      case EdgeAssignment::Mountain: layer = "MOUNTAIN"; break;
      case EdgeAssignment::Valley: layer = "VALLEY"; break;
      case EdgeAssignment::Flat: break;
    }
    if (!layer) continue;
    DxfPolyline line{layer, {}, chain.closed};
    for (const int v : chain.vertices) line.points.push_back(at(v));
    drawing.polylines.push_back(std::move(line));
  }
  for (Eigen::Index r = 0; r < pattern.rulings.rows(); ++r)
    drawing.polylines.push_back({"RULINGS",
                                 {Eigen::Vector2d(pattern.rulings(r, 0), pattern.rulings(r, 1)) * s,
                                  Eigen::Vector2d(pattern.rulings(r, 2), pattern.rulings(r, 3)) * s},
                                 false});
  drawing.layers = layersUsed(drawing);
  return drawing;
}

DxfDrawing cuttingPatternDrawing(const Eigen::MatrixXd& unfolding, const std::vector<PolygonFace>& faces,
                                 const std::vector<std::array<int, 2>>& gluePairs, double mmPerUnit,
                                 double labelHeightMm, bool drawMesh) {
  const Eigen::MatrixXd& V = unfolding;
  if (V.cols() != 2 && V.cols() != 3) throw std::invalid_argument("cutting pattern: the unfolding must have 2 or 3 columns");
  if (!V.allFinite()) throw std::invalid_argument("cutting pattern: the unfolding must be finite");
  if (!(std::isfinite(mmPerUnit) && mmPerUnit > 0.0))
    throw std::invalid_argument("cutting pattern: mmPerUnit must be finite and > 0");
  if (!(std::isfinite(labelHeightMm) && labelHeightMm > 0.0))
    throw std::invalid_argument("cutting pattern: labelHeightMm must be finite and > 0");
  const GlueSeams seams = findGlueSeams(static_cast<int>(V.rows()), faces, gluePairs, V);
  const double s = mmPerUnit;
  auto at = [&V, s](int v) { return Eigen::Vector2d(V(v, 0) * s, V(v, 1) * s); };
  DxfDrawing drawing;
  drawing.title = "cutting pattern";
  // Cuts chained into outlines; glue edges chained per side of a seam; mesh edges one by one.
  std::map<std::pair<int, int>, std::vector<std::array<int, 2>>> boundary;  // (seam, side) → edges; (−1, −1) = cut
  for (const PolygonEdge& e : seams.edges) {
    if (e.faceCount == 2) {
      if (drawMesh) drawing.polylines.push_back({"MESH", {at(e.v0), at(e.v1)}, false});
    } else {
      boundary[{e.gluedTo < 0 ? -1 : e.seam, e.gluedTo < 0 ? -1 : e.side}].push_back({{e.v0, e.v1}});
    }
  }
  for (const auto& [key, edges] : boundary)
    for (const auto& [vertices, closed] : chainSegments(edges)) {
      DxfPolyline line{key.first < 0 ? "CUT" : "GLUE", {}, closed};
      for (const int v : vertices) line.points.push_back(at(v));
      drawing.polylines.push_back(std::move(line));
    }
  for (const SeamLabel& label : seamLabelPositions(seams, faces, V, 0.7 * labelHeightMm / s))
    drawing.texts.push_back({"LABEL", label.position * s, labelHeightMm, std::to_string(label.seam + 1)});
  drawing.layers = layersUsed(drawing);
  return drawing;
}

}  // namespace devsurf::io
