#pragma once

#include <array>
#include <vector>

#include <string>

#include <Eigen/Core>

namespace devsurf::io {

/// A polygon mesh of quads (the sampled surfaces the models extract).
struct QuadMesh {
  Eigen::MatrixX3d vertices;  ///< m×3
  Eigen::MatrixX4i quads;     ///< f×4 vertex indices, counter-clockwise seen from the normal side
};

/// The quads as triangles for formats that only hold triangles (STL): quad (v0, v1, v2, v3)
/// becomes (v0, v1, v2) and (v0, v2, v3), in the quad's orientation. A triangle of zero area is
/// left out — a repeated vertex or a zero-length edge (a strip's rulings meeting in a point):
/// ‖(b − a) × (c − a)‖ ≤ 1e-12 · (longest edge)², or no normal once its corners are rounded to
/// float (STL's precision: two corners one point there).
/// @returns t×3 vertex indices into mesh.vertices
/// @throws std::runtime_error if a quad has a vertex index out of range
Eigen::MatrixX3i triangulateQuads(const QuadMesh& mesh);

/// Writes the mesh through OpenMesh; the format follows the extension (.obj, .off, .ply, .stl).
/// obj, off and ply keep the quads; stl (ASCII) gets triangulateQuads' triangles.
/// @throws std::runtime_error naming the file when writing fails.
void writeMesh(const QuadMesh& mesh, const std::string& path);

/// The text writeMesh writes for a file of extension `format` (obj, off, ply or stl), in memory.
/// @throws std::invalid_argument for another format, std::runtime_error when OpenMesh fails.
std::string meshString(const QuadMesh& mesh, const std::string& format);

/// Reads a polygon mesh through OpenMesh (faces that are not quads are rejected).
/// @throws std::runtime_error naming the file when reading fails.
QuadMesh readQuadMesh(const std::string& path);

/// A quad-dominant mesh as read from a file: vertices V×3 and faces of 3 or 4 vertices (a
/// triangle has −1 in its fourth slot).
struct PolygonMeshFile {
  Eigen::MatrixX3d vertices;
  std::vector<std::array<int, 4>> faces;
};

/// Reads an OBJ, OFF or PLY mesh through OpenMesh (by extension) with its vertex order; faces of
/// more than four vertices are refused. OpenMesh leaves out faces it cannot add (non-manifold
/// ones); `facesSkipped` says how many faces the file had that are not in the result when the
/// format tells (OBJ: counted from its "f" lines), else 0.
/// @throws std::runtime_error naming the file (and the face) when reading fails.
PolygonMeshFile readPolygonMesh(const std::string& path, int* facesSkipped = nullptr);

}  // namespace devsurf::io
