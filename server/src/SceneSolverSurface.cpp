// SceneSolver's surface as the OBJ export samples it, and distances from a user's reference shape
// to it (issue 15).
#include <stdexcept>
#include <vector>

#include "devsurf/reference/SurfaceDistance.h"
#include "devsurf/server/SceneSolver.h"

namespace devsurf::server {

namespace quasi = models::quasi_strip;
namespace conical = models::conical_strip;

namespace {

/// Quads of a grid of U × V vertices (row-major in u: vertex i·V + j) appended to `mesh`.
void appendGrid(io::QuadMesh& mesh, const std::vector<Eigen::Vector3d>& points, int U, int V) {
  const Eigen::Index v0 = mesh.vertices.rows(), q0 = mesh.quads.rows();
  mesh.vertices.conservativeResize(v0 + U * V, 3);
  for (int k = 0; k < U * V; ++k) mesh.vertices.row(v0 + k) = points[static_cast<std::size_t>(k)].transpose();
  mesh.quads.conservativeResize(q0 + (U - 1) * (V - 1), 4);
  Eigen::Index q = q0;
  for (int i = 0; i + 1 < U; ++i)
    for (int j = 0; j + 1 < V; ++j, ++q) {
      const int a = static_cast<int>(v0) + i * V + j;
      mesh.quads.row(q) << a, a + V, a + V + 1, a + 1;
    }
}

}  // namespace

io::QuadMesh SceneSolver::sampledSurface() const {
  if (composite_) return composite_->geometry(50, 8).merged;
  if (quadMesh_) {
    io::QuadMesh m;
    m.vertices = quadMesh_->meshVertices();
    const auto& faces = quadMesh_->topology().faces();
    m.quads.resize(static_cast<Eigen::Index>(faces.size()), 4);
    for (std::size_t f = 0; f < faces.size(); ++f)
      m.quads.row(static_cast<Eigen::Index>(f)) << faces[f][0], faces[f][1], faces[f][2],
          faces[f][3] < 0 ? faces[f][2] : faces[f][3];
    return m;
  }
  if (quasi_) {
    const quasi::RuledBSplineSurface& s = quasi_->results().surface;
    const int U = 200, V = 8;
    const double t0 = s.knots.front(), t1 = s.knots.back();
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < U; ++i)
      for (int j = 0; j < V; ++j) points.push_back(s.evaluate(j / (V - 1.0), t0 + (t1 - t0) * i / (U - 1.0)));
    io::QuadMesh mesh;
    appendGrid(mesh, points, U, V);
    return mesh;
  }
  if (conical_) {
    if (!conical_->solved()) throw ExportFailed("format: obj: the conical strip has not been solved");
    io::QuadMesh mesh;
    const int U = 25, V = 5;
    for (const conical::ConicalPatch& p : conical_->result().patches) {
      std::vector<Eigen::Vector3d> points;
      for (int i = 0; i < U; ++i) {
        const double u = i / (U - 1.0);
        const Eigen::Vector3d a = p.pointA(u), b = p.pointB(u);
        for (int j = 0; j < V; ++j) points.push_back(a + (b - a) * (j / (V - 1.0)));
      }
      appendGrid(mesh, points, U, V);
    }
    return mesh;
  }
  return strip_->geometry(200, 8, 2).surface;
}

proto::Metrics SceneSolver::referenceMetrics(const Eigen::MatrixX3d& reference, double tolerance,
                                             Eigen::VectorXd* distances) const {
  const io::QuadMesh surface = sampledSurface();
  if (!surface.vertices.allFinite())
    throw std::runtime_error("the surface has a non-finite coordinate; no distances measured");
  const reference::SurfaceDistance d =
      reference::surfaceDistance(reference, surface.vertices, io::triangulateQuads(surface), tolerance);
  if (distances) *distances = d.distances;
  return {{"reference_points", d.points},
          {"reference_distance_max", d.maxDistance},
          {"reference_distance_rms", d.rmsDistance},
          {"reference_distance_max_relative", d.maxRelative},
          {"reference_distance_rms_relative", d.rmsRelative},
          {"reference_coverage", d.coverage},
          {"reference_coverage_tolerance", d.tolerance}};
}

}  // namespace devsurf::server
