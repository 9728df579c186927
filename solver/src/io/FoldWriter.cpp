#include "devsurf/io/FoldWriter.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace devsurf::io {
namespace {

using nlohmann::json;
using ordered = nlohmann::ordered_json;  // keeps the spec's reading order in the written file

constexpr const char* kCurveKey = "edges_devsurf:curve";
constexpr const char* kSmoothKey = "edges_devsurf:smooth";
constexpr const char* kCurvesKey = "devsurf:curves";
constexpr const char* kRulingsKey = "devsurf:rulings";
constexpr const char* kScaleKey = "devsurf:unitToMm";

ordered point(double x, double y) { return ordered::array({x, y}); }
ordered point(double x, double y, double z) { return ordered::array({x, y, z}); }

bool hasAssignment(const CreasePattern& p, EdgeAssignment a) {
  return std::any_of(p.edges.begin(), p.edges.end(),
                     [a](const CreaseEdge& e) { return e.assignment == a; });
}

[[noreturn]] void bad(const std::string& what) {
  throw std::invalid_argument("FOLD: " + what);
}

/// Millimetres per frame_unit; 1 for "unit", none, or a unit this reader does not know.
double unitInMm(const json& frame) {
  const auto it = frame.find("frame_unit");
  if (it == frame.end() || !it->is_string()) return 1.0;
  const std::string u = it->get<std::string>();
  if (u == "mm") return 1.0;
  if (u == "cm") return 10.0;
  if (u == "m") return 1000.0;
  if (u == "um") return 1e-3;
  if (u == "nm") return 1e-6;
  if (u == "in") return 25.4;
  if (u == "pt") return 25.4 / 72.0;
  return 1.0;
}

/// The FOLD frame_unit that is exactly `unitToMm` millimetres long, or empty.
std::string exactFrameUnit(double unitToMm) {
  for (const char* u : {"mm", "cm", "m", "in", "pt", "um", "nm"})
    if (unitInMm(json{{"frame_unit", u}}) == unitToMm) return u;
  return {};
}

double number(const json& v, const std::string& what) {
  if (!v.is_number()) bad(what + " is not a number");
  return v.get<double>();
}

int index(const json& v, const std::string& what) {
  if (!v.is_number_integer()) bad(what + " is not an integer");
  return v.get<int>();
}

const json& array(const json& frame, const char* key) {
  const auto it = frame.find(key);
  if (it == frame.end()) bad(std::string("missing ") + key);
  if (!it->is_array()) bad(std::string(key) + " is not an array");
  return *it;
}

/// Coordinates of vertices_coords (missing trailing coordinates are zero), times `factor`.
Eigen::MatrixXd coords(const json& list, int dim, double factor, const char* what) {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(list.size()), dim);
  for (std::size_t i = 0; i < list.size(); ++i) {
    const json& c = list[i];
    if (!c.is_array() || c.empty()) bad(std::string(what) + " entry " + std::to_string(i) +
                                        " is not a coordinate array");
    for (int d = 0; d < dim; ++d)
      out(static_cast<Eigen::Index>(i), d) =
          d < static_cast<int>(c.size()) ? number(c[d], what) * factor : 0.0;
  }
  return out;
}

}  // namespace

