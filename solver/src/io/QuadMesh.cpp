#include "devsurf/io/QuadMesh.h"

#include <stdexcept>
#include <vector>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/System/omstream.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>

namespace devsurf::io {
namespace {

struct DoubleTraits : public OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
  typedef OpenMesh::Vec3d Normal;
};
using PolyMesh = OpenMesh::PolyMesh_ArrayKernelT<DoubleTraits>;

/// OpenMesh reports every read and write on its log streams; errors surface as our exceptions.
void silenceOpenMeshLogs() {
  omlog().disable();
  omout().disable();
}

}  // namespace

void writeMesh(const QuadMesh& mesh, const std::string& path) {
  silenceOpenMeshLogs();
  PolyMesh out;
  std::vector<PolyMesh::VertexHandle> handles;
  handles.reserve(static_cast<std::size_t>(mesh.vertices.rows()));
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i)
    handles.push_back(out.add_vertex(
        PolyMesh::Point(mesh.vertices(i, 0), mesh.vertices(i, 1), mesh.vertices(i, 2))));
  for (Eigen::Index f = 0; f < mesh.quads.rows(); ++f) {
    std::vector<PolyMesh::VertexHandle> face;
    for (int c = 0; c < 4; ++c) {
      const int v = mesh.quads(f, c);
      if (v < 0 || v >= static_cast<int>(handles.size()))
        throw std::runtime_error(path + ": quad " + std::to_string(f) + " has a bad vertex index");
      face.push_back(handles[static_cast<std::size_t>(v)]);
    }
    if (!out.add_face(face).is_valid())
      throw std::runtime_error(path + ": quad " + std::to_string(f) + " is not manifold");
  }
  OpenMesh::IO::Options options;
  if (!OpenMesh::IO::write_mesh(out, path, options, 17))
    throw std::runtime_error("cannot write mesh file " + path);
}

QuadMesh readQuadMesh(const std::string& path) {
  silenceOpenMeshLogs();
  PolyMesh in;
  if (!OpenMesh::IO::read_mesh(in, path)) throw std::runtime_error("cannot read mesh file " + path);
  QuadMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(in.n_vertices()), 3);
  for (const auto& v : in.vertices()) {
    const auto& p = in.point(v);
    mesh.vertices.row(v.idx()) << p[0], p[1], p[2];
  }
  mesh.quads.resize(static_cast<Eigen::Index>(in.n_faces()), 4);
  for (const auto& f : in.faces()) {
    int c = 0;
    for (const auto& v : f.vertices()) {
      if (c == 4) throw std::runtime_error(path + ": face " + std::to_string(f.idx()) + " is not a quad");
      mesh.quads(f.idx(), c++) = v.idx();
    }
    if (c != 4) throw std::runtime_error(path + ": face " + std::to_string(f.idx()) + " is not a quad");
  }
  return mesh;
}

}  // namespace devsurf::io
