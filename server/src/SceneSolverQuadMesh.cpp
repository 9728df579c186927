// SceneSolver's quad_mesh parts (Jiang et al. 2020): metrics and exports.
#include <sstream>

#include "devsurf/io/CuttingPatternSvg.h"
#include "devsurf/io/PolygonMesh.h"
#include "devsurf/io/QuadMeshFold.h"
#include "devsurf/server/SceneSolver.h"

namespace devsurf::server {

namespace qm = models::quad_mesh;

namespace {

/// The pairs glued on M (those on M′ join vertices of the unfolding itself and are not seams).
std::vector<std::array<int, 2>> meshGluePairs(const qm::QuadMeshDesign& d) {
  std::vector<std::array<int, 2>> pairs;
  for (const qm::GluePair& g : d.glue)
    if (g.on == qm::MeshSide::Mesh) pairs.push_back({g.a, g.b});
  return pairs;
}

}  // namespace

proto::Metrics SceneSolver::quadMeshMetrics() const {
  const qm::QuadMeshModel& model = *quadMesh_;
  const qm::QuadMeshQuality q = model.quality();
  proto::Metrics m;
  m["length_error"] = q.lengthError;
  m["area_error"] = q.areaError;
  m["isometry_residual_max"] = q.isometryResidualMax;
  m["glue_gap_max"] = q.glueGapMax;
  m["handle_distance_max"] = q.handleDistanceMax;
  m["unfolding_flipped_faces"] = q.unfoldingFlippedFaces;
  const Eigen::MatrixX3d mesh = model.meshVertices();
  double moved = 0.0;
  if (initialQuadMesh_.mesh.rows() == mesh.rows()) moved = (mesh - initialQuadMesh_.mesh).rowwise().norm().maxCoeff();
  m["displacement_max"] = moved;
  m["rounds"] = quadMeshSummary_.rounds;
  m["unknowns"] = model.numUnknowns();
  if (initialQuadMesh_.gaussImage) {
    const qm::QuadMeshCurvature c = model.curvature();
    m["gauss_curvature_max_abs"] = c.gauss.size() ? c.gauss.cwiseAbs().maxCoeff() : 0.0;
    m["mean_curvature_max_abs"] = c.mean.size() ? c.mean.cwiseAbs().maxCoeff() : 0.0;
  }
  return m;
}

ExportedFile SceneSolver::quadMeshExport(const std::string& format) const {
  const qm::QuadMeshModel& model = *quadMesh_;
  const std::string title = scene_.name.empty() ? std::string("quad mesh") : scene_.name;
  const auto& faces = model.topology().faces();
  if (format == "obj") return {io::objString(model.meshVertices(), faces, title + " (M)"), "model/obj", "obj"};
  if (format == "unfolding_obj")
    return {io::objString(model.unfoldingVertices(), faces, title + " (unfolding M')"), "model/obj", "unfolding.obj"};
  if (format == "svg" || format == "fold") {
    const qm::QuadMeshDesign d = model.design();
    if (!d.unfoldingPlanar)
      throw ExportUnavailable("format: " + format + " draws a planar unfolding; this scene's M′ is a second surface "
                              "(unfolding_planar false)");
    const double mm = proto::millimetresPerUnit(scene_.units);
    try {
      if (format == "svg") {
        io::CuttingPatternOptions options;
        options.title = title;
        return {io::cuttingPatternSvg(d.unfolding, faces, meshGluePairs(d), mm, options), "image/svg+xml", "svg"};
      }
      io::QuadMeshFoldOptions options;
      options.title = title;
      options.description = scene_.description;
      options.unitToMm = mm;
      return {io::quadMeshFoldString(d.unfolding, d.mesh, faces, meshGluePairs(d), options), "application/json",
              "fold"};
    } catch (const std::bad_alloc&) {
      throw;
    } catch (const std::invalid_argument& e) {
      throw ExportFailed("format: " + format + ": the mesh in its current state cannot be written (" + e.what() + ")");
    }
  }
  throw ExportUnavailable("format: expected json, obj, unfolding_obj, svg or fold for a quad_mesh scene, got \"" +
                          format + "\" (devsurf solve also writes stl)");
}

}  // namespace devsurf::server