ordered buildFold(const CreasePattern& p, const FoldWriteOptions& options) {
  p.validate();
  // Coordinates in the model's own unit when FOLD names it (frame_unit "cm" for 10 mm per model
  // unit, …), otherwise in millimetres.
  const std::string named = exactFrameUnit(p.unitToMm);
  const std::string unit = named.empty() ? std::string("mm") : named;
  const double s = named.empty() ? p.unitToMm : 1.0;
  const std::string title = p.title.empty() ? std::string("devsurf crease pattern") : p.title;
  const bool cuts = hasAssignment(p, EdgeAssignment::Cut);

  ordered doc = ordered::object();
  doc["file_spec"] = 1.2;
  doc["file_creator"] = "devsurf";
  if (!options.author.empty()) doc["file_author"] = options.author;
  doc["file_title"] = title;
  if (!options.description.empty()) doc["file_description"] = options.description;
  doc["file_classes"] = ordered::array({"singleModel"});

  // Key frame: the crease pattern.
  doc["frame_title"] = title + " (crease pattern)";
  doc["frame_classes"] = ordered::array({"creasePattern"});
  doc["frame_attributes"] = ordered::array({"2D", cuts ? "cuts" : "noCuts"});
  doc["frame_unit"] = unit;
  ordered vc = ordered::array();
  for (Eigen::Index i = 0; i < p.vertices2d.rows(); ++i)
    vc.push_back(point(p.vertices2d(i, 0) * s, p.vertices2d(i, 1) * s));
  doc["vertices_coords"] = std::move(vc);

  ordered ev = ordered::array(), ea = ordered::array(), ef = ordered::array(), ec = ordered::array(),
          es = ordered::array();
  const auto angles = exportedFoldAngles(p);
  bool allAngles = true, anyCurve = false, anySmooth = false;
  for (std::size_t e = 0; e < p.edges.size(); ++e) {
    const CreaseEdge& ed = p.edges[e];
    ev.push_back(ordered::array({ed.v0, ed.v1}));
    ea.push_back(std::string(1, foldAssignmentLetter(ed.assignment)));
    if (angles[e])
      ef.push_back(*angles[e] == 0.0 ? 0.0 : *angles[e]);  // no "-0.0"
    else
      allAngles = false;
    es.push_back(ed.proposed);
    anySmooth = anySmooth || ed.proposed;
    if (ed.curve >= 0) {
      ec.push_back(ed.curve);
      anyCurve = true;
    } else {
      ec.push_back(nullptr);
    }
  }
  doc["edges_vertices"] = std::move(ev);
  doc["edges_assignment"] = std::move(ea);
  if (allAngles) doc["edges_foldAngle"] = std::move(ef);
  if (!p.faces.empty()) doc["faces_vertices"] = p.faces;

  // Namespaced data.
  if (anyCurve) doc[kCurveKey] = std::move(ec);
  if (anySmooth) doc[kSmoothKey] = std::move(es);
  if (!p.curves.empty()) {
    ordered curves = ordered::array();
    for (const CreaseCurve& c : p.curves) {
      ordered cp = ordered::array();
      for (Eigen::Index i = 0; i < c.controlPoints.rows(); ++i)
        cp.push_back(point(c.controlPoints(i, 0) * s, c.controlPoints(i, 1) * s,
                           c.controlPoints(i, 2) * s));
      ordered entry = {{"id", c.id}, {"degree", c.degree}, {"knots", c.knots},
                    {"controlPoints", std::move(cp)}};
      if (!c.weights.empty()) entry["weights"] = c.weights;
      curves.push_back(std::move(entry));
    }
    doc[kCurvesKey] = std::move(curves);
  }
  if (p.rulings.rows() > 0) {
    ordered rulings = ordered::array();
    for (Eigen::Index r = 0; r < p.rulings.rows(); ++r)
      rulings.push_back(ordered::array({point(p.rulings(r, 0) * s, p.rulings(r, 1) * s),
                                     point(p.rulings(r, 2) * s, p.rulings(r, 3) * s)}));
    doc[kRulingsKey] = std::move(rulings);
  }
  doc[kScaleKey] = p.unitToMm;

  // Frame 1: the folded form, inheriting the structure of the crease pattern.
  if (options.foldedFrame && p.hasFoldedState()) {
    const bool flat = p.vertices3d.col(2).cwiseAbs().maxCoeff() == 0.0;
    ordered folded = ordered::object();
    folded["frame_title"] = title + " (folded form)";
    folded["frame_classes"] = ordered::array({"foldedForm"});
    folded["frame_attributes"] = ordered::array({flat ? "2D" : "3D", cuts ? "cuts" : "noCuts"});
    folded["frame_parent"] = 0;
    folded["frame_inherit"] = true;
    folded["frame_unit"] = unit;
    ordered fc = ordered::array();
    for (Eigen::Index i = 0; i < p.vertices3d.rows(); ++i)
      fc.push_back(point(p.vertices3d(i, 0) * s, p.vertices3d(i, 1) * s, p.vertices3d(i, 2) * s));
    folded["vertices_coords"] = std::move(fc);
    doc["file_frames"] = ordered::array({std::move(folded)});
  }
  return doc;
}

json foldDocument(const CreasePattern& pattern, const FoldWriteOptions& options) {
  return json(buildFold(pattern, options));
}

std::string foldString(const CreasePattern& pattern, const FoldWriteOptions& options) {
  return buildFold(pattern, options).dump(options.indent) + "\n";
}

void writeFold(const CreasePattern& pattern, const std::string& path,
               const FoldWriteOptions& options) {
  const std::string text = foldString(pattern, options);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot write FOLD file " + path);
  out << text;
  out.flush();
  if (!out) throw std::runtime_error("cannot write FOLD file " + path);
}

