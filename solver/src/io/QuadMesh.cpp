#include "devsurf/io/QuadMesh.h"
#include "devsurf/io/OpenMeshIo.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>
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

/// OpenMesh's read_mesh under openMeshIoMutex (its readers are shared by the whole process).
bool readLocked(PolyMesh& mesh, const std::string& path) {
  const std::lock_guard<std::mutex> io(openMeshIoMutex());
  return OpenMesh::IO::read_mesh(mesh, path);
}

/// Whether `path` ends in `extension` (ASCII case-insensitive).
bool hasExtension(const std::string& path, const std::string& extension) {
  if (path.size() < extension.size()) return false;
  for (std::size_t i = 0; i < extension.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(path[path.size() - extension.size() + i])) != extension[i]) return false;
  return true;
}

}  // namespace

Eigen::MatrixX3i triangulateQuads(const QuadMesh& mesh) {
  const Eigen::Index n = mesh.vertices.rows();
  Eigen::MatrixX3i triangles(2 * mesh.quads.rows(), 3);
  Eigen::Index count = 0;
  for (Eigen::Index f = 0; f < mesh.quads.rows(); ++f) {
    for (int c = 0; c < 4; ++c)
      if (mesh.quads(f, c) < 0 || mesh.quads(f, c) >= n)
        throw std::runtime_error("quad " + std::to_string(f) + " has a bad vertex index");
    const int corners[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (const auto& t : corners) {
      const Eigen::Vector3d a = mesh.vertices.row(mesh.quads(f, t[0])).transpose();
      const Eigen::Vector3d b = mesh.vertices.row(mesh.quads(f, t[1])).transpose();
      const Eigen::Vector3d c = mesh.vertices.row(mesh.quads(f, t[2])).transpose();
      const double longest = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
      if (!((b - a).cross(c - a).norm() > 1e-12 * longest)) continue;
      // STL holds single-precision coordinates: corners that are one point once rounded to float
      // (a strip pinched to a point, sampled 1e-10 apart) would give the facet a NaN normal.
      const Eigen::Vector3f af = a.cast<float>(), bf = b.cast<float>(), cf = c.cast<float>();
      const Eigen::Vector3f normal = (bf - af).cross(cf - af);
      if (!(normal.norm() > 0.0f) || !normal.normalized().allFinite()) continue;
      triangles.row(count++) << mesh.quads(f, t[0]), mesh.quads(f, t[1]), mesh.quads(f, t[2]);
    }
  }
  triangles.conservativeResize(count, 3);
  return triangles;
}

namespace {

/// The mesh as an OpenMesh polygon mesh: its quads, or triangulateQuads' triangles when
/// `triangles` (OpenMesh's STL writer writes triangles only; other faces become facets without
/// vertices). `what` names the destination in messages.
PolyMesh polyMeshOf(const QuadMesh& mesh, bool triangles, const std::string& what) {
  PolyMesh out;
  std::vector<PolyMesh::VertexHandle> handles;
  handles.reserve(static_cast<std::size_t>(mesh.vertices.rows()));
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i)
    handles.push_back(out.add_vertex(PolyMesh::Point(mesh.vertices(i, 0), mesh.vertices(i, 1), mesh.vertices(i, 2))));
  auto addFace = [&out, &handles, &what](const std::vector<int>& indices, const std::string& face) {
    std::vector<PolyMesh::VertexHandle> corners;
    for (const int v : indices) {
      if (v < 0 || v >= static_cast<int>(handles.size()))
        throw std::runtime_error(what + ": " + face + " has a bad vertex index");
      corners.push_back(handles[static_cast<std::size_t>(v)]);
    }
    if (!out.add_face(corners).is_valid()) throw std::runtime_error(what + ": " + face + " is not manifold");
  };
  if (triangles) {
    Eigen::MatrixX3i t;
    try {
      t = triangulateQuads(mesh);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(what + ": " + e.what());
    }
    // An STL of no facets reads as an empty part, not as an error: say it instead.
    if (t.rows() == 0) throw std::runtime_error(what + ": the surface has no triangle of positive area");
    for (Eigen::Index k = 0; k < t.rows(); ++k) addFace({t(k, 0), t(k, 1), t(k, 2)}, "triangle " + std::to_string(k));
  } else {
    for (Eigen::Index f = 0; f < mesh.quads.rows(); ++f) {
      // A quad whose last corner repeats its third is a triangle (a non-convex planar face of a
      // composite is triangulated that way); OpenMesh refuses a face with a corner twice.
      if (mesh.quads(f, 3) == mesh.quads(f, 2))
        addFace({mesh.quads(f, 0), mesh.quads(f, 1), mesh.quads(f, 2)}, "quad " + std::to_string(f));
      else
        addFace({mesh.quads(f, 0), mesh.quads(f, 1), mesh.quads(f, 2), mesh.quads(f, 3)}, "quad " + std::to_string(f));
    }
  }
  return out;
}

}  // namespace

