// SceneSolver's quad_mesh parts (Jiang et al. 2020): metrics and exports.
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <sstream>
#include <utility>

#include <Eigen/Geometry>

#include "devsurf/cad/StepWriter.h"
#include "devsurf/io/CuttingPatternSvg.h"
#include "devsurf/io/DxfDrawing.h"
#include "devsurf/io/IgesWriter.h"
#include "devsurf/io/PolygonMesh.h"
#include "devsurf/io/QuadMeshFold.h"
#include "devsurf/models/quad_mesh/SplineSurface.h"
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

/// Where M creases or folds back: the largest angle between the normals of two faces sharing an
/// edge (Newell normals of the polygons), in degrees, and how many shared edges exceed 30°.
struct FaceNormalAngles {
  double maxDegrees = 0.0;
  int sharpEdges = 0;
};

FaceNormalAngles faceNormalAngles(const Eigen::MatrixX3d& vertices, const std::vector<qm::Face>& faces) {
  std::vector<Eigen::Vector3d> normals(faces.size(), Eigen::Vector3d::Zero());
  std::map<std::pair<int, int>, std::vector<int>> edgeFaces;
  auto at = [&vertices](int v) { return Eigen::Vector3d(vertices.row(v)); };
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const int n = qm::faceSize(faces[f]);
    bool inside = true;
    for (int k = 0; k < n; ++k)
      inside = inside && faces[f][static_cast<std::size_t>(k)] >= 0 && faces[f][static_cast<std::size_t>(k)] < vertices.rows();
    if (!inside) continue;
    const std::array<int, 4>& c = faces[f];
    // The polygon's vector area, from differences (a quad's: half the cross product of its
    // diagonals), so that it keeps its digits far from the origin.
    normals[f] = n == 4 ? Eigen::Vector3d((at(c[2]) - at(c[0])).cross(at(c[3]) - at(c[1])))
                        : Eigen::Vector3d((at(c[1]) - at(c[0])).cross(at(c[2]) - at(c[0])));
    for (int k = 0; k < n; ++k) {
      const int a = c[static_cast<std::size_t>(k)], b = c[static_cast<std::size_t>((k + 1) % n)];
      edgeFaces[{std::min(a, b), std::max(a, b)}].push_back(static_cast<int>(f));
    }
  }
  FaceNormalAngles out;
  for (const auto& [edge, shared] : edgeFaces) {
    if (shared.size() != 2) continue;
    const Eigen::Vector3d& n0 = normals[static_cast<std::size_t>(shared[0])];
    const Eigen::Vector3d& n1 = normals[static_cast<std::size_t>(shared[1])];
    if (!(n0.norm() > 0.0) || !(n1.norm() > 0.0)) continue;
    const double degrees = std::atan2(n0.cross(n1).norm(), n0.dot(n1)) * 180.0 / 3.14159265358979323846;
    out.maxDegrees = std::max(out.maxDegrees, degrees);
    if (degrees > 30.0) ++out.sharpEdges;
  }
  return out;
}

}  // namespace