CreasePattern readFoldDocument(const json& doc) {
  if (!doc.is_object()) bad("the document is not a JSON object");
  CreasePattern p;
  if (const auto t = doc.find("file_title"); t != doc.end() && t->is_string())
    p.title = t->get<std::string>();

  // Model units: coordinates in frame_unit → millimetres → model units.
  double scale = unitInMm(doc);
  double toModel = 1.0;
  if (const auto it = doc.find(kScaleKey); it != doc.end()) {
    const double modelScale = number(*it, kScaleKey);
    if (!(modelScale > 0.0)) bad(std::string(kScaleKey) + " must be positive");
    toModel = scale / modelScale;
    scale = modelScale;
  }
  p.unitToMm = scale;

  p.vertices2d = coords(array(doc, "vertices_coords"), 2, toModel, "vertices_coords");
  const int n = p.numVertices();

  const json& ev = array(doc, "edges_vertices");
  p.edges.resize(ev.size());
  for (std::size_t e = 0; e < ev.size(); ++e) {
    if (!ev[e].is_array() || ev[e].size() != 2) bad("edges_vertices entry is not a pair");
    p.edges[e].v0 = index(ev[e][0], "edges_vertices entry");
    p.edges[e].v1 = index(ev[e][1], "edges_vertices entry");
  }
  if (doc.contains("edges_assignment")) {
    const json& ea = array(doc, "edges_assignment");
    if (ea.size() != ev.size()) bad("edges_assignment and edges_vertices differ in length");
    for (std::size_t e = 0; e < ea.size(); ++e) {
      if (!ea[e].is_string()) bad("edges_assignment entry is not a string");
      try {
        p.edges[e].assignment = parseFoldAssignment(ea[e].get<std::string>());
      } catch (const std::invalid_argument& ex) {
        bad(ex.what());
      }
    }
  }
  if (doc.contains("edges_foldAngle")) {
    const json& ef = array(doc, "edges_foldAngle");
    if (ef.size() != ev.size()) bad("edges_foldAngle and edges_vertices differ in length");
    for (std::size_t e = 0; e < ef.size(); ++e)
      if (!ef[e].is_null()) p.edges[e].foldAngle = number(ef[e], "edges_foldAngle entry");
  }
  if (doc.contains(kCurveKey)) {
    const json& ec = array(doc, kCurveKey);
    if (ec.size() != ev.size()) bad(std::string(kCurveKey) + " and edges_vertices differ in length");
    for (std::size_t e = 0; e < ec.size(); ++e)
      p.edges[e].curve = ec[e].is_null() ? -1 : index(ec[e], kCurveKey);
  }
  if (doc.contains(kSmoothKey)) {
    const json& es = array(doc, kSmoothKey);
    if (es.size() != ev.size()) bad(std::string(kSmoothKey) + " and edges_vertices differ in length");
    for (std::size_t e = 0; e < es.size(); ++e) {
      if (!es[e].is_boolean() && !es[e].is_null()) bad(std::string(kSmoothKey) + " entry is not true, false or null");
      // As the import reads it: smooth means something on a flat edge only.
      p.edges[e].proposed = es[e].is_boolean() && es[e].get<bool>() && p.edges[e].assignment == EdgeAssignment::Flat;
    }
  }
  if (doc.contains("faces_vertices")) {
    for (const json& f : array(doc, "faces_vertices")) {
      if (!f.is_array()) bad("faces_vertices entry is not an array");
      std::vector<int> loop;
      for (const json& v : f) loop.push_back(index(v, "faces_vertices entry"));
      p.faces.push_back(std::move(loop));
    }
  }

  if (doc.contains(kCurvesKey)) {
    for (const json& c : array(doc, kCurvesKey)) {
      if (!c.is_object()) bad(std::string(kCurvesKey) + " entry is not an object");
      CreaseCurve curve;
      curve.id = index(c.value("id", json()), "curve id");
      curve.degree = index(c.value("degree", json()), "curve degree");
      for (const json& k : array(c, "knots")) curve.knots.push_back(number(k, "knot"));
      curve.controlPoints = coords(array(c, "controlPoints"), 3, toModel, "controlPoints");
      if (c.contains("weights"))
        for (const json& w : array(c, "weights")) curve.weights.push_back(number(w, "weight"));
      p.curves.push_back(std::move(curve));
    }
  }
  if (doc.contains(kRulingsKey)) {
    const json& rl = array(doc, kRulingsKey);
    p.rulings.resize(static_cast<Eigen::Index>(rl.size()), 4);
    for (std::size_t r = 0; r < rl.size(); ++r) {
      if (!rl[r].is_array() || rl[r].size() != 2) bad("ruling is not a pair of points");
      const Eigen::MatrixXd ends = coords(rl[r], 2, toModel, kRulingsKey);
      p.rulings.row(static_cast<Eigen::Index>(r)) << ends(0, 0), ends(0, 1), ends(1, 0), ends(1, 1);
    }
  }

  // The folded state: the first folded-form frame with one coordinate per vertex.
  if (const auto frames = doc.find("file_frames"); frames != doc.end() && frames->is_array()) {
    for (const json& f : *frames) {
      if (!f.is_object()) continue;
      const auto cls = f.find("frame_classes");
      if (cls == f.end() || !cls->is_array() ||
          std::find(cls->begin(), cls->end(), json("foldedForm")) == cls->end())
        continue;
      const auto vc = f.find("vertices_coords");
      if (vc == f.end() || !vc->is_array() || static_cast<int>(vc->size()) != n) continue;
      const double frameToModel =
          (f.contains("frame_unit") ? unitInMm(f) : unitInMm(doc)) / p.unitToMm;
      p.vertices3d = coords(*vc, 3, frameToModel, "folded vertices_coords");
      break;
    }
  }

  try {
    p.validate();
  } catch (const std::invalid_argument& ex) {
    bad(ex.what());
  }
  return p;
}

CreasePattern parseFold(const std::string& text) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& ex) {  // a syntax error, or a number out of range (1e400)
    bad(std::string("not JSON: ") + ex.what());
  }
  return readFoldDocument(doc);
}

CreasePattern readFold(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read FOLD file " + path);
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw std::runtime_error("cannot read FOLD file " + path);
  return parseFold(text.str());
}

}  // namespace devsurf::io
