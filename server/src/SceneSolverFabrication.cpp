// SceneSolver's fabrication exports (issue 16 item 5): STL of every kind, flat patterns of strips
// and of composites cut along seams, and DXF cut/score drawings of every flat pattern.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "devsurf/io/CuttingPatternSvg.h"
#include "devsurf/io/DxfDrawing.h"
#include "devsurf/io/QuadMeshFold.h"
#include "devsurf/models/composite/CompositePieces.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/server/SceneSolver.h"
#include "devsurf/server/SurfaceThumbnail.h"
#include "devsurf/spatial/IsometricUnfolding.h"

namespace devsurf::server {

namespace {

/// Polygons (2 … 4 distinct corners kept in order) as PolygonFaces: a quad whose corners repeat
/// becomes a triangle; anything with fewer than three distinct corners is left out.
std::vector<io::PolygonFace> polygonFaces(const std::vector<std::vector<int>>& polygons) {
  std::vector<io::PolygonFace> faces;
  for (const std::vector<int>& poly : polygons) {
    if (poly.size() < 3) continue;
    if (poly.size() <= 4) {
      faces.push_back({{poly[0], poly[1], poly[2], poly.size() == 4 ? poly[3] : -1}});
    } else {
      for (std::size_t c = 1; c + 1 < poly.size(); ++c) faces.push_back({{poly[0], poly[c], poly[c + 1], -1}});
    }
  }
  return faces;
}

std::string sceneTitle(const proto::Scene& scene) { return scene.name.empty() ? std::string("devsurf") : scene.name; }

/// `make()`, with any failure but the export errors' own (and running out of memory) turned into
/// ExportFailed "format: F: <what> (<reason>)".
template <class Make>
auto orExportFailed(const std::string& format, const std::string& what, const Make& make) -> decltype(make()) {
  try {
    return make();
  } catch (const ExportUnavailable&) {
    throw;
  } catch (const ExportFailed&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    throw ExportFailed("format: " + format + ": " + what + " (" + std::string(e.what()) + ")");
  }
}

}  // namespace

bool SceneSolver::hasFlatStripPattern() const { return strip_ || quasi_ || conical_; }

SceneSolver::CuttingParts SceneSolver::cuttingParts(const std::string& format) const {
  if (cutAlongSeams()) {
    return orExportFailed(format, "the pieces in their current state cannot be unfolded", [this]() {
      const models::composite::FlatPieces pieces =
          models::composite::unfoldPieces(composite_->design(), composite_->topology());
      CuttingParts parts;
      parts.vertices = pieces.vertices;
      parts.spaceVertices = pieces.spaceVertices;
      parts.faces = pieces.faces;
      parts.gluePairs = pieces.gluePairs;
      parts.title = sceneTitle(scene_) + ": " + std::to_string(pieces.pieces) +
                    (pieces.pieces == 1 ? " piece" : " pieces") + ", cut along the seams";
      return parts;
    });
  }
  if (!hasFlatStripPattern())
    throw ExportUnavailable("format: " + format + " draws a flat pattern, which this scene does not have");
  return orExportFailed(format, "the surface in its current state cannot be unfolded", [this]() {
    // The sampled surface of the obj export, points shared by neighbouring patches welded, each
    // connected sheet unfolded from its own edge lengths.
    const io::QuadMesh surface = sampledSurface();
    const double diagonal =
        surface.vertices.rows() ? (surface.vertices.colwise().maxCoeff() - surface.vertices.colwise().minCoeff()).norm()
                                : 0.0;
    const std::vector<int> weld = spatial::weldedPointIds(surface.vertices, 1e-9 * diagonal);
    std::vector<Eigen::Vector3d> points(static_cast<std::size_t>(surface.vertices.rows()));
    for (Eigen::Index i = 0; i < surface.vertices.rows(); ++i) points[static_cast<std::size_t>(i)] = surface.vertices.row(i);
    std::vector<std::vector<int>> polygons;
    for (Eigen::Index q = 0; q < surface.quads.rows(); ++q) {
      std::vector<int> poly;
      for (int c = 0; c < 4; ++c) {
        const int id = weld[static_cast<std::size_t>(surface.quads(q, c))];
        if (std::find(poly.begin(), poly.end(), id) == poly.end()) poly.push_back(id);
      }
      if (poly.size() >= 3) polygons.push_back(std::move(poly));
    }
    const spatial::FlatLayout layout = spatial::unfoldPieces(points, polygons, spatial::edgeConnectedPieces(polygons));
    CuttingParts parts;
    parts.vertices = layout.vertices;
    parts.spaceVertices.resize(static_cast<Eigen::Index>(layout.pointOfVertex.size()), 3);
    for (std::size_t k = 0; k < layout.pointOfVertex.size(); ++k)
      parts.spaceVertices.row(static_cast<Eigen::Index>(k)) = points[static_cast<std::size_t>(layout.pointOfVertex[k])].transpose();
    parts.faces = polygonFaces(layout.polygons);
    parts.title = sceneTitle(scene_) + ": flat pattern" +
                  (layout.pieces == 1 ? std::string() : ", " + std::to_string(layout.pieces) + " pieces");
    if (parts.faces.empty()) throw std::invalid_argument("the surface has no face of positive size");
    return parts;
  });
}

std::string SceneSolver::cuttingPatternSvg(const CuttingParts& parts) const {
  io::CuttingPatternOptions options;
  options.title = parts.title;
  options.drawMesh = !cutAlongSeams();  // a strip's mesh lines are its rulings
  options.what = cutAlongSeams() ? "Flat pieces of a composite cut apart along its seams, exported by devsurf."
                                 : "Flat pattern of a developable strip, unrolled from its sampled surface (faint lines: "
                                   "its rulings and samples), exported by devsurf.";
  return io::cuttingPatternSvg(parts.vertices, parts.faces, parts.gluePairs, proto::millimetresPerUnit(scene_.units),
                               options);
}

ExportedFile SceneSolver::fabricationExport(const std::string& format) const {
  if (format == "png") {
    return orExportFailed(format, "the surface in its current state cannot be drawn", [this]() {
      return ExportedFile{surfaceThumbnailPng(sampledSurface()), "image/png", "png"};
    });
  }
  if (format == "stl") {
    // STL has no unit; slicers and CAD read it in millimetres: the scene's units are scaled to mm,
    // as the DXF and SVG patterns are (a sheet of 200 units in cm is a 2000 mm part).
    return orExportFailed(format, "the surface in its current state cannot be written", [this]() {
      io::QuadMesh mesh = sampledSurface();
      mesh.vertices *= proto::millimetresPerUnit(scene_.units);
      return ExportedFile{io::meshString(mesh, "stl"), "model/stl", "stl"};
    });
  }
  if (format == "fold") {
    // A composite cut along its seams: its pieces as one crease pattern of several parts (FOLD
    // allows disconnected faces), glued edges as joins numbered by seam, the folded form in 3D.
    if (!cutAlongSeams()) creasePattern(format);  // throws, naming what is missing
    const CuttingParts parts = cuttingParts(format);
    io::QuadMeshFoldOptions options;
    options.title = parts.title;
    options.description = scene_.description;
    options.unitToMm = proto::millimetresPerUnit(scene_.units);
    return orExportFailed(format, "the pieces in their current state cannot be written", [&parts, &options]() {
      return ExportedFile{io::quadMeshFoldString(parts.vertices, parts.spaceVertices, parts.faces, parts.gluePairs, options),
                          "application/json", "fold"};
    });
  }
  if (format == "svg") {
    const CuttingParts parts = cuttingParts(format);
    try {
      return {cuttingPatternSvg(parts), "image/svg+xml", "svg"};
    } catch (const std::invalid_argument& e) {
      throw ExportFailed("format: svg: the flat pattern cannot be drawn (" + std::string(e.what()) + ")");
    }
  }
  // dxf
  io::DxfDrawing drawing;
  if (composite_ && composite_->hasDevelopment()) {
    drawing = io::creasePatternDrawing(creasePattern(format));
  } else {
    if (composite_ && !cutAlongSeams()) creasePattern(format);  // throws, naming what is missing
    const CuttingParts parts = cuttingParts(format);
    try {
      drawing = io::cuttingPatternDrawing(parts.vertices, parts.faces, parts.gluePairs,
                                          proto::millimetresPerUnit(scene_.units));
    } catch (const std::invalid_argument& e) {
      throw ExportFailed("format: dxf: the flat pattern cannot be drawn (" + std::string(e.what()) + ")");
    }
    drawing.title = parts.title;
  }
  return {io::dxfDocument(drawing), "image/vnd.dxf", "dxf"};
}

}  // namespace devsurf::server
