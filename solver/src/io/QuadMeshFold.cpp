#include "devsurf/io/QuadMeshFold.h"

#include <cmath>
#include <fstream>
#include <stdexcept>

#include "devsurf/io/GlueSeams.h"

namespace devsurf::io {
namespace {

using ordered = nlohmann::ordered_json;  // keeps the spec's reading order in the written file

/// The FOLD frame_unit that is exactly `unitToMm` millimetres long, or empty.
std::string quadExactFrameUnit(double unitToMm) {
  const std::pair<const char*, double> units[] = {{"mm", 1.0},   {"cm", 10.0},        {"m", 1000.0},
                                                  {"in", 25.4},  {"pt", 25.4 / 72.0}, {"um", 1e-3},
                                                  {"nm", 1e-6}};
  for (const auto& [name, mm] : units)
    if (mm == unitToMm) return name;
  return {};
}

ordered buildDocument(const Eigen::MatrixXd& unfolding, const Eigen::MatrixXd& mesh,
                      const std::vector<PolygonFace>& faces,
                      const std::vector<std::array<int, 2>>& gluePairs, const QuadMeshFoldOptions& o) {
  if (unfolding.cols() != 2 && unfolding.cols() != 3)
    throw std::invalid_argument("FOLD: the unfolding must have 2 or 3 columns");
  if (mesh.rows() > 0 && (mesh.cols() != 3 || mesh.rows() != unfolding.rows()))
    throw std::invalid_argument("FOLD: the mesh must be V×3 with as many vertices as the unfolding");
  if (!unfolding.allFinite() || !mesh.allFinite())
    throw std::invalid_argument("FOLD: coordinates must be finite");
  if (!(std::isfinite(o.unitToMm) && o.unitToMm > 0.0))
    throw std::invalid_argument("FOLD: unitToMm must be finite and > 0");
  const GlueSeams seams = findGlueSeams(static_cast<int>(unfolding.rows()), faces, gluePairs, unfolding);

  const std::string named = quadExactFrameUnit(o.unitToMm);
  const std::string unit = named.empty() ? std::string("mm") : named;
  const double s = named.empty() ? o.unitToMm : 1.0;
  const std::string title = o.title.empty() ? std::string("devsurf quad mesh") : o.title;
  const bool flat = unfolding.cols() == 2 || unfolding.col(2).cwiseAbs().maxCoeff() == 0.0;
  bool joins = false;
  for (const PolygonEdge& e : seams.edges) joins = joins || e.gluedTo >= 0;

  ordered doc = ordered::object();
  doc["file_spec"] = 1.2;
  doc["file_creator"] = "devsurf";
  if (!o.author.empty()) doc["file_author"] = o.author;
  doc["file_title"] = title;
  if (!o.description.empty()) doc["file_description"] = o.description;
  doc["file_classes"] = ordered::array({"singleModel"});

  doc["frame_title"] = title + " (unfolding)";
  doc["frame_classes"] = ordered::array({"creasePattern"});
  doc["frame_attributes"] = ordered::array({flat ? "2D" : "3D", joins ? "joins" : "noJoins"});
  doc["frame_unit"] = unit;
  ordered vc = ordered::array();
  for (Eigen::Index i = 0; i < unfolding.rows(); ++i) {
    if (flat)
      vc.push_back(ordered::array({unfolding(i, 0) * s, unfolding(i, 1) * s}));
    else
      vc.push_back(ordered::array({unfolding(i, 0) * s, unfolding(i, 1) * s, unfolding(i, 2) * s}));
  }
  doc["vertices_coords"] = std::move(vc);
  ordered fv = ordered::array();
  for (const PolygonFace& f : faces) {
    ordered loop = ordered::array();
    for (int c = 0; c < cornerCount(f); ++c) loop.push_back(f[static_cast<std::size_t>(c)]);
    fv.push_back(std::move(loop));
  }
  doc["faces_vertices"] = std::move(fv);
  ordered ev = ordered::array(), ea = ordered::array(), es = ordered::array();
  for (const PolygonEdge& e : seams.edges) {
    ev.push_back(ordered::array({e.v0, e.v1}));
    ea.push_back(e.faceCount == 2 ? "F" : e.gluedTo >= 0 ? "J" : "B");
    if (e.seam >= 0)
      es.push_back(e.seam + 1);
    else
      es.push_back(nullptr);
  }
  doc["edges_vertices"] = std::move(ev);
  doc["edges_assignment"] = std::move(ea);
  if (joins) doc["edges_devsurf:seam"] = std::move(es);
  if (!gluePairs.empty()) {
    ordered gp = ordered::array();
    for (const auto& [i, j] : gluePairs) gp.push_back(ordered::array({i, j}));
    doc["devsurf:gluePairs"] = std::move(gp);
  }
  doc["devsurf:unitToMm"] = o.unitToMm;

  if (mesh.rows() > 0) {
    ordered folded = ordered::object();
    folded["frame_title"] = title + " (folded form)";
    folded["frame_classes"] = ordered::array({"foldedForm"});
    folded["frame_attributes"] = ordered::array({"3D"});
    folded["frame_parent"] = 0;
    folded["frame_inherit"] = true;
    folded["frame_unit"] = unit;
    ordered fc = ordered::array();
    for (Eigen::Index i = 0; i < mesh.rows(); ++i)
      fc.push_back(ordered::array({mesh(i, 0) * s, mesh(i, 1) * s, mesh(i, 2) * s}));
    folded["vertices_coords"] = std::move(fc);
    doc["file_frames"] = ordered::array({std::move(folded)});
  }
  return doc;
}

}  // namespace

nlohmann::json quadMeshFoldDocument(const Eigen::MatrixXd& unfolding, const Eigen::MatrixXd& mesh,
                                    const std::vector<PolygonFace>& faces,
                                    const std::vector<std::array<int, 2>>& gluePairs,
                                    const QuadMeshFoldOptions& options) {
  return nlohmann::json(buildDocument(unfolding, mesh, faces, gluePairs, options));
}

std::string quadMeshFoldString(const Eigen::MatrixXd& unfolding, const Eigen::MatrixXd& mesh,
                               const std::vector<PolygonFace>& faces,
                               const std::vector<std::array<int, 2>>& gluePairs,
                               const QuadMeshFoldOptions& options) {
  return buildDocument(unfolding, mesh, faces, gluePairs, options).dump(options.indent) + "\n";
}

void writeQuadMeshFold(const Eigen::MatrixXd& unfolding, const Eigen::MatrixXd& mesh,
                       const std::vector<PolygonFace>& faces,
                       const std::vector<std::array<int, 2>>& gluePairs, const std::string& path,
                       const QuadMeshFoldOptions& options) {
  const std::string text = quadMeshFoldString(unfolding, mesh, faces, gluePairs, options);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot write FOLD file " + path);
  out << text;
  out.flush();
  if (!out) throw std::runtime_error("cannot write FOLD file " + path);
}

}  // namespace devsurf::io
