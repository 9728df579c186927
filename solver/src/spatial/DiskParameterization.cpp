#include "devsurf/spatial/DiskParameterization.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_parameterization/ARAP_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/LSCM_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>

namespace devsurf::spatial {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
using VertexIndex = Mesh::Vertex_index;
namespace SMP = CGAL::Surface_mesh_parameterization;

[[noreturn]] void failDisk(const std::string& why) {
  throw std::invalid_argument("parameterizeDisk: " + why);
}

double signedArea2d(const Eigen::MatrixX2d& uv, const Eigen::MatrixX3i& T) {
  double area = 0.0;
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    const Eigen::Vector2d a = uv.row(T(t, 0)), b = uv.row(T(t, 1)), c = uv.row(T(t, 2));
    area += 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
  }
  return area;
}

}  // namespace

Eigen::MatrixX2d parameterizeDisk(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& T,
                                  ParameterizationMethod method) {
  if (T.rows() == 0) failDisk("no triangles");
  if (!V.allFinite()) failDisk("a vertex coordinate is not finite");
  Mesh mesh;
  std::vector<VertexIndex> vertexOf(V.rows());
  std::vector<int> used(V.rows(), 0);
  for (Eigen::Index t = 0; t < T.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int v = T(t, k);
      if (v < 0 || v >= V.rows()) failDisk("triangle " + std::to_string(t) + " has a vertex index out of range");
      used[v] = 1;
    }
  for (Eigen::Index v = 0; v < V.rows(); ++v)
    if (used[v]) vertexOf[v] = mesh.add_vertex(Kernel::Point_3(V(v, 0), V(v, 1), V(v, 2)));
  double area3d = 0.0;
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    const Eigen::Vector3d a = V.row(T(t, 0)), b = V.row(T(t, 1)), c = V.row(T(t, 2));
    const double twiceArea = (b - a).cross(c - a).norm();
    const double longest = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    if (!(twiceArea > 1e-12 * longest)) failDisk("triangle " + std::to_string(t) + " is degenerate");
    area3d += 0.5 * twiceArea;
    if (mesh.add_face(vertexOf[T(t, 0)], vertexOf[T(t, 1)], vertexOf[T(t, 2)]) == Mesh::null_face())
      failDisk("triangle " + std::to_string(t) + " makes the mesh non-manifold or is oriented against its neighbours");
  }
  for (VertexIndex v : mesh.vertices())
    if (mesh.is_border(v, false) && mesh.halfedge(v) == Mesh::null_halfedge()) failDisk("an isolated vertex");

  // A disk: one component, one boundary loop, χ = V − E + F = 1.
  auto componentMap = mesh.add_property_map<Mesh::Face_index, std::size_t>("f:component").first;
  const std::size_t components = CGAL::Polygon_mesh_processing::connected_components(mesh, componentMap);
  if (components != 1) failDisk("the mesh has " + std::to_string(components) + " components; a disk has one");
  std::vector<Mesh::Halfedge_index> borderCycles;
  CGAL::Polygon_mesh_processing::extract_boundary_cycles(mesh, std::back_inserter(borderCycles));
  if (borderCycles.empty()) failDisk("the mesh is closed; cut it open to a disk first");
  const long euler = static_cast<long>(mesh.number_of_vertices()) - static_cast<long>(mesh.number_of_edges()) +
                     static_cast<long>(mesh.number_of_faces());
  if (borderCycles.size() != 1 || euler != 1)
    failDisk("the mesh has " + std::to_string(borderCycles.size()) + " boundary loops and Euler characteristic " +
         std::to_string(euler) + "; a disk has one loop and 1 (fill its holes first)");

  // The longest boundary loop is the one CGAL's border parameterizers walk.
  Mesh::Halfedge_index border = borderCycles.front();
  auto uvMap = mesh.add_property_map<VertexIndex, Kernel::Point_2>("v:uv").first;
  SMP::Error_code status;
  if (method == ParameterizationMethod::Conformal) {
    status = SMP::parameterize(mesh, SMP::LSCM_parameterizer_3<Mesh>(), border, uvMap);
  } else {
    status = SMP::parameterize(mesh, SMP::ARAP_parameterizer_3<Mesh>(), border, uvMap);
  }
  if (status != SMP::OK) failDisk(std::string("CGAL: ") + SMP::get_error_message(status));

  Eigen::MatrixX2d uv = Eigen::MatrixX2d::Zero(V.rows(), 2);
  for (Eigen::Index v = 0; v < V.rows(); ++v)
    if (used[v]) {
      const Kernel::Point_2& p = uvMap[vertexOf[v]];
      uv(v, 0) = p.x();
      uv(v, 1) = p.y();
    }
  if (!uv.allFinite()) failDisk("the map has a non-finite coordinate");
  double area2d = signedArea2d(uv, T);
  if (area2d < 0.0) {  // mirrored: flip v
    uv.col(1) = -uv.col(1);
    area2d = -area2d;
  }
  if (!(area2d > 0.0)) failDisk("the map has no area");
  Eigen::RowVector2d centre = Eigen::RowVector2d::Zero();
  int count = 0;
  for (Eigen::Index v = 0; v < V.rows(); ++v)
    if (used[v]) centre += uv.row(v), ++count;
  centre /= count;
  const double scale = std::sqrt(area3d / area2d);
  for (Eigen::Index v = 0; v < V.rows(); ++v)
    if (used[v]) uv.row(v) = (uv.row(v) - centre) * scale;
  return uv;
}

}  // namespace devsurf::spatial