proto::Metrics SceneSolver::quadMeshMetrics() const {
  const qm::QuadMeshModel& model = *quadMesh_;
  const qm::QuadMeshQuality q = model.quality();
  proto::Metrics m;
  m["length_error"] = q.lengthError;
  m["edge_length_error_max"] = q.edgeLengthErrorMax;
  m["area_error"] = q.areaError;
  m["isometry_residual_max"] = q.isometryResidualMax;
  m["glue_gap_max"] = q.glueGapMax;
  m["handle_distance_max"] = q.handleDistanceMax;
  m["unfolding_flipped_faces"] = q.unfoldingFlippedFaces;
  const Eigen::MatrixX3d mesh = model.meshVertices();
  double moved = 0.0;
  if (initialQuadMesh_.mesh.rows() == mesh.rows()) moved = (mesh - initialQuadMesh_.mesh).rowwise().norm().maxCoeff();
  m["displacement_max"] = moved;
  // Creases and fold-backs that guided projection made (a doubly curved M cannot become one
  // regular developable: Jiang et al. Fig. 8b), next to M's own before the solve.
  const FaceNormalAngles now = faceNormalAngles(mesh, model.topology().faces());
  m["face_normal_angle_max_deg"] = now.maxDegrees;
  m["sharp_edges"] = now.sharpEdges;
  if (initialQuadMesh_.mesh.rows() == mesh.rows())
    m["face_normal_angle_max_deg_initial"] = faceNormalAngles(initialQuadMesh_.mesh, model.topology().faces()).maxDegrees;
  m["rounds"] = quadMeshSummary_.rounds;
  m["unknowns"] = model.numUnknowns();
  if (initialQuadMesh_.control) {
    // The spline M^∞ itself (issue 14), before (the scene's control points) and now.
    const qm::ControlNet& net = *initialQuadMesh_.control;
    const qm::SplineSurfaceAnalysis now = qm::analyzeSplineSurface(net, model.controlPoints());
    m["spline_gauss_max_scaled"] = now.gaussMaxScaled;
    m["spline_gauss_mean_scaled"] = now.gaussMeanScaled;
    m["spline_gauss_max_scaled_initial"] = initialSpline_.gaussMaxScaled;
    m["spline_gauss_mean_scaled_initial"] = initialSpline_.gaussMeanScaled;
    m["spline_normal_jump_max_deg"] = now.normalJumpMaxDegrees;
    m["spline_normal_jump_max_deg_initial"] = initialSpline_.normalJumpMaxDegrees;
    m["spline_patches"] = static_cast<double>(now.samples.size());
    m["spline_shared_sides"] = now.sharedSides;
    m["control_points"] = static_cast<double>(net.points.rows());
  }
  if (initialQuadMesh_.gaussImage) {
    const qm::QuadMeshCurvature c = model.curvature();
    m["gauss_curvature_max_abs"] = c.gauss.size() ? c.gauss.cwiseAbs().maxCoeff() : 0.0;
    m["mean_curvature_max_abs"] = c.mean.size() ? c.mean.cwiseAbs().maxCoeff() : 0.0;
  }
  if (initialQuadMesh_.reference) {
    // Distances from the reference's vertices to M (CGAL's AABB tree over M split into
    // triangles), as for a fitted strip; coverage within 1 % of the reference's diagonal.
    try {
      for (const auto& [name, value] : referenceMetrics(initialQuadMesh_.reference->vertices, 0.0))
        m["approximation_" + name.substr(std::string("reference_").size())] = value;
    } catch (const std::exception&) {
      // A degenerate M has no distances; length and area errors say what went wrong.
    }
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
  if (format == "iges" || format == "step") {
    checkExportFormat(format);  // throws without a control net
    std::vector<io::IgesSurface> surfaces;
    std::vector<io::IgesCurve> curves;
    igesEntities(surfaces, curves);
    try {
      if (format == "iges") {
        io::IgesHeader header;
        header.fileName = title + ".igs";
        header.units = scene_.units;
        return {io::igesDocument(surfaces, curves, header), "model/iges", "igs"};
      }
      cad::StepOptions options;
      options.units = scene_.units;
      options.sew = true;  // patches sharing a side share its edge: one watertight shell
      options.sewingTolerance = 1e-7 * std::max(1e-300, (model.meshVertices().colwise().maxCoeff() -
                                                          model.meshVertices().colwise().minCoeff()).norm());
      return {cad::stepDocument(surfaces, options), "model/step", "step"};
    } catch (const std::bad_alloc&) {
      throw;
    } catch (const std::exception& e) {
      throw ExportFailed("format: " + format + ": the surface in its current state cannot be written (" + e.what() + ")");
    }
  }
  if (format == "stl") return fabricationExport(format);
  if (format == "svg" || format == "fold" || format == "dxf") {
    const qm::QuadMeshDesign d = model.design();
    checkExportFormat(format);  // throws unless M′ is planar
    const double mm = proto::millimetresPerUnit(scene_.units);
    try {
      if (format == "dxf") {
        io::DxfDrawing drawing = io::cuttingPatternDrawing(d.unfolding, faces, meshGluePairs(d), mm);
        drawing.title = title + ": cutting pattern of the unfolding";
        return {io::dxfDocument(drawing), "image/vnd.dxf", "dxf"};
      }
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
  throw ExportUnavailable("format: expected json, obj, unfolding_obj, stl, svg, dxf, fold, png, or iges, step with a control "
                          "net, for a quad_mesh scene, got \"" +
                          format + "\"");
}

void SceneSolver::quadMeshIgesEntities(std::vector<io::IgesSurface>& surfaces) const {
  const qm::QuadMeshModel& model = *quadMesh_;
  if (!initialQuadMesh_.control)
    throw ExportUnavailable("format: iges exports B-spline surfaces; a quad_mesh scene without a control net is a mesh "
                            "(use obj, unfolding_obj, stl, svg, dxf, fold or png)");
  const std::vector<qm::SplinePatchSurface> patches =
      qm::splinePatchSurfaces(*initialQuadMesh_.control, model.controlPoints());
  for (std::size_t k = 0; k < patches.size(); ++k) {
    io::IgesSurface s;
    s.degreeU = s.degreeV = 3;
    s.nu = patches[k].nu;
    s.nv = patches[k].nv;
    s.knotsU = patches[k].knotsU;
    s.knotsV = patches[k].knotsV;
    s.points = patches[k].points;
    s.label = "PATCH" + std::to_string(k);
    surfaces.push_back(std::move(s));
  }
}

}  // namespace devsurf::server
