// SceneSolver's quad_mesh parts (Jiang et al. 2020): metrics and exports.
#include <sstream>

#include "devsurf/server/SceneSolver.h"

namespace devsurf::server {

namespace qm = models::quad_mesh;

namespace {

/// Wavefront OBJ of a quad-dominant mesh (1-based indices, one "f" line per face).
std::string polygonObjText(const Eigen::MatrixX3d& vertices, const std::vector<qm::Face>& faces,
                           const std::string& title) {
  std::ostringstream out;
  out.precision(17);
  out << "# devsurf: " << title << "\n";
  for (Eigen::Index i = 0; i < vertices.rows(); ++i)
    out << "v " << vertices(i, 0) << ' ' << vertices(i, 1) << ' ' << vertices(i, 2) << "\n";
  for (const qm::Face& f : faces) {
    out << 'f';
    for (int k = 0; k < qm::faceSize(f); ++k) out << ' ' << f[k] + 1;
    out << "\n";
  }
  return out.str();
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
  const Eigen::MatrixX3d mesh = model.meshVertices(), unfolding = model.unfoldingVertices();
  double moved = 0.0;
  if (initialQuadMesh_.mesh.rows() == mesh.rows()) moved = (mesh - initialQuadMesh_.mesh).rowwise().norm().maxCoeff();
  m["displacement_max"] = moved;
  m["rounds"] = quadMeshSummary_.rounds;
  m["unknowns"] = model.numUnknowns();
  if (model.design().gaussImage) {
    const qm::QuadMeshCurvature c = model.curvature();
    m["gauss_curvature_max_abs"] = c.gauss.size() ? c.gauss.cwiseAbs().maxCoeff() : 0.0;
    m["mean_curvature_max_abs"] = c.mean.size() ? c.mean.cwiseAbs().maxCoeff() : 0.0;
  }
  return m;
}

ExportedFile SceneSolver::quadMeshExport(const std::string& format) const {
  const qm::QuadMeshModel& model = *quadMesh_;
  const std::string title = scene_.name.empty() ? std::string("quad mesh") : scene_.name;
  if (format == "obj") return {polygonObjText(model.meshVertices(), model.topology().faces(), title + " (M)"), "model/obj", "obj"};
  if (format == "unfolding_obj")
    return {polygonObjText(model.unfoldingVertices(), model.topology().faces(), title + " (unfolding M')"),
            "model/obj", "unfolding.obj"};
  throw ExportUnavailable("format: expected json, obj, unfolding_obj, svg or fold for a quad_mesh scene, got \"" +
                          format + "\"");
}

}  // namespace devsurf::server