void writeMesh(const QuadMesh& mesh, const std::string& path) {
  silenceOpenMeshLogs();
  const PolyMesh out = polyMeshOf(mesh, hasExtension(path, ".stl"), path);
  OpenMesh::IO::Options options;
  bool written = false;
  {
    const std::lock_guard<std::mutex> io(openMeshIoMutex());
    written = OpenMesh::IO::write_mesh(out, path, options, 17);
  }
  if (!written) throw std::runtime_error("cannot write mesh file " + path);
}

std::string meshString(const QuadMesh& mesh, const std::string& format) {
  if (format != "obj" && format != "off" && format != "ply" && format != "stl")
    throw std::invalid_argument("meshString: format must be obj, off, ply or stl, got \"" + format + "\"");
  silenceOpenMeshLogs();
  const PolyMesh out = polyMeshOf(mesh, format == "stl", format);
  std::ostringstream text;
  OpenMesh::IO::Options options;
  bool written = false;
  {
    const std::lock_guard<std::mutex> io(openMeshIoMutex());
    written = OpenMesh::IO::write_mesh(out, text, "." + format, options, 17);
  }
  if (!written) throw std::runtime_error("cannot write the mesh as " + format);
  return text.str();
}

QuadMesh readQuadMesh(const std::string& path) {
  silenceOpenMeshLogs();
  PolyMesh in;
  if (!readLocked(in, path)) throw std::runtime_error("cannot read mesh file " + path);
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

PolygonMeshFile readPolygonMesh(const std::string& path, int* facesSkipped) {
  silenceOpenMeshLogs();
  PolyMesh in;
  if (!readLocked(in, path)) throw std::runtime_error("cannot read mesh file " + path);
  PolygonMeshFile mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(in.n_vertices()), 3);
  for (const auto& v : in.vertices()) {
    const auto& p = in.point(v);
    mesh.vertices.row(v.idx()) << p[0], p[1], p[2];
  }
  for (const auto& f : in.faces()) {
    std::array<int, 4> face{-1, -1, -1, -1};
    int c = 0;
    for (const auto& v : f.vertices()) {
      if (c == 4)
        throw std::runtime_error(path + ": face " + std::to_string(f.idx()) +
                                 " has more than four vertices (quad-dominant meshes have triangles and quads)");
      face[static_cast<std::size_t>(c++)] = v.idx();
    }
    mesh.faces.push_back(face);
  }
  if (facesSkipped) {
    *facesSkipped = 0;
    std::string extension = path.substr(path.find_last_of('.') + 1);
    std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
    if (extension == "obj") {
      std::ifstream file(path);
      std::string line;
      int faces = 0;
      while (std::getline(file, line))
        if (line.size() > 1 && line[0] == 'f' && std::isspace(static_cast<unsigned char>(line[1]))) ++faces;
      *facesSkipped = std::max(0, faces - static_cast<int>(mesh.faces.size()));
    }
  }
  return mesh;
}

}  // namespace devsurf::io
