// Reference shapes a user brings (issue 15): point clouds as text, meshes and clouds through
// OpenMesh, held to size limits.
#include "devsurf/reference/ReferenceShape.h"
#include "devsurf/io/OpenMeshIo.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

namespace devsurf::reference {
namespace {

struct DoubleTraits : public OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
  typedef OpenMesh::Vec3d Normal;
};
using PolyMesh = OpenMesh::PolyMesh_ArrayKernelT<DoubleTraits>;

/// OpenMesh reports every read and every face it cannot add on global streams; we report by
/// file and count. Switched off once per process (toggling them raced between threads).
void silenceOpenMesh() {
  static const bool silenced = [] {
    omlog().disable();
    omout().disable();
    omerr().disable();
    return true;
  }();
  (void)silenced;
}

[[noreturn]] void failShape(const std::string& path, const std::string& message) {
  throw std::invalid_argument(path + ": " + message);
}

/// The words for a coordinate past kMaxShapeCoordinate.
std::string outsideTheBound(const std::string& value) {
  return "coordinate " + value + " is outside ±1e9 (the surfaces fitted to a shape are scenes in its units, "
         "whose coordinates stay within ±1e9): shift or scale the shape";
}

std::string lowerExtension(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

void checkPointCount(const std::string& path, std::int64_t n, const ReferenceLimits& limits) {
  if (n > limits.maxPoints)
    failShape(path, "more than " + std::to_string(limits.maxPoints) + " points (the limit; thin the cloud first)");
}

ReferenceShape readXyz(const std::string& path, const ReferenceLimits& limits) {
  std::ifstream in(path);
  if (!in) failShape(path, "cannot open");
  std::vector<double> xyz, normals;
  std::string line;
  long lineNumber = 0;
  int columns = -1;
  while (std::getline(in, line)) {
    ++lineNumber;
    const std::size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream fields(line);
    double v[7];
    int n = 0;
    std::string token;
    while (fields >> token) {
      if (n == 6) failShape(path, "line " + std::to_string(lineNumber) + ": more than 6 numbers (x y z [nx ny nz])");
      char* end = nullptr;
      v[n] = std::strtod(token.c_str(), &end);
      if (end == token.c_str() || *end != '\0')
        failShape(path, "line " + std::to_string(lineNumber) + ": \"" + token + "\" is not a number");
      if (!std::isfinite(v[n])) failShape(path, "line " + std::to_string(lineNumber) + ": a coordinate is not finite");
      if (n < 3 && std::abs(v[n]) > kMaxShapeCoordinate)
        failShape(path, "line " + std::to_string(lineNumber) + ": " + outsideTheBound(token));
      ++n;
    }
    if (n == 0) continue;
    if (n != 3 && n != 6)
      failShape(path, "line " + std::to_string(lineNumber) + ": " + std::to_string(n) +
                     " numbers; a point is x y z or x y z nx ny nz");
    if (columns < 0) columns = n;
    if (n != columns)
      failShape(path, "line " + std::to_string(lineNumber) + ": " + std::to_string(n) + " numbers after lines of " +
                     std::to_string(columns));
    xyz.insert(xyz.end(), v, v + 3);
    if (n == 6) normals.insert(normals.end(), v + 3, v + 6);
    checkPointCount(path, static_cast<std::int64_t>(xyz.size() / 3), limits);
  }
  ReferenceShape shape;
  shape.format = "xyz";
  const Eigen::Index count = static_cast<Eigen::Index>(xyz.size() / 3);
  shape.points = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(xyz.data(), count, 3);
  if (!normals.empty()) {
    shape.normals = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(normals.data(), count, 3);
    for (Eigen::Index i = 0; i < count; ++i) {
      const double length = shape.normals.row(i).norm();
      if (length > 0) shape.normals.row(i) /= length;
    }
  }
  return shape;
}

/// What a mesh file declares before its data: vertex and face counts (−1 where it does not say).
/// OFF and PLY headers, binary STL's triangle count (checked against the file's size), and for
/// OBJ and ASCII STL a count of the lines. Read before OpenMesh so that a forged header cannot
/// make it reserve memory for billions of elements.
struct DeclaredCounts {
  long long vertices = -1, faces = -1;
};

DeclaredCounts declaredCounts(const std::string& path, const std::string& extension, std::uint64_t bytes) {
  DeclaredCounts counts;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  if (extension == ".off") {
    bool header = false;
    while (std::getline(in, line)) {
      const std::size_t hash = line.find('#');
      if (hash != std::string::npos) line.resize(hash);
      std::istringstream fields(line);
      std::string first;
      if (!(fields >> first)) continue;
      if (!header && first.find("OFF") != std::string::npos) {
        header = true;
        if (line.find("BINARY") != std::string::npos) failShape(path, "binary OFF is not read; write it as ASCII OFF");
        long long v = 0, f = 0;
        if (fields >> v >> f) return {v, f};  // "OFF v f e" on one line
        continue;
      }
      std::istringstream numbers(line);
      long long v = 0, f = 0;
      if (numbers >> v >> f) return {v, f};
      failShape(path, "an OFF file needs its vertex and face counts after the OFF line");
    }
    failShape(path, "no OFF header");
  }
  if (extension == ".ply") {
    counts.faces = 0;
    while (std::getline(in, line)) {
      if (line.rfind("end_header", 0) == 0) break;
      std::istringstream fields(line);
      std::string element, name;
      long long n = 0;
      if (fields >> element >> name >> n && element == "element") {
        if (name == "vertex") counts.vertices = n;
        if (name == "face") counts.faces = n;
      }
    }
    return counts;
  }
  if (extension == ".stl") {
    char head[84] = {};
    in.read(head, 84);
    const bool ascii = std::string(head, std::min<std::size_t>(5, static_cast<std::size_t>(in.gcount()))) == "solid";
    if (!ascii || in.gcount() < 84) {
      if (in.gcount() < 84) failShape(path, "too short for a binary STL (84-byte header)");
      std::uint32_t n = 0;
      for (int k = 3; k >= 0; --k) n = (n << 8) | static_cast<unsigned char>(head[80 + k]);
      if (84ull + 50ull * n != bytes)
        failShape(path, "binary STL declares " + std::to_string(n) + " triangles but has " + std::to_string(bytes) +
                       " bytes (84 + 50 per triangle expected)");
      return {3ll * n, static_cast<long long>(n)};
    }
    // ASCII (or a binary file whose header starts with "solid"): count facets.
    in.clear();
    in.seekg(0);
    long long facets = 0;
    while (std::getline(in, line)) {
      const std::size_t first = line.find_first_not_of(" \t");
      if (first != std::string::npos && line.compare(first, 5, "facet") == 0) ++facets;
    }
    if (facets == 0 && bytes >= 84) {  // binary after all
      std::uint32_t n = 0;
      for (int k = 3; k >= 0; --k) n = (n << 8) | static_cast<unsigned char>(head[80 + k]);
      if (84ull + 50ull * n == bytes) return {3ll * n, static_cast<long long>(n)};
    }
    return {3 * facets, facets};
  }
  if (extension == ".obj") {
    counts = {0, 0};
    while (std::getline(in, line)) {
      if (line.size() > 1 && line[0] == 'v' && std::isspace(static_cast<unsigned char>(line[1]))) ++counts.vertices;
      if (line.size() > 1 && line[0] == 'f' && std::isspace(static_cast<unsigned char>(line[1]))) ++counts.faces;
    }
    return counts;
  }
  return counts;
}

ReferenceShape readThroughOpenMesh(const std::string& path, const std::string& extension, std::uint64_t bytes,
                                   const ReferenceLimits& limits) {
  const DeclaredCounts declared = declaredCounts(path, extension, bytes);
  if (declared.vertices < -1 || declared.faces < -1) failShape(path, "a negative count in its header");
  checkPointCount(path, declared.vertices, limits);
  // A face has at least one triangle: a face count over the triangle limit is over it too.
  if (declared.faces > limits.maxTriangles)
    failShape(path, "declares " + std::to_string(declared.faces) + " faces, more than the limit of " +
                   std::to_string(limits.maxTriangles) + " triangles");
  silenceOpenMesh();
  PolyMesh mesh;
  mesh.request_vertex_normals();
  OpenMesh::IO::Options options;
  options += OpenMesh::IO::Options::VertexNormal;
  try {
    bool read = false;
    {
      const std::lock_guard<std::mutex> io(io::openMeshIoMutex());  // OpenMesh's readers are shared
      read = OpenMesh::IO::read_mesh(mesh, path, options);
    }
    if (!read) failShape(path, "OpenMesh could not read it as " + extension.substr(1));
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::exception& e) {
    failShape(path, "OpenMesh could not read it as " + extension.substr(1) + " (" + e.what() + ")");
  }
  checkPointCount(path, static_cast<std::int64_t>(mesh.n_vertices()), limits);
  ReferenceShape shape;
  shape.format = extension.substr(1);
  shape.points.resize(static_cast<Eigen::Index>(mesh.n_vertices()), 3);
  for (const auto v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    shape.points.row(v.idx()) << p[0], p[1], p[2];
  }
  if (!shape.points.allFinite()) failShape(path, "a coordinate is not finite");
  for (Eigen::Index v = 0; v < shape.points.rows(); ++v)
    for (int k = 0; k < 3; ++k)
      if (std::abs(shape.points(v, k)) > kMaxShapeCoordinate) {
        std::ostringstream value;
        value << shape.points(v, k);
        failShape(path, "vertex " + std::to_string(v + 1) + ": " + outsideTheBound(value.str()));
      }
  if (options.check(OpenMesh::IO::Options::VertexNormal)) {
    shape.normals.resize(shape.points.rows(), 3);
    for (const auto v : mesh.vertices()) {
      const auto& n = mesh.normal(v);
      Eigen::RowVector3d row(n[0], n[1], n[2]);
      const double length = row.norm();
      shape.normals.row(v.idx()) = std::isfinite(length) && length > 0 ? Eigen::RowVector3d(row / length)
                                                                       : Eigen::RowVector3d::Zero();
    }
  }
  std::int64_t triangles = 0;
  for (const auto f : mesh.faces()) triangles += static_cast<std::int64_t>(mesh.valence(f)) - 2;
  if (triangles > limits.maxTriangles)
    failShape(path, "more than " + std::to_string(limits.maxTriangles) + " triangles (the limit)");
  shape.triangles.resize(static_cast<Eigen::Index>(triangles), 3);
  Eigen::Index row = 0;
  for (const auto f : mesh.faces()) {
    std::vector<int> corners;
    for (const auto v : mesh.fv_range(f)) corners.push_back(v.idx());
    for (std::size_t k = 1; k + 1 < corners.size(); ++k) shape.triangles.row(row++) << corners[0], corners[k], corners[k + 1];
  }
  if (declared.faces >= 0)
    shape.facesSkipped = std::max<std::int64_t>(0, declared.faces - static_cast<std::int64_t>(mesh.n_faces()));
  return shape;
}

}  // namespace

double ReferenceShape::diagonal() const {
  if (points.rows() == 0) return 0.0;
  return (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm();
}

ReferenceShape readReferenceShape(const std::string& path, const ReferenceLimits& limits) {
  std::error_code error;
  const auto bytes = std::filesystem::file_size(path, error);
  if (error) failShape(path, "cannot open (" + error.message() + ")");
  if (bytes > limits.maxFileBytes)
    failShape(path, std::to_string(bytes) + " bytes, over the limit of " + std::to_string(limits.maxFileBytes));
  const std::string extension = lowerExtension(path);
  ReferenceShape shape;
  if (extension == ".xyz" || extension == ".pwn" || extension == ".txt") {
    shape = readXyz(path, limits);
  } else if (extension == ".ply" || extension == ".obj" || extension == ".off" || extension == ".stl") {
    shape = readThroughOpenMesh(path, extension, bytes, limits);
  } else {
    failShape(path, "unknown extension \"" + extension + "\" (point clouds: .xyz, .pwn, .ply; meshes: .obj, .off, .ply, .stl)");
  }
  if (shape.points.rows() == 0) failShape(path, "no points");
  return shape;
}

}  // namespace devsurf::reference
